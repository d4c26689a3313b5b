"""Sweeps on a Dask cluster: the same runs as a serial sweep, resume, worker loss, and the optional extra."""

from __future__ import annotations

import os
import subprocess
import sys
import time

import pytest

from pcabench import cli, store
from tests.conftest import run_children

pytest.importorskip("dask.distributed")

SWEEP = ["--dx", "1", "0.5", "--solver", "linkedlist-cpu", "allpair-cpu", "--steps", "3", "--no-report"]


def study(results, *args, **kw):
    return subprocess.run(
        [sys.executable, "-m", "pcabench.cli", "study", *args, "--results", str(results)],
        capture_output=True,
        text=True,
        timeout=600,
        **kw,
    )


def outcome(results):
    """What a sweep found, without timings or where it ran: one entry per run."""
    return sorted(
        (r["solver"], r["dx"], r["status"], r["steps"], round(r["mse"], 12), r["pair_loop"])
        for r in store.read_rows(results)
    )


@pytest.mark.tier2  # a local Dask cluster's sweep: 13-21 s (the second tier)
def test_a_cluster_sweep_makes_the_same_runs_as_a_serial_one_and_resumes(tmp_path):
    serial, dask = tmp_path / "serial", tmp_path / "dask"
    assert study(serial, *SWEEP).returncode == 0
    proc = study(dask, *SWEEP, "--cluster", "local:2")
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert "dashboard at http" in proc.stderr and "4/4 done" in proc.stderr
    assert outcome(dask) == outcome(serial) and len(outcome(dask)) == 4
    rows = store.read_rows(dask)
    assert all(r["profile_id"] and r["host"] for r in rows)  # captured on the worker
    again = study(dask, *SWEEP, "--cluster", "local:2")
    assert again.returncode == 0 and again.stderr.count("already stored") == 4
    assert len(store.read_rows(dask)) == 4


def children(pid: int) -> list[int]:
    """The processes whose parent is ``pid``."""
    out = subprocess.run(["pgrep", "-P", str(pid)], capture_output=True, text=True).stdout.split()
    return [int(p) for p in out]


def run_child_under_a_worker(root: int) -> tuple[int, int] | None:
    """(worker, run child) among the descendants of ``root`` only: a test signals only what it started."""
    for worker in children(root):
        for child in run_children(worker):
            return worker, child
    return None


@pytest.mark.tier2  # a local Dask cluster's sweep: 13-21 s (the second tier)
def test_a_killed_worker_loses_and_duplicates_nothing(tmp_path):
    args = ["--dx", "0.25", "0.2", "--steps", "150", "--no-report", "--cluster", "local:2"]
    proc = subprocess.Popen(
        [sys.executable, "-m", "pcabench.cli", "study", *args, "--results", str(tmp_path)],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    found = None
    deadline = time.time() + 180
    while time.time() < deadline and found is None and proc.poll() is None:
        found = run_child_under_a_worker(proc.pid)
        time.sleep(0.1)
    assert found is not None, "no run started on a worker of this test's cluster"
    os.kill(found[0], 9)  # the worker dies mid-run; its run's child dies with it
    _, err = proc.communicate(timeout=600)
    assert proc.returncode == 0, err[-2000:]
    rows = store.read_rows(tmp_path)
    assert sorted(r["dx"] for r in rows) == [0.2, 0.25]  # each run once: retried elsewhere, or recorded as lost
    assert all(r["status"] == "ok" or "lost" in r["message"] for r in rows)


def test_without_dask_the_option_names_the_extra(monkeypatch, capsys, tmp_path):
    monkeypatch.setitem(sys.modules, "dask.distributed", None)  # import fails as if dask were not installed
    with pytest.raises(SystemExit) as exc:
        cli.main(["study", *SWEEP, "--cluster", "local:2", "--results", str(tmp_path)])
    err = capsys.readouterr().err
    assert exc.value.code == 2 and "[cluster]" in err and len(err.strip().splitlines()) == 1


@pytest.mark.parametrize("address", ["local:0", "local:x", "host:8786"])
def test_bad_cluster_addresses_are_one_line(address, capsys, tmp_path):
    with pytest.raises(SystemExit) as exc:
        cli.main(["study", *SWEEP, "--cluster", address, "--results", str(tmp_path)])
    err = capsys.readouterr().err
    assert exc.value.code == 2 and "--cluster" in err and "Traceback" not in err


def test_a_local_cluster_listens_on_loopback_only():
    from contextlib import ExitStack

    import psutil

    from pcabench.execute.cluster import connect

    with ExitStack() as stack:
        client = connect("local:1", stack)
        here = psutil.Process()
        listening = [
            c.laddr
            for p in (here, *here.children(recursive=True))
            for c in p.net_connections("inet")
            if c.status == psutil.CONN_LISTEN
        ]
        assert listening and all(addr.ip == "127.0.0.1" for addr in listening), listening
        assert "127.0.0.1" in client.dashboard_link


def test_a_local_cluster_takes_no_client_but_its_own():
    """Another process on the machine (any user) that reaches the local scheduler cannot be its client, so
    cannot run code on the workers: the cluster speaks TLS with credentials made for this sweep only."""
    from contextlib import ExitStack

    import dask.distributed as dd

    from pcabench.execute.cluster import connect

    with ExitStack() as stack:
        client = connect("local:1", stack)
        address = client.scheduler.address
        assert address.startswith("tls://127.0.0.1:"), address
        assert client.submit(lambda: 6 * 7).result(timeout=60) == 42  # its own client works
        # a stranger with TLS credentials of its own (not signed by this cluster's authority); one in plain TCP
        for stranger, security in ((address, dd.Security.temporary()), (address.replace("tls://", "tcp://"), None)):
            with pytest.raises((OSError, TimeoutError)):
                dd.Client(stranger, security=security, timeout="3s")
