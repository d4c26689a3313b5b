"""A sweep on a Dask cluster: each run a Dask task, run in its own child process on a worker.

    pcabench study --quick --cluster local:4           # a LocalCluster of 4 workers, started and stopped here
    pcabench study --paper --cluster tcp://host:8786   # an existing scheduler (dask-jobqueue, SSHCluster, ...)

Dask (``dask.distributed``) schedules; pcabench adds no scheduler of its own.
Each task runs :func:`pcabench.execute.sweep.run_child` on the worker, so a crash,
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

import math
import subprocess
import sys
from contextlib import ExitStack
from pathlib import Path

from pcabench import store
from pcabench.execute.sweep import Executor, failed_record, run_child, run_specs
from pcabench.machine.profiles import machine_id
from pcabench.spec import OptionError, RunSpec, identity, row_code
from pcabench.store.provenance import git_commit, host_id
from solvers import solver_class

TIMING = "timing"  # one per worker: one timed run at a time
LOOPBACK = "127.0.0.1"  # a local cluster (scheduler, workers, dashboard) listens here only


def dask_distributed():
    """The dask.distributed module, or OptionError naming the extra to install."""
    try:
        import dask.distributed
    except ImportError:
        raise OptionError('--cluster needs Dask: pip install -e ".[cluster]"') from None
    return dask.distributed


def check_address(address: str) -> None:
    """One line (OptionError) unless ``address`` is ``local:N`` (N >= 1) or a scheduler's ``proto://host:port``:
    checked before anything is printed or started."""
    if address.startswith("local:"):
        try:
            n = int(address.split(":", 1)[1])
        except ValueError:
            n = 0
        if n < 1:
            raise OptionError(f"--cluster local:N needs N >= 1 workers (got {address!r})")
    elif "://" not in address:
        raise OptionError(
            f"--cluster must be a scheduler address such as tcp://host:8786, or local:N (got {address!r})"
        )


def connect(address: str, stack: ExitStack, stream=sys.stderr):
    """A Client for ``address``: ``local:N`` starts a LocalCluster of N one-thread workers on loopback only
    (closed with ``stack``), over TLS with credentials made for it alone (distributed's
    ``Security.temporary``): a scheduler on loopback is reachable by every user of the machine, and a Dask
    client runs code on the workers as their user, so only this process may be one. A remote ``tcp://``
    scheduler takes any client that reaches it: one line says so (use ``tls://`` with certificates)."""
    dd = dask_distributed()
    check_address(address)
    if address.startswith("local:"):
        n = int(address.split(":", 1)[1])
        try:
            security = dd.Security.temporary()  # a CA and a key for this cluster only, in memory
        except ImportError:
            raise OptionError('--cluster local:N needs the cryptography package: pip install -e ".[cluster]"') from None
        cluster = stack.enter_context(
            dd.LocalCluster(
                n_workers=n,
                threads_per_worker=1,
                processes=True,
                host=LOOPBACK,
                protocol="tls://",
                security=security,
                dashboard_address=f"{LOOPBACK}:0",
                resources={TIMING: 1},
            )
        )
        return stack.enter_context(dd.Client(cluster, security=security))
    if address.startswith("tcp://") and stream is not None:
        print(
            f"--cluster {address}: a tcp:// scheduler runs the code of any client that reaches it, as its workers' "
            "user; secure it with tls:// and certificates (docs/store.md, 'Sweeps on a Dask cluster')",
            file=stream,
        )
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
        return store.to_row(failed_record(spec, "timeout", f"past the run budget of {timeout:.0f} s", machine, timeout))


class DaskExecutor(Executor):
    """Runs as Dask tasks, up to one per worker in flight (so predictions learn from the runs that finish);
    a run is done once stored from any worker."""

    whose = "the cluster"

    def __init__(self, client, commit: str):
        self.client, self.commit, self.futures = client, commit, {}
        self.slots = max(len(worker_resources(client)), 1)
        self.finished = dask_distributed().as_completed()

    def key(self, spec, code):
        return _unplaced(spec.solver, spec.threads, spec.scene, spec.preset, code, spec.pair_loop)

    def row_key(self, row):
        return _unplaced(
            row["solver"],
            row.get("threads", 1),
            row.get("scene") or {},
            row.get("preset", ""),
            row_code(row),
            row.get("pair_loop", ""),
        )

    def informs(self, row):
        return row.get("status") == "ok"

    def start(self, spec, timeout, budget_cut):
        future = self.client.submit(
            run_on_worker,
            spec.to_json(),
            timeout,
            self.commit,
            pure=False,
            resources=task_resources(spec),
            key=f"pcabench-run-{len(self.futures)}",
        )
        self.futures[future] = spec
        self.finished.add(future)

    def wait(self):
        future = next(self.finished)
        spec = self.futures[future]
        try:
            return spec, future.result()
        except Exception as exc:  # noqa: BLE001 - the task never returned: its workers died (KilledWorker)
            return spec, store.to_row(failed_record(spec, "error", f"lost: {type(exc).__name__}: {exc}", machine_id()))


def cluster_sweep(
    specs: list[RunSpec],
    results: Path,
    run_budget: float,
    address: str,
    stream=sys.stderr,
    retry_failed: bool = False,
    sweep_budget: float = math.inf,
) -> list[dict]:
    """Run ``specs`` as Dask tasks on the cluster at ``address``; each record stored as it arrives
    (:func:`pcabench.execute.sweep.run_specs`)."""
    results = Path(results)
    with store.SweepLock(results, whole_folder=True) as lock:  # before any work: every store it may write
        rows = store.read_rows(results)
        specs = [s.resolved() for s in specs]
        with ExitStack() as stack:
            client = connect(address, stack, stream)
            print(f"pcabench: Dask dashboard at {client.dashboard_link}", file=stream, flush=True)
            workers = worker_resources(client)
            for need in {tuple(sorted(task_resources(s))) for s in specs}:
                if not any(all(r.get(k, 0) >= 1 for k in need) for r in workers.values()):
                    raise OptionError(
                        f"--cluster {address}: no worker offers the resources {', '.join(need)}; "
                        f'start workers with --resources "{" ".join(f"{k}=1" for k in need)}"'
                    )
            return run_specs(
                specs,
                DaskExecutor(client, git_commit()),
                Stores(results, lock),
                rows,
                run_budget,
                sweep_budget,
                stream,
                retry_failed,
            )


def _unplaced(solver, threads, scene, preset, code, pair_loop) -> str:
    """:func:`pcabench.spec.identity` without the machine: a cluster places a run on any worker."""
    return identity(solver, int(threads or 1), scene, preset, "", code or "", "", pair_loop)


class Stores:
    """The client's stores under ``results``, one per machine, all under ``lock`` (the folder's, held by the
    cluster sweep); each store's reserve is kept from its first write."""

    def __init__(self, results: Path, lock: store.SweepLock):
        self.results, self.lock, self.paths = results, lock, set()

    def append(self, row: dict) -> dict:
        path = self.results / store.store_name(row["profile_id"], row.get("host") or host_id())
        if path not in self.paths:
            store.check_writable(path)
            self.lock.hold(path)
            self.paths.add(path)
        return self.lock.append(row, path)
