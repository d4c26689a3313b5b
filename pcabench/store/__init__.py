"""The results store: append-only JSON lines, one run record per line, with a database's guarantees.

Why JSONL and not SQLite: the committed reference results must diff and merge
in git as text, and a store is copied between machines by copying a file;
the guarantees below make the plain file as safe as a database for one
writer at a time.

- Every write takes an exclusive lock on the file (``fcntl.flock``), repairs
  its tail (a complete last record that only lacks its newline gets it; a
  partial line left by a crash is moved to ``<store>.torn`` and the file cut
  back to its last complete line), then appends one line and fsyncs. A write
  that fails (a full disk) is cut back off: no partial line is left.
- A sweep holds its store's lock for its whole life (:class:`SweepLock`), so a
  second sweep on the same store is refused at once, with the first's pid; it
  also keeps ``<store>.reserve``, space given up to store the record that
  meets a full disk, after which the sweep stops.
- Nothing is written through a symbolic link: a store, lock, reserve or
  ``.torn`` file that is one, or that is not a regular file (a FIFO), is
  refused.
- Every row carries ``schema`` (:data:`SCHEMA`) and is checked against the
  one declared schema (``pcabench/store/schema.py``: types, ranges, finite numbers,
  allowed characters, lengths, names safe as file names) on write (a record
  that would not read back is refused, :class:`InvalidRecord`) and on load
  (:func:`validate`): a bad row is skipped with one warning naming the file,
  line and field; a row of a newer schema is kept in the file and skipped
  with one warning; nothing crashes on them.
- A store past :data:`SEGMENT_BYTES` is closed, when a sweep on it starts, as segments
  ``<store>.001.jsonl``, ... (:func:`roll_over`): its lines unchanged, in order; a sweep counts their runs
  as stored (:func:`store_files`) and a folder's readers read them before the store.
- Only regular files of the store folder are read, up to
  :data:`MAX_STORE_BYTES` each: a link, a FIFO or a device named ``*.jsonl``
  is skipped with one warning.
- Stores taken on different machines merge by concatenation: a record keeps
  its ``run_id`` wherever it is copied, and copies are one run on load. Two
  different records under one ``run_id``: the later write in the store's order
  wins (the one read later, never by the rows' own timestamps), with one
  warning naming both files and lines (:func:`read_records`).
- Readers take the typed record (:meth:`pcabench.store.record.RunRecord.from_row`):
  the schema's fields only, so a key the schema does not know never reaches
  a table.
"""

from __future__ import annotations

import errno
import fcntl
import hashlib
import itertools
import json
import math
import os
import shutil
import stat
import sys
import time
import warnings
from pathlib import Path

from pcabench.errors import StoreError, StoreFull  # noqa: F401 - raised here, re-exported for callers
from pcabench.store import schema
from pcabench.store.schema import SCHEMA
from pcabench.store.watch import StoreWatch
from solvers import Scene, SceneError

MIN_FREE_BYTES = 1 << 20  # a sweep needs room for its records: refuse to start with less free space
RESERVE_BYTES = 1 << 18  # <store>.reserve: room for the record that meets a full disk
MAX_STORE_BYTES = 1 << 30  # a store file larger than this is not read (a link to /dev/zero, a stray dump)
SEGMENT_BYTES = 4 << 20  # a store past this is closed as segments when a sweep starts (files a review can read)
NAME = schema.NAME  # a machine or host name, safe as a file name


class StoreWarning(UserWarning):
    """A row of a store was skipped (torn, corrupt, invalid, or from a newer schema)."""


FULL = (errno.ENOSPC, errno.EDQUOT, errno.EFBIG)  # the disk (or the quota, or the file size limit) is full


class InvalidRecord(StoreError):
    """A record that would not read back (it fails the schema): never written."""


def run_id(row: dict) -> str:
    """The id of a row that has none (rows of old stores): a hash of its provenance and time."""
    key = json.dumps(
        [
            row.get("profile_id"),
            row.get("commit"),
            row.get("solver"),
            row.get("threads"),
            row.get("scene"),
            row.get("timestamp"),
            row.get("host"),
        ],
        sort_keys=True,
        default=str,
    )
    return hashlib.sha1(key.encode()).hexdigest()[:16]


def _clean(value):
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _clean(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_clean(v) for v in value]
    return value


