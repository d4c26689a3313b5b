"""A sweep: a list of run specs, each run in its own child process, stored as it finishes.

Each run is a child process (``python -m pcabench.child``) with a time budget:
a crash, hang or out-of-memory in one run is recorded (status error /
timeout / out-of-memory, naming the signal or exit code) and the sweep goes
on. A child dies with its parent (Linux: PR_SET_PDEATHSIG), so a killed sweep
leaves no run going on unsupervised. The sweep holds the store's lock and is
its only writer; every finished run is appended at once, and a rerun skips
the runs the store already holds for this machine (hardware profile and
host), commit and preset (:func:`pcabench.spec.identity`), so an interrupted
sweep resumes where it stopped (a run given twice is run once); ``retry_failed``
reruns timeouts, skips and errors. A run predicted to take longer than the run budget is stored as
``skipped`` with the prediction.
"""
from __future__ import annotations

import ctypes
import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

from . import store
from .memory import cgroup_memory_folders
from .predict import predicted_seconds
from .profiles import MACHINE_ID_ENV, machine_id
from .provenance import git_commit, host_id
from .record import RunRecord, step_seconds
from .spec import RunSpec, identity, row_identity

RETRIED = ("timeout", "skipped", "error")  # statuses --retry-failed runs again


def failed_record(spec: RunSpec, status: str, message: str, profile: str, seconds: float | None = None) -> RunRecord:
    """The record of a run that made no result of its own (skipped, timed out, crashed)."""
    if seconds is not None:
        message = f"{message} (after {seconds:.0f} s)"
    record = RunRecord.before_run(spec.scene, spec.solver, spec.threads, status=status, message=message,
                                  profile_id=profile, pair_loop=spec.pair_loop)
    record.preset = spec.preset
    return record


def _die_with_parent() -> None:
    """In the child, before exec: receive SIGKILL when the parent dies (Linux only; else nothing)."""
    try:
        ctypes.CDLL("libc.so.6", use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG = 1
    except (OSError, AttributeError):
        pass


def oom_kills() -> int | None:
    """The kernel's count of OOM kills so far in this process's cgroup and its ancestors (v2
    ``memory.events``, v1 ``memory.oom_control``), or None where the kernel does not say."""
    counts = []
    for *_, events in cgroup_memory_folders():
        try:
            with open(events) as f:
                counts += [int(line.split()[1]) for line in f if line.startswith("oom_kill ")]
        except (OSError, ValueError, IndexError):
            pass
    return sum(counts) if counts else None


def exit_status(returncode: int, oom_before: int | None, oom_after: int | None) -> tuple[str, str]:
    """(status, what happened) of a child that ended without a record."""
    if returncode < 0:
        name = signal.Signals(-returncode).name if -returncode in signal.valid_signals() else f"signal {-returncode}"
        if -returncode == signal.SIGKILL and oom_before is not None and oom_after is not None \
                and oom_after > oom_before:
            return "out-of-memory", f"killed by {name}: the kernel's OOM killer (cgroup oom_kill count rose)"
        return "error", f"killed by {name}"
    return "error", f"exit code {returncode}"


def run_child(spec: RunSpec, timeout: float, commit: str, machine: str, stream=sys.stderr) -> dict:
    """Run ``spec`` in a child process, relaying its progress to ``stream``; its record as a row.

    The child's record carries ``commit`` and ``machine`` (the parent's :func:`~pcabench.profiles.machine_id`).

    Raises subprocess.TimeoutExpired (the child is killed first) past ``timeout`` seconds.
    """
    cmd = [sys.executable, "-m", "pcabench.child", spec.to_json()]
    env = {**os.environ, "PCABENCH_COMMIT": commit, MACHINE_ID_ENV: machine}  # every run carries the sweep's
    oom_before = oom_kills()
    proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env,
                            preexec_fn=_die_with_parent if sys.platform.startswith("linux") else None)
    tail = []

    def relay():  # the child's progress lines go on to the user; the end is kept for the record
        for raw in iter(lambda: proc.stderr.read1(4096), b""):
            text = raw.decode("utf-8", "replace")
            if stream is not None:
                stream.write(text)
                stream.flush()
            tail.append(text)
            del tail[:-50]

    reader = threading.Thread(target=relay, daemon=True)
    reader.start()
    try:
        out, _ = proc.communicate(timeout=timeout)
    except BaseException:
        proc.kill()
        proc.wait()
        raise
    finally:
        reader.join(timeout=5)
        if stream is not None and tail and not tail[-1].endswith("\n"):
            stream.write("\n")  # end the child's last progress line
    lines = out.decode("utf-8", "replace").strip().splitlines()
    if proc.returncode == 0 and lines:
        return json.loads(lines[-1])
    status, what = exit_status(proc.returncode, oom_before, oom_kills())
    stderr = "".join(tail).strip()[-400:]
    return store.to_row(failed_record(spec, status, what + (f": {stderr}" if stderr else ""), machine))


