"""A sweep on a Dask cluster: each run a Dask task, run in its own child process on a worker.

    pcabench study --quick --cluster local:4           # a LocalCluster of 4 workers, started and stopped here
    pcabench study --paper --cluster tcp://host:8786   # an existing scheduler (dask-jobqueue, SSHCluster, ...)

Dask (``dask.distributed``) schedules; pcabench adds no scheduler of its own.
Each task runs :func:`pcabench.sweep.run_child` on the worker, so a crash,
hang or out-of-memory is recorded as in a local sweep and never takes the
worker down, and the record carries the worker's hardware profile and host,
captured there. Every task asks for one ``timing`` resource (and GPU runs for
one ``GPU``): with one ``timing`` slot per worker, timed runs never share a
worker's cores or card. The client is the only writer: it locks the whole
``--results`` folder before any work (no other sweep may write there while it
runs), and each record goes to its machine's store there as it arrives, so a
killed client loses no finished run, and rerunning the command resumes. A run whose worker
dies is retried on another worker by Dask (``distributed.scheduler.allowed-failures``
times), then recorded as ``error`` (lost).
"""
from __future__ import annotations

import subprocess
import sys
import time
from contextlib import ExitStack
from pathlib import Path

from . import store
from .predict import predicted_seconds
from .profiles import machine_id
from .provenance import git_commit, host_id
from .record import step_seconds
from solvers import solver_class

from .spec import OptionError, RunSpec, identity
from .sweep import RETRIED, eta_text, failed_record, run_child

TIMING = "timing"  # one per worker: one timed run at a time
LOOPBACK = "127.0.0.1"  # a local cluster (scheduler, workers, dashboard) listens here only


def dask_distributed():
    """The dask.distributed module, or OptionError naming the extra to install."""
    try:
        import dask.distributed
    except ImportError:
        raise OptionError("--cluster needs Dask: pip install -e \".[cluster]\"") from None
    return dask.distributed


def connect(address: str, stack: ExitStack):
    """A Client for ``address``: ``local:N`` starts a LocalCluster of N one-thread workers on loopback only
    (closed with ``stack``)."""
    dd = dask_distributed()
    if address.startswith("local:"):
        try:
            n = int(address.split(":", 1)[1])
        except ValueError:
            n = 0
        if n < 1:
            raise OptionError(f"--cluster local:N needs N >= 1 workers (got {address!r})")
        cluster = stack.enter_context(dd.LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                                      host=LOOPBACK, dashboard_address=f"{LOOPBACK}:0",
                                                      resources={TIMING: 1}))
        return stack.enter_context(dd.Client(cluster))
    if "://" not in address:
        raise OptionError(f"--cluster must be a scheduler address such as tcp://host:8786, or local:N "
                          f"(got {address!r})")
    try:
        return stack.enter_context(dd.Client(address, timeout="30s"))
    except OSError as exc:
        raise OptionError(f"--cluster {address}: no scheduler answers ({exc})") from None


def worker_resources(client) -> dict:
    """{worker address: its resources}."""
    return {w: info.get("resources", {}) for w, info in client.scheduler_info()["workers"].items()}


def task_resources(spec: RunSpec) -> dict:
    """What one run of ``spec`` takes on a worker: its solver's ``resources`` (one ``timing`` slot; a GPU run
    one ``GPU`` too)."""
    return dict(solver_class(spec.solver).resources)


def run_on_worker(spec_json: str, timeout: float, commit: str) -> dict:
    """On a worker: run the spec in a child process; its record (with the worker's machine id and host)."""
    spec, machine = RunSpec.from_json(spec_json), machine_id()
    try:
        return run_child(spec, timeout, commit, machine, stream=None)
    except subprocess.TimeoutExpired:
        return store.to_row(failed_record(spec, "timeout", f"past the run budget of {timeout:.0f} s", machine,
                                          timeout))


def cluster_sweep(specs: list[RunSpec], results: Path, run_budget: float, address: str, stream=sys.stderr,
                  retry_failed: bool = False) -> list[dict]:
    """Run ``specs`` as Dask tasks on the cluster at ``address``; each record stored as it arrives."""
    results = Path(results)
    with store.SweepLock(results, whole_folder=True) as lock:  # before any work: every store it may write
        return _cluster_sweep(specs, results, run_budget, address, stream, retry_failed, Stores(results, lock))