def to_row(record) -> dict:
    """The stored form of a run record (a RunRecord or dict): JSON-safe (NaN as null), schema and run_id."""
    row = _clean(record.as_dict() if hasattr(record, "as_dict") else dict(record))
    if isinstance(row.get("message"), str):
        row["message"] = schema.clean_text(row["message"])
    row.setdefault("schema", SCHEMA)
    row.setdefault("run_id", run_id(row))
    return row


def check_name(name, what: str) -> str:
    """``name`` if it is safe as a file name (letters, digits, ``. _ -``; not starting with a dot or dash);
    else StoreError naming ``what``."""
    if not isinstance(name, str) or not NAME.fullmatch(name):
        raise StoreError(f"{what} {name!r:.120} is not a safe name (letters, digits, '.', '_', '-')")
    why = schema.check_value(what, schema.PATH_NAME, name)
    if why:
        raise StoreError(why)
    return name


def store_name(profile_id: str, host: str | None = None) -> str:
    """The file name of a machine's store: hardware profile and host, so two hosts never share one by accident."""
    from pcabench.store.provenance import host_id

    return f"{check_name(profile_id, 'profile_id')}--{check_name(host or host_id(), 'host')}.jsonl"


def _segment(path: Path, k: int) -> Path:
    """The ``k``-th segment's name: ``<store>.001.jsonl`` (numbered so that a folder's name order is the order
    they were closed in)."""
    return path.with_name(f"{path.name[: -len('.jsonl')]}.{k:03d}.jsonl")


def segments(path) -> list[Path]:
    """The closed segments of the store at ``path``, oldest first (:func:`roll_over` made them); a folder's
    readers read them, before the store itself, as the stores they are."""
    path = Path(path)
    found = []
    for k in itertools.count(1):
        if not _segment(path, k).exists():
            return found
        found.append(_segment(path, k))


def store_files(path) -> list[Path]:
    """The files of the store at ``path`` that exist, in the order they were written: its segments, then itself."""
    path = Path(path)
    return segments(path) + ([path] if path.exists() else [])


def roll_over(path, limit: int | None = None) -> list[Path]:
    """Close the store at ``path`` as segments when it holds ``limit`` bytes (:data:`SEGMENT_BYTES`) or more and
    ends with a whole line (a sweep does so under its lock, before it appends): its lines, in order and
    unchanged, in files of under ``limit`` bytes each (a longer line alone in one), each written whole, then
    the store removed; the next record begins a fresh file. Interrupted between, a row read twice is one run.
    The segments made ([] when none)."""
    from pcabench.store.safeio import write_file

    path, limit = Path(path), SEGMENT_BYTES if limit is None else limit
    try:
        if not path.is_file() or path.is_symlink() or path.stat().st_size < limit:
            return []
        data = path.read_bytes()
    except OSError:
        return []
    if not data.endswith(b"\n"):
        return []  # a torn last line: the sweep's hold mends it first, the next sweep closes the store
    chunks, chunk = [], b""
    for line in data.splitlines(keepends=True):
        if chunk and len(chunk) + len(line) >= limit:
            chunks.append(chunk)
            chunk = b""
        chunk += line
    chunks.append(chunk)
    first = len(segments(path)) + 1
    made = [write_file(_segment(path, first + i), c) for i, c in enumerate(chunks)]
    path.unlink()
    return made


def _open(path, flags: int, mode: int = 0o644) -> int:
    """``os.open`` that refuses a symbolic link, a FIFO or a device (StoreError naming the path): never
    blocks on a FIFO, never writes where a link points."""
    try:
        fd = os.open(path, flags | os.O_NOFOLLOW | os.O_CLOEXEC | os.O_NONBLOCK, mode)
    except OSError as exc:
        if exc.errno == errno.ELOOP:
            raise StoreError(f"{path} is a symbolic link; pcabench writes only regular files") from None
        if exc.errno == errno.ENXIO:  # a FIFO with no reader
            raise StoreError(f"{path} is not a regular file; pcabench writes only regular files") from None
        raise
    if not stat.S_ISREG(os.fstat(fd).st_mode):
        os.close(fd)
        raise StoreError(f"{path} is not a regular file; pcabench writes only regular files")
    return fd


