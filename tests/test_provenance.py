"""What made a result is what it says (issue 57): the code key (pcabench/store/provenance.py) is the content of
the code that makes a run, first-party and plug-ins alike; the store's resume key and every record carry it."""

from __future__ import annotations

import json
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


LONE = """
from solvers.kernels.wendland_c2 import WendlandC2

from lone_constants import SCALE


class Lone(WendlandC2):
    name = "lone-kernel"

    def value(self, r, h, dims=2):
        return SCALE * super().value(r, h, dims)
"""


@pytest.mark.parametrize("layout", ["lone module", "package"])
def test_the_code_key_holds_every_module_a_plugin_imports_of_its_own(tmp_path, layout):
    """A kernel plug-in that imports a constant from a module beside it (a lone module's sibling, or another
    module of its package): an edit there changes the code key (a study runs again), undoing it restores it."""
    from solvers.kernels.registry import ENTRY_POINT_GROUP as KERNELS

    site = tmp_path / "site"
    if layout == "lone module":
        install(site, "lone_kernel", LONE, {})
        constants = site / "lone_constants.py"
        target = "lone_kernel:Lone"
    else:
        install(site, "lone_kernel", "", {})
        (site / "lone_kernel.py").unlink()
        (site / "lone_pkg").mkdir()
        (site / "lone_pkg" / "__init__.py").write_text(LONE.replace("from lone_constants", "from lone_pkg.constants"))
        constants = site / "lone_pkg" / "constants.py"
        target = "lone_pkg:Lone"
    (site / "lone_kernel-0.1.dist-info" / "entry_points.txt").write_text(f"[{KERNELS}]\nlone-kernel = {target}\n")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(site), str(ROOT)])}

    def key() -> str:
        out = subprocess.run(
            [sys.executable, "-c", "from pcabench.store.provenance import code_key; print(code_key())"],
            capture_output=True,
            text=True,
            env=env,
            cwd=ROOT,
            timeout=120,
        )
        assert out.returncode == 0, out.stderr[-2000:]
        return out.stdout.split()[-1]

    constants.write_text("SCALE = 1.0\n")
    before = key()
    constants.write_text("SCALE = 1.5\n")
    assert key() != before, "an edit of a module the plug-in imports left the code key as it was"
    constants.write_text("SCALE = 1.0\n")
    assert key() == before


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
@pytest.mark.parametrize("command", ["run", "plain run", "study"])
def test_a_process_that_leaves_the_runs_group_ends_with_the_run(tmp_path, command):
    """`run` (with a budget: in a child; plain: in-process) returns and `study` stores its run in seconds, not
    when the escaped processes end (600 s), though they hold its stdout and stderr pipes, and neither escaped
    process outlives the run."""
    site, pids = tmp_path / "site", tmp_path / "pids"
    pids.mkdir()
    install(site, "escaper_solver", ESCAPER, {"escaper": "escaper_solver:Escaper"})
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(site), str(ROOT)]), "ESCAPE_PIDS": str(pids)}
    words = ["--solver", "escaper", "--dx", "1", "--steps", "3"] + (
        [] if command == "plain run" else ["--run-budget", "60"]
    )
    extra = ["--no-report", "--results", str(tmp_path)] if command == "study" else []
    started = time.monotonic()
    out = subprocess.run(  # capture_output: pipes, which the escaped processes inherit and hold
        [sys.executable, "-m", "pcabench.cli", command.split()[-1], *words, *extra],
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


FORGER = """
import glob
import json
import os

from solvers.linkedlist_cpu import LinkedListCPU


class Forger(LinkedListCPU):
    \"\"\"Appends to the store, behind the sweep's back, a copy of the row stored first with its stage times cut
    a hundredfold and its error 1e-9: the same run_id, so the later copy would win.\"\"\"

    name = "forger"

    def init(self):
        super().init()
        folder = os.environ.get("FORGE_DIR")
        if folder:
            for path in glob.glob(os.path.join(folder, "*.jsonl")):
                with open(path) as f:
                    row = json.loads(f.readline())
                row["stages"] = {k: v / 100 for k, v in row["stages"].items()}
                row["mse"] = 1e-9
                with open(path, "a") as f:
                    f.write(json.dumps(row) + "\\n")
"""


def test_a_row_a_runs_process_writes_into_the_store_is_found_and_never_read(tmp_path):
    """A run's process appends a forged copy of a stored row while the sweep holds the store: the sweep moves it
    to ``<store>.foreign`` with one warning, and the stored row keeps its own times and error."""
    site, results = tmp_path / "site", tmp_path / "results"
    install(site, "forger_solver", FORGER, {"forger": "forger_solver:Forger"})
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(site), str(ROOT)])}

    def study(steps: int, forge: bool) -> subprocess.CompletedProcess:
        return subprocess.run(
            [sys.executable, "-m", "pcabench.cli", "study", "--solver", "forger", "--dx", "1", "--steps", str(steps)]
            + ["--no-report", "--results", str(results)],
            capture_output=True,
            text=True,
            env={**env, **({"FORGE_DIR": str(results)} if forge else {})},
            cwd=ROOT,
            timeout=300,
        )

    first = study(2, forge=False)
    assert first.returncode == 0, first.stderr[-2000:]
    (original,) = store.read_rows(results)
    second = study(3, forge=True)
    assert second.returncode == 0, second.stderr[-2000:]
    assert "behind the sweep's back" in second.stderr, second.stderr[-2000:]
    rows = {r["run_id"]: r for r in store.read_rows(results)}
    assert len(rows) == 2
    kept = rows[original["run_id"]]
    assert kept["stages"] == original["stages"] and kept["mse"] == original["mse"]
    (foreign,) = results.glob("*.foreign")
    assert json.loads(foreign.read_text().splitlines()[0])["mse"] == 1e-9


