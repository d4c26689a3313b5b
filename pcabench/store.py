"""The results store: append-only JSON lines, one run record per line, with a database's guarantees.

Why JSONL and not SQLite: the committed reference results must diff and merge
in git as text, and a store is copied between machines by copying a file;
the guarantees below make the plain file as safe as a database for one
writer at a time.

- Every write takes an exclusive lock on the file (``fcntl.flock``), repairs
  a torn tail left by a crash or a full disk (the partial line is moved to
  ``<store>.torn`` and the file cut back to its last complete line), then
  appends one line and fsyncs. A torn record never takes a good one with it.
- A sweep holds ``<store>.lock`` for its whole life (:class:`SweepLock`), so a
  second sweep on the same store is refused at once, with the first's pid.
- Every row carries ``schema`` (:data:`SCHEMA`) and is validated on load:
  a bad row is skipped with one warning naming the file and line, a row of a
  newer schema is reported as such, and nothing crashes on them.
- Stores taken on different machines merge by concatenation: a record keeps
  its ``run_id`` wherever it is copied, and duplicates are dropped on load.
"""
from __future__ import annotations

import errno
import fcntl
import hashlib
import json
import math
import os
import shutil
import warnings
from pathlib import Path

import numpy as np

from .record import STEP_STAGES

SCHEMA = 2  # version of the row format; rows from before versioning are schema 1
REQUIRED = {"solver": str, "status": str, "n_particles": int, "steps": int, "dx": (int, float),
            "stages": dict, "scene": dict, "profile_id": str}
MIN_FREE_BYTES = 1 << 20  # a sweep needs room for its records: refuse to start with less free space


class StoreWarning(UserWarning):
    """A row of a store was skipped (torn, corrupt, invalid, or from a newer schema)."""


class StoreError(OSError):
    """The store cannot be written (one line naming the path)."""


def run_id(row: dict) -> str:
    """The id of a row that has none (rows of old stores): a hash of its provenance and time."""
    key = json.dumps([row.get("profile_id"), row.get("commit"), row.get("solver"), row.get("threads"),
                      row.get("scene"), row.get("timestamp"), row.get("host")], sort_keys=True, default=str)
    return hashlib.sha1(key.encode()).hexdigest()[:16]


def _clean(value):
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _clean(v) for k, v in value.items()}
    return value


def to_row(record) -> dict:
    """The stored form of a run record (a RunRecord or dict): JSON-safe (NaN as null), schema and run_id."""
    row = _clean(record.as_dict() if hasattr(record, "as_dict") else dict(record))
    row.setdefault("schema", SCHEMA)
    row.setdefault("run_id", run_id(row))
    return row


def store_name(profile_id: str, host: str | None = None) -> str:
    """The file name of a machine's store: hardware profile and host, so two hosts never share one by accident."""
    from .provenance import host_id

    return f"{profile_id}--{host or host_id()}.jsonl"