def check_writable(path) -> Path:
    """Make sure a record can be appended to the store at ``path`` before any run; StoreError if not."""
    path = Path(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        os.close(_open(path, os.O_WRONLY | os.O_APPEND | os.O_CREAT))
    except OSError as exc:
        if isinstance(exc, StoreError):
            raise
        raise StoreError(f"results store {path} is not writable: {exc.strerror or exc}") from None
    free = shutil.disk_usage(path.parent).free
    if free < MIN_FREE_BYTES:
        raise StoreFull(
            f"results store {path}: only {free} bytes free on its file system (need at least {MIN_FREE_BYTES})"
        )
    return path


def _write_all(fd: int, data: bytes) -> None:
    while data:
        data = data[os.write(fd, data) :]


def _complete(line: bytes) -> bool:
    """Whether ``line`` is a whole JSON object (a crash cuts a record's closing brace off, so a cut one never
    is). Whether it is a valid record is for the reader to say: a record of a newer schema is whole."""
    try:
        return isinstance(json.loads(line.decode("utf-8")), dict)
    except (ValueError, RecursionError):
        return False


def _repair_tail(fd: int, path: Path) -> None:
    """Mend the last line of the locked store ``fd`` if it lacks its newline: a whole record gets the
    newline; a torn line is moved to ``<store>.torn`` and the file cut back to its last complete line."""
    size = os.fstat(fd).st_size
    if size == 0 or os.pread(fd, 1, size - 1) == b"\n":
        return
    pos, start = size, 0
    while pos > 0:  # find the last newline before the tail
        step = min(1 << 16, pos)
        pos -= step
        k = os.pread(fd, step, pos).rfind(b"\n")
        if k >= 0:
            start = pos + k + 1
            break
    tail = os.pread(fd, size - start, start)
    if _complete(tail):
        _write_all(fd, b"\n")
        return
    torn = _open(f"{path}.torn", os.O_WRONLY | os.O_APPEND | os.O_CREAT)
    try:
        _write_all(torn, tail + b"\n")
        os.fsync(torn)
    finally:
        os.close(torn)
    os.ftruncate(fd, start)
    warnings.warn(
        f"{path}: a torn last line ({len(tail)} bytes, a write cut short) was moved to {path}.torn",
        StoreWarning,
        stacklevel=3,
    )


def _regular_or_refuse(path: Path, what: str) -> None:
    """StoreError naming ``path`` unless it is absent or a regular file (not a link, a FIFO or a folder)."""
    try:
        st = os.lstat(path)
    except FileNotFoundError:
        return
    if not stat.S_ISREG(st.st_mode):
        kind = "a symbolic link" if stat.S_ISLNK(st.st_mode) else "not a regular file"
        raise StoreError(f"{path}, {what}, is {kind}; remove it (pcabench writes only regular files there)")


def check_torn(path) -> None:
    """StoreError before any run unless ``<store>.torn`` (where a torn last line is moved) can be written."""
    _regular_or_refuse(Path(f"{path}.torn"), "where a torn last line of the store is kept")


def reserve_path(path) -> Path:
    """The space a sweep keeps beside its store, given up to store the record that meets a full disk."""
    return Path(f"{path}.reserve")


def keep_reserve(path) -> Path:
    """Make the reserve of the store at ``path`` (:data:`RESERVE_BYTES`) unless it exists; its path."""
    reserve = reserve_path(path)
    try:
        fd = _open(reserve, os.O_WRONLY | os.O_CREAT | os.O_EXCL)
    except FileExistsError:
        _regular_or_refuse(reserve, "the store's reserve (room for the record that meets a full disk)")
        return reserve
    try:
        _write_all(fd, bytes(RESERVE_BYTES))
    finally:
        os.close(fd)
    return reserve


APPEND_WAIT = 10.0  # s an append waits for a store another writer holds (a sweep holds its store for its life)


def _lock_store(fd: int, path: Path) -> None:
    """Take the store ``fd``'s exclusive lock, waiting up to :data:`APPEND_WAIT` for another writer's append;
    StoreError if a sweep holds it (what its runs and their processes write is not taken)."""
    deadline = time.monotonic() + APPEND_WAIT
    while True:
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            return
        except BlockingIOError:
            if time.monotonic() > deadline:
                raise StoreError(
                    f"results store {path} is held by a sweep: only that sweep writes it while it runs"
                ) from None
            time.sleep(0.02)


def append(record, path, held: int | None = None) -> dict:
    """Append one run record (a RunRecord or dict) to the store at ``path`` safely; returns the row.

    ``held`` is the store's file descriptor, locked, of the sweep that holds it (:meth:`SweepLock.held`);
    without it the store is locked for this one write, and refused while a sweep holds it.
    A failed write leaves the file as it was. On a full disk the store's reserve (:class:`SweepLock`),
    if any, is given up and the write tried again: the record is then stored, and StoreError says the
    disk is full all the same, so that the sweep stops.
    """
    row = to_row(record)
    path = Path(path)
    why = validate(row)
    if why:
        raise InvalidRecord(f"results store {path}: a record that would not read back was not stored ({why})")
    line = (json.dumps(row, sort_keys=True, allow_nan=False) + "\n").encode("utf-8")
    freed = False
    try:
        if held is None:
            path.parent.mkdir(parents=True, exist_ok=True)
            fd = _open(path, os.O_RDWR | os.O_APPEND | os.O_CREAT)
        else:
            fd = held
        try:
            if held is None:
                _lock_store(fd, path)
            while True:
                _repair_tail(fd, path)
                before = os.fstat(fd).st_size
                try:
                    _write_all(fd, line)
                    os.fsync(fd)
                    break
                except OSError as exc:
                    os.ftruncate(fd, before)  # a failed write leaves no partial line behind
                    reserve = reserve_path(path)
                    if exc.errno not in FULL or freed or not reserve.is_file() or reserve.is_symlink():
                        raise
                    reserve.unlink()
                    freed = True
        finally:
            if held is None:
                os.close(fd)  # and with it the lock
    except StoreError:
        raise
    except OSError as exc:
        if exc.errno in FULL:
            raise StoreFull(f"results store {path}: the disk is full; the record was not stored") from None
        raise StoreError(f"results store {path} is not writable: {exc.strerror or exc}") from None
    if freed:
        raise StoreFull(
            f"results store {path}: the disk is full; this run's record was stored in the space "
            "kept for it, and the sweep stops: free some space and rerun to resume"
        )
    return row


def _behind_its_back(watch: StoreWatch) -> None:
    """One StoreWarning where the watched store was written behind its holder's back (pcabench/store/watch.py)."""
    said = watch.check()
    if said:
        warnings.warn(said, StoreWarning, stacklevel=3)


class SweepLock:
    """Held by a sweep for its whole life, before any work: a second sweep on the same store is refused
    (StoreError naming the holder).

    ``SweepLock(store_path)`` locks one store: ``<store>.lock`` exclusively and the folder's
    ``.sweeps.lock`` shared, and keeps ``<store>.reserve`` (see :func:`append`) until released.
    ``SweepLock(folder, whole_folder=True)`` locks every store of a folder, as a cluster sweep (whose
    records may belong to any machine) needs: ``.sweeps.lock`` exclusively.
    """

    FOLDER_LOCK = ".sweeps.lock"

    def __init__(self, path, whole_folder: bool = False):
        path = Path(path)
        self.folder = path if whole_folder else path.parent
        self.store = None if whole_folder else path
        self.fds, self.reserves, self.stores = [], [], {}
        self.watches: dict = {}  # store path -> StoreWatch: what the sweep has seen of each store it holds

    def _lock(self, path: Path, how: int, what: str, holder_wrote_pid: bool = True) -> int:
        fd = _open(path, os.O_RDWR | os.O_CREAT)
        self.fds.append(fd)
        try:
            fcntl.flock(fd, how | fcntl.LOCK_NB)
        except BlockingIOError:  # only an exclusive holder writes its pid
            holder = os.pread(fd, 200, 0).decode("utf-8", "replace").strip() if holder_wrote_pid else ""
            self.__exit__()
            raise StoreError(
                f"{what} is in use by another sweep{f' ({holder})' if holder else ''}; "
                "wait for it, or give this one its own --results folder"
            ) from None
        return fd

    def __enter__(self):
        try:
            self.folder.mkdir(parents=True, exist_ok=True)
            if self.store is None:
                fd = self._lock(
                    self.folder / self.FOLDER_LOCK,
                    fcntl.LOCK_EX,
                    f"results folder {self.folder}",
                    holder_wrote_pid=False,
                )
            else:
                self._lock(
                    self.folder / self.FOLDER_LOCK, fcntl.LOCK_SH, f"results folder {self.folder} (a cluster sweep)"
                )
                fd = self._lock(Path(f"{self.store}.lock"), fcntl.LOCK_EX, f"results store {self.store}")
                roll_over(self.store)  # locked, not yet held: a full store becomes segments, the sweep a fresh file
            os.ftruncate(fd, 0)
            os.pwrite(fd, f"pid {os.getpid()}".encode(), 0)
            if self.store is not None:
                self.hold(self.store)
        except StoreError:
            self.__exit__()
            raise
        except OSError as exc:
            self.__exit__()
            raise StoreError(f"results folder {self.folder} is not writable: {exc.strerror or exc}") from None
        return self

    def hold(self, store_path) -> int:
        """Hold the store at ``store_path`` (of the locked folder) until released: its file locked for writing,
        so that no other process appends to it (a run's own processes included), and its reserve kept; its
        locked file descriptor, which :func:`append` takes as ``held``."""
        store_path = Path(store_path)
        if store_path not in self.stores:
            check_torn(store_path)
            fd = _open(store_path, os.O_RDWR | os.O_APPEND | os.O_CREAT)
            self.fds.append(fd)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                raise StoreError(f"results store {store_path} is being written by another process") from None
            self.reserves.append(keep_reserve(store_path))
            _repair_tail(fd, store_path)  # whole lines only: what the watch sees ends with one
            self.stores[store_path] = fd
            self.watches[store_path] = StoreWatch(fd, store_path)
        return self.stores[store_path]

    def held(self, store_path) -> int | None:
        """The held store's locked file descriptor (:meth:`hold`), or None."""
        return self.stores.get(Path(store_path))

    def append(self, record, store_path) -> dict:
        """:func:`append` ``record`` to the held store at ``store_path`` (held here if it is not yet), after moving
        aside whatever was written into it behind this sweep's back (pcabench/store/watch.py); the row."""
        store_path = Path(store_path)
        fd = self.hold(store_path)
        watch = self.watches[store_path]
        _behind_its_back(watch)
        try:
            return append(record, store_path, held=fd)
        finally:
            watch.saw_append()

    def __exit__(self, *exc):
        for watch in self.watches.values():  # the last run's process may have written after the last append
            try:
                _behind_its_back(watch)
            except OSError:
                pass
        self.watches = {}
        for reserve in self.reserves:
            reserve.unlink(missing_ok=True)
        for fd in self.fds:
            os.close(fd)
        self.fds, self.reserves, self.stores = [], [], {}


def _no_constant(name):
    raise ValueError(f"{name} is not standard JSON")


def validate(row) -> str:
    """Why ``row`` is not a usable run record ('' if it is): the schema (``pcabench/store/schema.py``), then the
    scene's own checks."""
    why = schema.check(row)
    if why:
        return why
    try:
        scene = Scene(
            **{k: v for k, v in row["scene"].items() if k in Scene.PARAMETERS},
            memory_limit_bytes=sys.maxsize,
        )
    except (SceneError, TypeError, ValueError, OverflowError) as exc:
        return f"'scene' is not a valid scene ({exc})"
    return derived_problem(row, scene)


def derived_problem(row: dict, scene: Scene) -> str:
    """Why a row's derived fields do not follow from its scene ('' if they do): the particle count, the steps
    asked and taken, the precision, model, integrator and dx, each against the scene the row stores (its own
    derived keys, and the scene rebuilt: a row's particle count is the scene's, never its own word)."""
    stored = row["scene"]
    n = stored.get("n_particles", scene.n_particles)
    if row["n_particles"] != n:
        return f"'n_particles' {row['n_particles']} is not its scene's {n}"
    # open edges whose layer width was left to the absorber's default: that default changed (issue 41), so such
    # a row's count is its scene's stored one, not today's rebuild
    if not (scene.open and stored.get("layer_width") is None) and scene.n_particles != n:
        return f"'n_particles' {n} is not the {scene.n_particles} particles its scene's lattice holds"
    n_steps = stored.get("n_steps", scene.n_steps)
    if row.get("steps_requested") not in (None, 0, n_steps):
        return f"'steps_requested' {row['steps_requested']} is not its scene's {n_steps} steps"
    if not row["steps"] <= n_steps:
        return f"'steps' {row['steps']} is more than its scene's {n_steps}"
    for key in ("precision", "model", "integrator", "dx"):
        if key in row and row[key] != getattr(scene, key):
            return f"{key!r} {row[key]!r:.40} is not its scene's {getattr(scene, key)!r:.40}"
    return ""


def read_regular(path, limit: int = MAX_STORE_BYTES, follow: bool = False) -> bytes:
    """The bytes of the regular file ``path`` (a link is not followed unless ``follow``); OSError naming
    it if it is a link, not a regular file (a FIFO, a device) or larger than ``limit`` bytes."""
    flags = os.O_RDONLY | os.O_CLOEXEC | os.O_NONBLOCK | (0 if follow else os.O_NOFOLLOW)
    try:
        fd = os.open(path, flags)
    except OSError as exc:
        if exc.errno == errno.ELOOP:
            raise OSError(errno.ELOOP, "a symbolic link, not followed", str(path)) from None
        raise
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise OSError(errno.EINVAL, "not a regular file", str(path))
        if st.st_size > limit:
            raise OSError(errno.EFBIG, f"larger than {limit} bytes", str(path))
        chunks, left = [], limit + 1
        while left > 0:
            chunk = os.read(fd, min(left, 1 << 20))
            if not chunk:
                break
            chunks.append(chunk)
            left -= len(chunk)
        if left <= 0:
            raise OSError(errno.EFBIG, f"larger than {limit} bytes", str(path))
        return b"".join(chunks)
    finally:
        os.close(fd)


def _canonical(record) -> str:
    return json.dumps(_clean(record.as_dict()), sort_keys=True, default=str)


def read_records(paths) -> list:
    """Every valid row of the stores ``paths`` (files or folders of *.jsonl) as a typed record
    (:meth:`~pcabench.store.record.RunRecord.from_row`: the schema's fields only), one per run.

    A line that is not valid UTF-8, not JSON, not a record, or fails :func:`validate` is skipped with one
    StoreWarning naming its file and line. One ``run_id`` read twice with the same record (a store copied
    into another) is one run. Read twice with different records, the later write in the store's order wins:
    the one read later (files in the order given, a folder's by name; lines in their order, which is the
    order they were appended in), never by the rows' own ``timestamp`` (a row's word for itself: a copy
    with a later one must not win); one StoreWarning names both places.
    """
    from pcabench.store.record import RunRecord

    if isinstance(paths, (str, Path)):
        paths = [paths]
    kept: dict[str, tuple] = {}  # run_id -> (record, where, canonical form)
    for path in paths:
        path = Path(path)
        folder = path.is_dir()
        files = sorted(path.glob("*.jsonl")) if folder else [path]
        for file in files:
            if not folder and not file.exists():
                continue
            try:  # an entry of a folder: a regular file, not a link; a named file: followed, but regular
                data = read_regular(file, follow=not folder)
            except OSError as exc:
                warnings.warn(f"{file}: {exc.strerror or exc}; skipped", StoreWarning, stacklevel=2)
                continue
            lines = data.split(b"\n")
            if lines and lines[-1] == b"":
                lines.pop()  # the newline that ends the last record
            for number, raw in enumerate(lines, 1):
                if not raw.strip():
                    warnings.warn(f"{file}:{number}: a blank line, skipped", StoreWarning, stacklevel=2)
                    continue
                try:
                    row = json.loads(raw.decode("utf-8"), parse_constant=_no_constant)
                except UnicodeDecodeError:
                    why = "not UTF-8 text"
                except json.JSONDecodeError as exc:
                    why = f"not JSON ({exc.msg}; a torn or hand-edited line?)"
                except ValueError as exc:  # NaN or Infinity
                    why = f"not standard JSON ({exc})"
                except RecursionError:
                    why = "not a record (nested too deeply)"
                else:
                    why = validate(row)
                if why:
                    warnings.warn(f"{file}:{number}: {why}; row skipped", StoreWarning, stacklevel=2)
                    continue
                record = RunRecord.from_row(row)
                record.run_id = row.get("run_id") or run_id(row)
                where, form = f"{file}:{number}", _canonical(record)
                if record.run_id not in kept:
                    kept[record.run_id] = (record, where, form)
                    continue
                first, first_where, first_form = kept[record.run_id]
                if form == first_form:
                    continue  # the same record, copied
                warnings.warn(  # the store's order decides, never a row's word for its own time
                    f"run_id {record.run_id} is stored twice with different records, at {first_where} and "
                    f"{where}; the later write in the store's order ({where}) is kept",
                    StoreWarning,
                    stacklevel=2,
                )
                kept[record.run_id] = (record, where, form)
    return [record for record, _, _ in kept.values()]


def read_rows(paths) -> list[dict]:
    """:func:`read_records` as dicts (:meth:`~pcabench.store.record.RunRecord.as_dict`): what every reader takes."""
    return [record.as_dict() for record in read_records(paths)]
