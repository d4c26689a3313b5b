"""What made a result is what it says (issue 57): the code key (pcabench/store/provenance.py) is the content of
the code that makes a run, first-party and plug-ins alike; the store's resume key and every record carry it."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from pcabench import store
from pcabench.store import provenance

from .test_registry import NAME, install, readme_example

ROOT = Path(__file__).resolve().parents[1]


def test_the_code_key_is_every_source_a_run_is_made_of_and_no_other():
    names = set(provenance.run_sources())
    assert {"solvers/physics/pairs.py", "solvers/kernels/gaussian.py", "pcabench/execute/sweep.py"} <= names
    assert not any(n.startswith("pcabench/reports/") for n in names)  # a report's edit reruns nothing
    assert len(provenance.code_key()) == 16


def study(results: Path, site: Path) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(site), str(ROOT)])}
    return subprocess.run(
        [sys.executable, "-m", "pcabench.cli", "study", "--solver", NAME, "--dx", "1", "--steps", "3"]
        + ["--no-report", "--results", str(results)],
        capture_output=True,
        text=True,
        env=env,
        cwd=ROOT,
        timeout=600,
    )


def test_a_study_reruns_what_a_plugins_edit_changed_and_resumes_what_it_did_not(tmp_path):
    """A plug-in's source is part of the resume key: after an edit the study runs again (the stored run was
    made by other code), after the edit is undone it finds its first run stored; each row names its code."""
    site, results = tmp_path / "site", tmp_path / "results"
    source = readme_example()
    install(site, "argsort_solver", source, {NAME: "argsort_solver:ArgsortCellList"})
    first = study(results, site)
    assert first.returncode == 0, first.stderr[-2000:]
    (site / "argsort_solver.py").write_text(source + "\n# an edit: other code, whatever it computes\n")
    edited = study(results, site)
    assert edited.returncode == 0 and "already stored" not in edited.stderr, edited.stderr[-2000:]
    (site / "argsort_solver.py").write_text(source)
    undone = study(results, site)
    assert undone.returncode == 0 and "already stored" in undone.stderr, undone.stderr[-2000:]
    rows = store.read_rows(results)
    assert len(rows) == 2 and len({r["code"] for r in rows}) == 2  # one commit, two codes: told apart
    assert len({r["commit"] for r in rows}) == 1


# ---------------------------------------------------------------- the parent checks what it scores
LIARS = """
import dataclasses

from solvers.linkedlist_cpu import LinkedListCPU


class Early(LinkedListCPU):
    name = "liar-early"  # its fields at a time of its own choosing, near 0: an error near 0

    def output(self):
        return dataclasses.replace(super().output(), t=1e-9)


class Zero(LinkedListCPU):
    name = "liar-zero"  # t = 0: the exact solution's scale is 0

    def output(self):
        return dataclasses.replace(super().output(), t=0.0)


class Huge(LinkedListCPU):
    name = "liar-huge"  # finite fields whose error overflows

    def output(self):
        f = super().output()
        return dataclasses.replace(f, u=f.u * 1e300, v=f.v * 1e300, drho=f.drho * 1e300)


class Late(LinkedListCPU):
    name = "liar-late"

    def output(self):
        return dataclasses.replace(super().output(), t=1e9)
"""


def test_a_childs_claimed_time_or_unscorable_fields_are_an_error_and_the_sweep_goes_on(tmp_path):
    """Fields at another time than steps x dt (1e-9 s, 0, 1e9 s), or past the blow-up bound (x 1e300), are
    each the run's `error` with one line saying why, never `ok`; the sweep stores every run and ends normally,
    and the honest solver's run beside them is `ok`."""
    site, results = tmp_path / "site", tmp_path / "results"
    names = ["liar-early", "liar-zero", "liar-huge", "liar-late"]
    install(site, "liars", LIARS, {n: f"liars:{c}" for n, c in zip(names, ("Early", "Zero", "Huge", "Late"))})
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(site), str(ROOT)])}
    out = subprocess.run(
        [sys.executable, "-m", "pcabench.cli", "study", "--solver", *names, "linkedlist-cpu", "--dx", "1"]
        + ["--steps", "3", "--no-report", "--results", str(results)],
        capture_output=True,
        text=True,
        env=env,
        cwd=ROOT,
        timeout=600,
    )
    assert "Traceback" not in out.stderr, out.stderr[-3000:]
    rows = {r["solver"]: r for r in store.read_rows(results)}
    assert set(rows) == {*names, "linkedlist-cpu"}
    assert rows["linkedlist-cpu"]["status"] == "ok"
    for name in ("liar-early", "liar-zero", "liar-late"):
        assert rows[name]["status"] == "error" and "steps reach" in rows[name]["message"], rows[name]
    assert rows["liar-huge"]["status"] == "error" and "past the bound the run checks" in rows["liar-huge"]["message"]