def check_writable(path) -> Path:
    """Make sure a record can be appended to the store at ``path`` before any run; StoreError if not."""
    path = Path(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with open(path, "a", encoding="utf-8"):
            pass
    except OSError as exc:
        raise StoreError(f"results store {path} is not writable: {exc.strerror or exc}") from None
    free = shutil.disk_usage(path.parent).free
    if free < MIN_FREE_BYTES:
        raise StoreError(f"results store {path}: only {free} bytes free on its file system "
                         f"(need at least {MIN_FREE_BYTES})")
    return path


def _repair_tail(f, path: Path) -> None:
    """Cut a torn last line (no newline) off the locked file ``f``, keeping it in ``<store>.torn``."""
    size = os.fstat(f.fileno()).st_size
    if size == 0:
        return
    f.seek(size - 1)
    if f.read(1) == b"\n":
        return
    # find the last newline before the torn tail
    pos, block = size, 1 << 16
    start = 0
    while pos > 0:
        step = min(block, pos)
        pos -= step
        f.seek(pos)
        chunk = f.read(step)
        k = chunk.rfind(b"\n")
        if k >= 0:
            start = pos + k + 1
            break
    f.seek(start)
    torn = f.read()
    with open(f"{path}.torn", "ab") as t:
        t.write(torn + b"\n")
    f.truncate(start)
    warnings.warn(f"{path}: a torn last line ({len(torn)} bytes, a write cut short) was moved to {path}.torn",
                  StoreWarning, stacklevel=3)


def append(record, path) -> dict:
    """Append one run record (a RunRecord or dict) to the store at ``path`` safely; returns the row."""
    row = to_row(record)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    line = (json.dumps(row, sort_keys=True) + "\n").encode("utf-8")
    try:
        with open(path, "a+b") as f:
            fcntl.flock(f.fileno(), fcntl.LOCK_EX)
            try:
                _repair_tail(f, path)
                before = f.seek(0, os.SEEK_END)
                try:
                    f.write(line)
                    f.flush()
                    os.fsync(f.fileno())
                except OSError:
                    f.truncate(before)  # a full disk leaves no torn line behind
                    raise
            finally:
                fcntl.flock(f.fileno(), fcntl.LOCK_UN)
    except OSError as exc:
        if exc.errno in (errno.ENOSPC, errno.EDQUOT):
            raise StoreError(f"results store {path}: the disk is full; the record was not stored") from None
        raise StoreError(f"results store {path} is not writable: {exc.strerror or exc}") from None
    return row


class SweepLock:
    """Held by a sweep for its whole life: a second sweep on the same store is refused (StoreError)."""

    def __init__(self, store_path):
        self.path = Path(f"{store_path}.lock")
        self.file = None

    def __enter__(self):
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self.file = open(self.path, "a+")
        try:
            fcntl.flock(self.file.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            self.file.seek(0)
            holder = self.file.read().strip() or "another process"
            self.file.close()
            raise StoreError(f"results store {str(self.path)[:-5]} is in use by another sweep ({holder}); "
                             "wait for it, or give this one its own --results folder") from None
        self.file.seek(0)
        self.file.truncate()
        self.file.write(f"pid {os.getpid()}")
        self.file.flush()
        return self

    def __exit__(self, *exc):
        fcntl.flock(self.file.fileno(), fcntl.LOCK_UN)
        self.file.close()


def validate(row) -> str:
    """Why ``row`` is not a usable run record ('' if it is)."""
    if not isinstance(row, dict):
        return f"not a record but a JSON {type(row).__name__}"
    version = row.get("schema", 1)
    if not isinstance(version, int) or version > SCHEMA:
        return f"a row of a newer pcabench (schema {version}; this one reads up to {SCHEMA}): upgrade to read it"
    for key, kind in REQUIRED.items():
        if key not in row:
            return f"missing {key!r}"
        if not isinstance(row[key], kind) or isinstance(row[key], bool):
            return f"{key!r} is {type(row[key]).__name__}, not {getattr(kind, '__name__', 'a number')}"
    missing = [s for s in STEP_STAGES if not isinstance(row["stages"].get(s), (int, float))]
    if missing:
        return f"stages lack {', '.join(missing)}"
    return ""


def read_rows(paths) -> list[dict]:
    """Every valid row of the stores ``paths`` (files or folders of *.jsonl), deduplicated.

    A line that is not valid UTF-8, not JSON, not a record, or fails
    :func:`validate` is skipped with one StoreWarning naming its file and line.
    """
    if isinstance(paths, (str, Path)):
        paths = [paths]
    seen, rows = set(), []
    for path in paths:
        path = Path(path)
        files = sorted(path.glob("*.jsonl")) if path.is_dir() else [path]
        for file in files:
            if not file.exists():
                continue
            lines = file.read_bytes().split(b"\n")
            if lines and lines[-1] == b"":
                lines.pop()  # the newline that ends the last record
            for number, raw in enumerate(lines, 1):
                if not raw.strip():
                    warnings.warn(f"{file}:{number}: a blank line, skipped", StoreWarning, stacklevel=2)
                    continue
                try:
                    row = json.loads(raw.decode("utf-8"))
                except UnicodeDecodeError:
                    why = "not UTF-8 text"
                except json.JSONDecodeError as exc:
                    why = f"not JSON ({exc.msg}; a torn or hand-edited line?)"
                else:
                    why = validate(row)
                if why:
                    warnings.warn(f"{file}:{number}: {why}; row skipped", StoreWarning, stacklevel=2)
                    continue
                rid = row.get("run_id") or run_id(row)
                if rid not in seen:
                    seen.add(rid)
                    rows.append(row)
    return rows


def load(paths):
    """The stores ``paths`` as one tidy pandas DataFrame (stage times as columns t_<stage>)."""
    import pandas as pd

    from .spec import stored_parameters

    rows = read_rows(paths)
    flat = []
    for row in rows:
        r = {k: v for k, v in row.items() if k not in ("stages", "scene", "versions")}
        for stage, seconds in (row.get("stages") or {}).items():
            r[f"t_{stage}"] = seconds
        scene = row.get("scene") or {}
        scene = {**stored_parameters(scene), **scene}  # a parameter the row predates at its default (kernel)
        for key in ("strip_height", "cutoff_factor", "kernel", "h_factor", "cfl", "t_final", "height"):
            r[key] = scene.get(key)
        # how the run ends: the paper's fixed step count, or a fixed physical time
        r["protocol"] = f"t = {scene['t_end']:g} s" if scene.get("t_end") else f"{scene.get('steps')} steps"
        r["domain"] = "strip" if scene.get("strip_height") else "full"
        r["scene_key"] = json.dumps({k: v for k, v in scene.items() if k != "memory_limit_bytes"},
                                    sort_keys=True)
        r.setdefault("preset", "")
        r.setdefault("pair_loop", "")  # rows from before the pair list: the gather loop
        r["threads"] = int(r.get("threads") or 1)
        flat.append(r)
    df = pd.DataFrame(flat)
    if not df.empty:
        for col in ("mse", "me", "mean_neighbours", "jit_seconds", "dx", "t_end"):  # null (NaN stored) -> NaN
            if col in df:
                df[col] = pd.to_numeric(df[col], errors="coerce")
        if "host" not in df:
            df["host"] = ""
        df["host"] = df["host"].fillna("")
        # one machine: a hardware profile, and its host where several hosts share the profile
        hosts = df.groupby("profile_id")["host"].transform("nunique")
        df["machine"] = np.where(hosts > 1, df["profile_id"] + "--" + df["host"], df["profile_id"])
        step_total = sum(df[f"t_{s}"] for s in STEP_STAGES)
        df["t_step"] = step_total / df["steps"].clip(lower=1)
        df["t_solution"] = df["t_init"] + step_total  # s, without JIT and I/O
    return df