def _cluster_sweep(specs, results, run_budget, address, stream, retry_failed, stores) -> list[dict]:
    commit = git_commit()
    rows = store.read_rows(results)
    # on a cluster a run may land on any worker: it is done once stored from any of them
    done = {_unplaced(r["solver"], r.get("threads", 1), r.get("scene") or {}, r.get("preset", ""), r.get("commit"),
                      r.get("pair_loop", "")) for r in rows if not (retry_failed and r.get("status") in RETRIED)}
    specs = list(dict.fromkeys(s.resolved() for s in specs))  # a run given twice is run once
    todo = [s for s in specs if _unplaced(s.solver, s.threads, s.scene, s.preset, commit, s.pair_loop) not in done]
    for s in specs:
        if s not in todo:
            print(f"{s.label}: already stored", file=stream, flush=True)
    finished = [r for r in rows if r.get("status") == "ok"]
    stored = []
    with ExitStack() as stack:
        client = connect(address, stack)
        print(f"pcabench: Dask dashboard at {client.dashboard_link}", file=stream, flush=True)
        workers = worker_resources(client)
        for need in {tuple(sorted(task_resources(s))) for s in todo}:
            if not any(all(r.get(k, 0) >= 1 for k in need) for r in workers.values()):
                raise OptionError(f"--cluster {address}: no worker offers the resources {', '.join(need)}; start "
                                  f"workers with --resources \"{' '.join(f'{k}=1' for k in need)}\"")
        dd = dask_distributed()
        futures = {}
        for spec in todo:
            seconds, why = predicted_seconds(spec, finished)
            if seconds is not None and seconds > run_budget:
                row = store.to_row(failed_record(spec, "skipped", f"{why} > run budget {run_budget:.0f} s",
                                                 machine_id()))
                stored.append(stores.append(row))
                print(f"{spec.label}: skipped, {why}", file=stream, flush=True)
                continue
            future = client.submit(run_on_worker, spec.to_json(), run_budget, commit, pure=False,
                                   resources=task_resources(spec), key=f"pcabench-run-{len(futures)}")
            futures[future] = spec
        t0, failed, left = time.perf_counter(), 0, list(futures.values())
        for future in dd.as_completed(futures):
            spec = futures[future]
            try:
                row = future.result()
            except Exception as exc:  # noqa: BLE001 - the task never returned: its workers died (KilledWorker)
                row = store.to_row(failed_record(spec, "error", f"lost: {type(exc).__name__}: {exc}",
                                                 machine_id()))
            stored.append(stores.append(row))
            left.remove(spec)
            failed += row["status"] != "ok"
            running = sum(f.status == "pending" for f in futures)
            per_run = (time.perf_counter() - t0) / len(stored) / max(len(workers), 1)
            mse = row.get("mse")
            print(f"{spec.label} on {row.get('profile_id')}/{row.get('host')}: {row['status']}, step "
                  f"{1e3 * step_seconds(row['stages'], row['steps']):.2f} ms, MSE "
                  f"{'-' if mse is None else f'{mse:.4g}'} | sweep: {len(stored)}/{len(todo)} done, "
                  f"{running} running or queued, {failed} not ok, {eta_text(left, finished, per_run, 'the cluster')}",
                  file=stream, flush=True)
            finished.append(row)
    return stored


def _unplaced(solver, threads, scene, preset, commit, pair_loop) -> str:
    """:func:`pcabench.spec.identity` without the machine: a cluster places a run on any worker."""
    return identity(solver, int(threads or 1), scene, preset, "", commit or "", "", pair_loop)


class Stores:
    """The client's stores under ``results``, one per machine, all under ``lock`` (the folder's, held by the
    cluster sweep); each store's reserve is kept from its first write."""

    def __init__(self, results: Path, lock: store.SweepLock):
        self.results, self.lock, self.paths = results, lock, set()

    def append(self, row: dict) -> dict:
        path = self.results / store.store_name(row["profile_id"], row.get("host") or host_id())
        if path not in self.paths:
            store.check_writable(path)
            self.lock.keep_reserve(path)
            self.paths.add(path)
        return store.append(row, path)