def run_here(spec: RunSpec, timeout: float, commit: str, machine: str, stream=sys.stderr) -> dict:
    """Run ``spec`` in this process: no crash isolation and no per-run time limit (``timeout`` is not
    enforced), but compiled kernels are kept from run to run. For the GPU check, whose budget is minutes."""
    from .child import run_spec

    return run_spec(spec)


def eta_text(remaining: list[RunSpec], mine: list[dict], seconds_per_run: float | None,
             whose: str = "this host's") -> str:
    """The sweep's ETA and how sure it is: runs predicted from ``whose`` timings, the rest at the mean so far."""
    if not remaining:
        return "done"
    predicted = [predicted_seconds(s, mine)[0] for s in remaining]
    known = [p for p in predicted if p is not None]
    unknown = len(predicted) - len(known)
    if unknown and seconds_per_run is None:
        return f"eta unknown ({len(remaining)} runs left, {len(known)} predicted)"
    total = sum(known) + unknown * (seconds_per_run or 0.0)
    how = (f"{len(known)} of {len(remaining)} runs predicted from {whose} timings"
           + (f", {unknown} at the mean so far" if unknown else ""))
    return f"eta {total / 60:.1f} min ({how})"


def sweep(specs: list[RunSpec], store_path: Path, run_budget: float, sweep_budget: float,
          stream=sys.stderr, retry_failed: bool = False, runner=None) -> list[dict]:
    """Run ``specs`` (skipping those already stored), one child process each (``runner``); the rows stored.

    Before each run its time is predicted from this host's finished runs
    (``predict.py``); a run predicted past ``run_budget`` is stored as
    ``skipped`` with the prediction instead of being run into the wall.
    """
    store.check_writable(store_path)
    with store.SweepLock(store_path):
        return _sweep(specs, Path(store_path), run_budget, sweep_budget, stream, retry_failed, runner or run_child)


def _sweep(specs, store_path, run_budget, sweep_budget, stream, retry_failed, runner) -> list[dict]:
    profile, commit, host = machine_id(), git_commit(), host_id()
    rows = store.read_rows(store_path) if store_path.exists() else []
    done = {row_identity(r) for r in rows if not (retry_failed and r.get("status") in RETRIED)}
    mine = [r for r in rows if r.get("profile_id") == profile and r.get("host") == host]
    t_start, stored, failed = time.perf_counter(), [], 0
    specs = list(dict.fromkeys(s.resolved() for s in specs))  # a run given twice is run once
    for i, spec in enumerate(specs, 1):
        label = f"[{i}/{len(specs)}] {spec.label}"
        if identity(spec.solver, spec.threads, spec.scene, spec.preset, profile, commit, host,
                    spec.pair_loop) in done:
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
        print(f"{label}: running" + (f" (predicted {seconds:.0f} s)" if seconds is not None else ""),
              file=stream, flush=True)
        t0 = time.perf_counter()
        try:
            row = runner(spec, min(run_budget, left), commit, profile, stream)
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
        failed += row["status"] != "ok"
        step_ms = 1e3 * step_seconds(row["stages"], row["steps"])
        mse = row.get("mse")
        made = [r for r in stored if r["status"] != "skipped"]
        per_run = (time.perf_counter() - t_start) / len(made) if made else None
        print(f"{label}: {row['status']}, step {step_ms:.2f} ms, MSE {'-' if mse is None else f'{mse:.4g}'}, "
              f"{time.perf_counter() - t0:.1f} s | sweep: {i}/{len(specs)} done, {failed} not ok, "
              f"{eta_text(specs[i:], mine, per_run)}", file=stream, flush=True)
    return stored
