"""A sweep's runs forked from the warm server (pcabench/execute/forkserver.py): the same record as a fresh
interpreter's, the same budget, and a fresh interpreter wherever the environment differs."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from pcabench.execute.sweep import run_child
from pcabench.spec import RunSpec
from solvers import Scene
from tests.conftest import run_children, study_process

ROOT = Path(__file__).resolve().parents[1]


def in_a_process_of_its_own(body: str) -> None:
    """``body`` (asserts) in a fresh interpreter: the forkserver is one per process, and an earlier test in this
    worker may have started it in an environment of its own (a variable it set), which a run in today's
    environment rightly does not share (it starts a fresh interpreter instead)."""
    prelude = (
        "import os\n"
        "from pcabench.execute import forkserver\n"
        "from pcabench.execute.sweep import run_child\n"
        "from pcabench.spec import RunSpec\n"
        "from solvers import Scene\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", prelude + textwrap.dedent(body)], capture_output=True, text=True, cwd=ROOT, timeout=600
    )
    assert out.returncode == 0, out.stderr[-3000:]


def test_a_forked_run_makes_the_record_a_fresh_interpreter_makes():
    in_a_process_of_its_own(
        """
        spec = RunSpec("linkedlist-cpu", Scene(dx=1.0, steps=6)).resolved()
        assert forkserver.usable(dict(os.environ))
        forked = run_child(spec, 300, "abc", "m", stream=None)
        os.environ[forkserver.ENV] = "0"
        fresh = run_child(spec, 300, "abc", "m", stream=None)
        assert forked["status"] == fresh["status"] == "ok", (forked["message"], fresh["message"])
        for key in ("mse", "me", "mean_neighbours", "n_particles", "steps", "profile_id", "commit", "errors"):
            assert forked[key] == fresh[key], key  # bit for bit, and the sweep's machine and commit
        assert forked["jit_cached"] is True  # the fresh one filled the cache or found it filled
        """
    )


def test_a_forked_run_past_its_budget_is_killed():
    spec = RunSpec("allpair-cpu", Scene(dx=0.25, steps=100000, model="linear")).resolved()
    t0 = time.perf_counter()
    with pytest.raises(subprocess.TimeoutExpired):
        run_child(spec, 3, "abc", "m", stream=None)
    assert time.perf_counter() - t0 < 60
    deadline = time.time() + 10
    while run_children(os.getpid()) and time.time() < deadline:
        time.sleep(0.05)
    assert not run_children(os.getpid()), "the timed-out run outlived its budget"


def test_only_the_run_time_variables_may_differ_from_the_servers():
    in_a_process_of_its_own(
        """
        env = dict(os.environ)
        assert forkserver.usable(env)
        assert forkserver.usable({**env, "PCABENCH_HOME": "/elsewhere", "PCABENCH_CACHE": "/other"})
        assert not forkserver.usable({**env, "NUMBA_OPT": "0"})  # read by numba at import: a fresh interpreter
        assert not forkserver.usable({**env, "PYTHONPATH": "/a/plugin"})
        assert not forkserver.usable({**env, forkserver.ENV: "0"})
        """
    )


def test_a_run_killed_with_its_forkserver_is_run_again_in_a_fresh_interpreter(tmp_path):
    """The server killed while it holds a run (its child dies with it): the run is made again in a fresh
    interpreter, not stored as an `error` (exit 255), and the sweep's next runs start a new server."""
    import signal

    from pcabench import store
    from pcabench.execute import containment

    proc = study_process(
        tmp_path, "--dx", "0.5", "0.25", "--steps", "400", "--model", "linear", "--solver", "linkedlist-cpu"
    )
    try:
        killed, deadline = False, time.time() + 180
        while not killed and time.time() < deadline and proc.poll() is None:
            for server in containment.children(proc.pid):  # the sweep's children: the forkserver among them
                if run_children(server):  # the one holding a forked run
                    os.kill(server, signal.SIGKILL)
                    killed = True
                    break
            time.sleep(0.01)
        assert killed, "no forked run seen"
        _, err = proc.communicate(timeout=300)
        rows = store.read_rows(tmp_path)
        assert proc.returncode == 0 and sorted(r["status"] for r in rows) == ["ok", "ok"], err[-2000:]
        assert "its forkserver ended under it; run again in a fresh interpreter" in err
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)


def test_a_ctrl_c_while_the_server_is_spawned_is_held_back_not_lost():
    """The sweep ignores SIGINT for the milliseconds its server is spawned (so the server inherits the ignore): a
    Ctrl-C then reaches the sweep's handler afterwards instead of being dropped (the resource tracker's own start,
    which unblocks SIGINT, comes first). In a process of its own: one server per process."""
    code = """
import os, signal
from unittest import mock
from multiprocessing import forkserver
from pcabench.execute import forkserver as F
got = []
signal.signal(signal.SIGINT, lambda *a: got.append(1))
real = forkserver.ensure_running
def spawn():
    os.kill(os.getpid(), signal.SIGINT)  # the terminal's Ctrl-C, in the window
    real()
with mock.patch.object(forkserver, "ensure_running", spawn):
    F.start_server()
print(len(got))
"""
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0 and proc.stdout.strip() == "1", proc.stderr[-2000:]


@pytest.mark.tier2  # two sets of loops compiled from an empty cache: about 15 s
def test_a_sweeps_uncached_loops_are_compiled_ahead_side_by_side_and_its_runs_compile_none(tmp_path):
    """pcabench/execute/ahead.py: a sweep of two configurations (float64 and float32) whose loops the cache lacks
    compiles them before its first run, one process each, says so once, and its runs load them (each record
    ``jit_cached``, a fraction of a second of JIT); a sweep of one configuration starts no such process."""
    in_a_process_of_its_own(
        f"""
        import io, json
        from pcabench.execute import ahead
        from pcabench.execute.sweep import sweep
        os.environ["PCABENCH_CACHE"] = {str(tmp_path / "cache")!r}
        ahead.cores = lambda: 2  # the grouping on two cores, whatever this machine has
        specs = [RunSpec("allpair-cpu", Scene(dx=1.0, steps=3, precision=p)) for p in ("float64", "float32")]
        said = io.StringIO()
        rows = sweep(specs, {str(tmp_path / "store.jsonl")!r}, 300, 600, stream=said)
        assert "compiled ahead: 2 sets of loops" in said.getvalue(), said.getvalue()
        assert [r["status"] for r in rows] == ["ok", "ok"] and all(r["jit_cached"] for r in rows), rows
        assert max(r["jit_seconds"] for r in rows) < 1.0, [r["jit_seconds"] for r in rows]
        assert ahead.compile_ahead(specs[:1], stream=said) == (0, 0.0)  # one set: nothing ahead
        """
    )
