"""A sweep: a list of run specs, each run in its own child process, stored as it finishes.

Each run is a child process (``python -m pcabench.child``) with a time budget:
a crash, hang or out-of-memory in one run is recorded (status error /
timeout / out-of-memory) and the sweep goes on. The sweep is the only writer
of the store; every finished run is appended at once, and a rerun skips the
runs the store already holds for this machine (hardware profile and host),
commit and preset (:func:`pcabench.spec.identity`), so an interrupted sweep
resumes where it stopped. A run predicted to take longer than the run budget
is stored as ``skipped`` with the prediction.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

from . import store
from .predict import predicted_seconds
from .profiles import profile_id as this_profile_id
from .provenance import git_commit, host_id
from .record import RunRecord, step_seconds
from .spec import RunSpec, identity, row_identity


def failed_record(spec: RunSpec, status: str, message: str, profile: str, seconds: float | None = None) -> RunRecord:
    """The record of a run that made no result of its own (skipped, timed out, crashed)."""
    if seconds is not None:
        message = f"{message} (after {seconds:.0f} s)"
    record = RunRecord.before_run(spec.scene, spec.solver, spec.threads, status=status, message=message,
                                  profile_id=profile, pair_loop=spec.pair_loop)
    record.preset = spec.preset
    return record


def run_child(spec: RunSpec, timeout: float, commit: str) -> dict:
    """Run ``spec`` in a child process; its record as a row. Raises subprocess.TimeoutExpired."""
    cmd = [sys.executable, "-m", "pcabench.child", spec.to_json()]
    env = dict(os.environ, PCABENCH_COMMIT=commit)  # every run of a sweep carries the sweep's commit
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, env=env)
    lines = proc.stdout.strip().splitlines()
    if proc.returncode == 0 and lines:
        return json.loads(lines[-1])
    status = "out-of-memory" if proc.returncode in (-9, 137) else "error"
    return store.to_row(failed_record(spec, status, proc.stderr.strip()[-400:], this_profile_id()))


def sweep(specs: list[RunSpec], store_path: Path, run_budget: float, sweep_budget: float,
          stream=sys.stderr) -> list[dict]:
    """Run ``specs`` (skipping those already stored), one child process each; the rows stored.

    Before each run its time is predicted from this machine's finished runs
    (``predict.py``); a run predicted past ``run_budget`` is stored as
    ``skipped`` with the prediction instead of being run into the wall.
    """
    profile, commit, host = this_profile_id(), git_commit(), host_id()
    rows = store.read_rows(store_path) if Path(store_path).exists() else []
    done = {row_identity(r) for r in rows}
    mine = [r for r in rows if r.get("profile_id") == profile]
    t_start, stored = time.perf_counter(), []
    for i, spec in enumerate(specs, 1):
        spec = spec.resolved()
        label = f"[{i}/{len(specs)}] {spec.label}"
        if identity(spec.solver, spec.threads, spec.scene, spec.preset, profile, commit, host, spec.pair_loop) in done:
            print(f"{label}: already stored", file=stream, flush=True)
            continue
        left = sweep_budget - (time.perf_counter() - t_start)
        if left <= 0:
            print(f"{label}: sweep budget spent, stopping (rerun to resume)", file=stream, flush=True)
            break
        seconds, why = predicted_seconds(spec, mine)
        if seconds is not None and seconds > run_budget:
            stored.append(store.append(failed_record(spec, "skipped", f"{why} > run budget {run_budget:.0f} s",
                                                     profile), store_path))
            print(f"{label}: skipped, {why}", file=stream, flush=True)
            continue
        t0 = time.perf_counter()
        try:
            row = run_child(spec, min(run_budget, left), commit)
        except subprocess.TimeoutExpired:
            if left < run_budget:  # the sweep's budget ran out, not the run's: nothing to record
                print(f"{label}: sweep budget spent during the run, not stored (rerun to resume)",
                      file=stream, flush=True)
                break
            row = failed_record(spec, "timeout", f"past the run budget of {run_budget:.0f} s", profile,
                                time.perf_counter() - t0)
        row = store.append(row, store_path)
        stored.append(row)
        mine.append(row)
        eta = (time.perf_counter() - t_start) / len(stored) * (len(specs) - i)
        step_ms = 1e3 * step_seconds(row["stages"], row["steps"])
        mse = row.get("mse")
        print(f"{label}: {row['status']}, step {step_ms:.2f} ms, MSE {'-' if mse is None else f'{mse:.4g}'}, "
              f"{time.perf_counter() - t0:.1f} s (sweep eta <= {eta / 60:.1f} min)", file=stream, flush=True)
    return stored