LOUD = """
import atexit
import os

from solvers.linkedlist_cpu import LinkedListCPU

print("loud plug-in: imported")  # at import, before any command runs
atexit.register(lambda: os.write(1, b"loud plug-in: bye\\\\n"))  # at exit, after the command's output


class Loud(LinkedListCPU):
    name = "loud-cpu"
"""


LOUD_KERNEL = """
import atexit
import os

from solvers.kernels.wendland_c2 import WendlandC2

print("loud plug-in: imported")  # at import: a kernel's registry loads as the command line is built
atexit.register(lambda: os.write(1, b"loud plug-in: bye\\n"))


class LoudKernel(WendlandC2):
    name = "loud-kernel"
"""


@pytest.mark.parametrize("registry", ["solver", "kernel"])
def test_run_json_is_one_object_on_stdout_whatever_a_plugin_prints_at_import_or_exit(tmp_path, registry):
    """A solver plug-in that runs, or a kernel plug-in that is only installed (another kernel runs)."""
    import json

    from solvers.kernels.registry import ENTRY_POINT_GROUP as KERNELS

    site = tmp_path / "site"
    if registry == "solver":
        install(site, "loud_solver", LOUD, {"loud-cpu": "loud_solver:Loud"})
    else:
        install(site, "loud_kernel", LOUD_KERNEL, {})
        (site / "loud_kernel-0.1.dist-info" / "entry_points.txt").write_text(
            f"[{KERNELS}]\nloud-kernel = loud_kernel:LoudKernel\n"
        )
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(site), str(ROOT)])}
    solver = "loud-cpu" if registry == "solver" else "linkedlist-cpu"
    out = subprocess.run(
        [sys.executable, "-m", "pcabench.cli", "run", "--solver", solver, "--dx", "1", "--steps", "2", "--json"],
        capture_output=True,
        text=True,
        env=env,
        cwd=ROOT,
        timeout=300,
    )
    assert out.returncode == 0, out.stderr[-2000:]
    assert json.loads(out.stdout)["status"] == "ok", out.stdout  # the whole of stdout is one object
    assert "loud plug-in: imported" in out.stderr and "loud plug-in: bye" in out.stderr


def test_a_class_made_at_run_time_has_no_source_and_says_so():
    """A class exec'd in a namespace that is no module (a notebook's cell, CONTRIBUTING's recipes as the tests
    run them) has no source file: ValueError, which run_sources turns into an unknown code, never a TypeError out
    of the first run's provenance."""
    import pytest

    from solvers.interface import Solver
    from solvers.sources import code_sources

    namespace = {"__name__": "__made_at_run_time__", "Solver": Solver}
    exec("class Made(Solver):\n    name = 'made'\n", namespace)  # noqa: S102
    with pytest.raises(ValueError, match="no source file for class Made"):
        code_sources(namespace["Made"])
