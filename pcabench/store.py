"""The results store: append-only JSON lines, one run record per line.

Each finished run is appended and flushed to disk at once, so an interrupted
sweep loses no finished run. Stores taken on different machines merge by
concatenation: a run is identified by its ``run_id`` (profile, commit,
solver, scene, timestamp and host), and duplicates are dropped on load.
"""
from __future__ import annotations

import hashlib
import json
import math
import os
from pathlib import Path

from .record import STEP_STAGES


def run_id(row: dict) -> str:
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
    """The stored form of a run record (a RunRecord or dict): JSON-safe (NaN as null), with its run_id."""
    row = _clean(record.as_dict() if hasattr(record, "as_dict") else dict(record))
    row.setdefault("run_id", run_id(row))
    return row


def append(record, path) -> dict:
    """Append one run record (a RunRecord or dict) to the store at ``path``; returns the row."""
    row = to_row(record)
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    line = json.dumps(row, sort_keys=True) + "\n"
    with open(path, "a", encoding="utf-8") as f:
        f.write(line)
        f.flush()
        os.fsync(f.fileno())
    return row


def read_rows(paths) -> list[dict]:
    """Every complete row of the stores ``paths`` (a torn last line is skipped), deduplicated."""
    if isinstance(paths, (str, Path)):
        paths = [paths]
    seen, rows = set(), []
    for path in paths:
        path = Path(path)
        files = sorted(path.glob("*.jsonl")) if path.is_dir() else [path]
        for file in files:
            if not file.exists():
                continue
            for line in file.read_text(encoding="utf-8").splitlines():
                try:
                    row = json.loads(line)
                except json.JSONDecodeError:
                    continue  # a run killed mid-write leaves at most one torn line
                rid = row.get("run_id") or run_id(row)
                if rid not in seen:
                    seen.add(rid)
                    rows.append(row)
    return rows


def load(paths):
    """The stores ``paths`` as one tidy pandas DataFrame (stage times as columns t_<stage>)."""
    import pandas as pd

    rows = read_rows(paths)
    flat = []
    for row in rows:
        r = {k: v for k, v in row.items() if k not in ("stages", "scene", "versions")}
        for stage, seconds in (row.get("stages") or {}).items():
            r[f"t_{stage}"] = seconds
        scene = row.get("scene") or {}
        for key in ("strip_height", "cutoff_factor", "h_factor", "cfl", "t_final", "height"):
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
        step_total = sum(df[f"t_{s}"] for s in STEP_STAGES)
        df["t_step"] = step_total / df["steps"].clip(lower=1)
        df["t_solution"] = df["t_init"] + step_total  # s, without JIT and I/O
    return df