def test_an_exception_while_scoring_is_the_runs_error_in_one_line(monkeypatch):
    from pcabench.execute.run import score
    from pcabench.spec import RunSpec
    from pcabench.store.record import RunRecord
    from solvers import Scene, make_solver

    scene = Scene(dx=1.0, steps=2)
    solver = make_solver("linkedlist-cpu")
    solver.input(scene)
    solver.init()
    fields = solver.output()
    record = RunRecord.from_spec(RunSpec("linkedlist-cpu", scene))
    record.steps = 0  # the fields at t = 0: the time its steps reach

    def broken(*_):
        raise ZeroDivisionError("float division by zero")

    monkeypatch.setattr(type(scene.kind), "errors", broken)
    score(record, scene, fields)
    assert record.status == "error" and "raised ZeroDivisionError: float division by zero" in record.message
    assert "\n" not in record.message


# ---------------------------------------------------------------- every descendant ends with its run
ESCAPER = '''
import os
import subprocess

from solvers.linkedlist_cpu import LinkedListCPU


class Escaper(LinkedListCPU):
    """Starts two processes that leave the run's process group, holding its stdout and stderr: a setsid child
    and a daemon's double fork (its parent exits at once, so it is an orphan in a session of its own)."""

    name = "escaper"

    def init(self):
        super().init()
        folder = os.environ["ESCAPE_PIDS"]
        child = subprocess.Popen(["sleep", "600"], start_new_session=True)
        with open(os.path.join(folder, "setsid.pid"), "w") as f:
            f.write(str(child.pid))
        subprocess.run(["sh", "-c", f"setsid sleep 601 & echo $! > {folder}/daemon.pid"], check=True)
'''


def alive(pid: int) -> bool:
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().split(")")[-1].split()[0] != "Z"
    except OSError:
        return False


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the subreaper is Linux's")
@pytest.mark.parametrize("command", ["run", "study"])
def test_a_process_that_leaves_the_runs_group_ends_with_the_run(tmp_path, command):
    """`run` returns and `study` stores its run in seconds, not when the escaped processes end (600 s), and
    neither escaped process outlives the run."""
    site, pids = tmp_path / "site", tmp_path / "pids"
    pids.mkdir()
    install(site, "escaper_solver", ESCAPER, {"escaper": "escaper_solver:Escaper"})
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(site), str(ROOT)]), "ESCAPE_PIDS": str(pids)}
    words = ["--solver", "escaper", "--dx", "1", "--steps", "3", "--run-budget", "60"]
    extra = [] if command == "run" else ["--no-report", "--results", str(tmp_path)]
    started = time.monotonic()
    out = subprocess.run(
        [sys.executable, "-m", "pcabench.cli", command, *words, *extra],
        capture_output=True,
        text=True,
        env=env,
        cwd=ROOT,
        timeout=120,
    )
    took = time.monotonic() - started
    escaped = [int((pids / f).read_text()) for f in ("setsid.pid", "daemon.pid")]
    try:
        assert out.returncode == 0 and took < 60, (took, out.stderr[-2000:])
        assert not [pid for pid in escaped if alive(pid)], "a process of the run outlived it"
    finally:
        for pid in escaped:
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass


LOUD = """
import atexit
import os

from solvers.linkedlist_cpu import LinkedListCPU

print("loud plug-in: imported")  # at import, before any command runs
atexit.register(lambda: os.write(1, b"loud plug-in: bye\\\\n"))  # at exit, after the command's output


class Loud(LinkedListCPU):
    name = "loud-cpu"
"""


def test_run_json_is_one_object_on_stdout_whatever_a_plugin_prints_at_import_or_exit(tmp_path):
    import json

    site = tmp_path / "site"
    install(site, "loud_solver", LOUD, {"loud-cpu": "loud_solver:Loud"})
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(site), str(ROOT)])}
    out = subprocess.run(
        [sys.executable, "-m", "pcabench.cli", "run", "--solver", "loud-cpu", "--dx", "1", "--steps", "2", "--json"],
        capture_output=True,
        text=True,
        env=env,
        cwd=ROOT,
        timeout=300,
    )
    assert out.returncode == 0, out.stderr[-2000:]
    assert json.loads(out.stdout)["status"] == "ok", out.stdout  # the whole of stdout is one object
    assert "loud plug-in: imported" in out.stderr and "loud plug-in: bye" in out.stderr
