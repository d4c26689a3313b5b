"""The solver registry: built-in solvers found in solvers/, plug-ins through the ``pcabench.solvers`` entry points.

The plug-in is the README's example ("Add your own solver"), installed into a
temporary site folder with its dist-info, exactly as pip leaves an installed
package: importlib.metadata finds it on ``sys.path`` (``PYTHONPATH`` for the
command line's processes).
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import solvers
from pcabench.execute.run import run
from pcabench.spec import RunSpec
from solvers import ENTRY_POINT_GROUP, Scene, registry
from solvers.interface import Solver
from solvers.registry import SOLVERS

ROOT = Path(__file__).resolve().parents[1]


NAME = "readme-argsort"  # the README's solver under a name no user's installed copy of it can hold


def readme_example() -> str:
    """The plug-in module of the README's section "Add your own solver" (named :data:`NAME`)."""
    text = (ROOT / "README.md").read_text()
    section = text[text.index("### Add your own solver") :]
    code = re.search(r"```python\n# argsort_solver.py\n(.*?)```", section, re.S).group(1)
    assert 'name = "argsort-cpu"' in code
    return code.replace('name = "argsort-cpu"', f'name = "{NAME}"')


def install(site: Path, module: str, source: str, entries: dict) -> Path:
    """``module`` with ``source`` and a dist-info declaring ``entries`` ({name: object}) in ``site``."""
    site.mkdir(parents=True, exist_ok=True)
    (site / f"{module}.py").write_text(source)
    info = site / f"{module}-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {module}\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text(
        f"[{ENTRY_POINT_GROUP}]\n" + "".join(f"{k} = {v}\n" for k, v in entries.items())
    )
    return site


@pytest.fixture
def site(tmp_path, monkeypatch):
    """A site folder on sys.path; the registry is rebuilt with it and again after the test."""
    path = tmp_path / "site"
    path.mkdir()
    monkeypatch.syspath_prepend(str(path))
    SOLVERS.cache_clear()
    yield path
    SOLVERS.cache_clear()
    for name in [m for m in sys.modules if m in ("argsort_solver", "broken_solver")]:
        del sys.modules[name]


def test_the_builtin_solvers_are_found_and_state_what_they_can_do():
    found = registry()
    assert {"allpair-cpu", "linkedlist-cpu", "linkedlist-gpu"} <= set(found)
    for name, cls in found.items():
        assert issubclass(cls, Solver) and cls.name == name and cls.summary and cls.device in ("cpu", "gpu")
        assert cls.pair_loops and cls.order >= 1 and "timing" in cls.resources
    assert found["linkedlist-gpu"].resources.get("GPU") == 1 and found["linkedlist-gpu"].device == "gpu"
    assert found["linkedlist-cpu"].threaded and not found["allpair-cpu"].threaded


def test_finding_the_solvers_touches_no_gpu_library():
    code = (
        "import sys, solvers; solvers.registry(); print(any(m.startswith(('cupy', 'numba.cuda')) for m in sys.modules))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, check=True)
    assert out.stdout.strip() == "False"


def test_the_readme_plugin_is_found_and_matches_the_paper_cell_list_bit_for_bit(site, tmp_path):
    install(site, "argsort_solver", readme_example(), {NAME: "argsort_solver:ArgsortCellList"})
    assert NAME in solvers.solver_names()
    fields = {}
    for name in (NAME, "linkedlist-cpu"):
        path = tmp_path / f"{name}.npz"
        spec = RunSpec(name, Scene(dx=0.5, steps=20, model="lagrangian"), pair_loop="gather")
        record = run(spec, fields_path=path)
        assert record.status == "ok" and record.solver == name and record.pair_loop == "gather"
        fields[name] = np.load(path)
    for key in ("x", "y", "u", "v", "drho"):  # the same stable order by cell: the same sums
        np.testing.assert_array_equal(fields[NAME][key], fields["linkedlist-cpu"][key])


BROKEN = (
    "import numpy\nfrom solvers.linkedlist_cpu import LinkedListCPU\nNOT_A_SOLVER = 1\n\n\n"
    "class NoName(LinkedListCPU):\n    pass\n\n\nclass Renamed(LinkedListCPU):\n    name = 'renamed-cpu'\n"
)
BROKEN_ENTRIES = {
    "nothing": "broken_solver:NOT_A_SOLVER",
    "missing": "broken_solver:Absent",
    "linkedlist-cpu": "solvers.allpair_cpu:AllPairCPU",
    "noname": "broken_solver:NoName",
    "other-key": "broken_solver:Renamed",
}


def test_a_broken_or_clashing_plugin_is_left_out_with_one_warning(site):
    install(site, "broken_solver", BROKEN, BROKEN_ENTRIES)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        found = registry()
    mine = [str(w.message) for w in caught if "broken_solver" in str(w.message) or "allpair_cpu" in str(w.message)]
    assert not {"nothing", "missing", "noname", "other-key"} & set(found) and "renamed-cpu" in found
    assert found["linkedlist-cpu"].__name__ == "LinkedListCPU"  # a plug-in never replaces a built-in
    assert len(mine) == 5, mine
    for words in (
        "does not load",
        "not a concrete Solver subclass",
        "is taken",
        "no name of its own (it would inherit 'linkedlist-cpu')",
        "registered as 'renamed-cpu'",
    ):
        assert sum(words in m for m in mine) == 1, (words, mine)


@pytest.mark.tier2  # a plug-in through run, study, report and the benchmarks: 15 s (the second tier)
def test_a_plugin_runs_through_run_a_study_a_report_and_the_benchmarks(tmp_path):
    site = install(tmp_path / "site", "argsort_solver", readme_example(), {NAME: "argsort_solver:ArgsortCellList"})
    install(site, "broken_solver", BROKEN, {"missing": "broken_solver:Absent"})  # one broken plug-in beside it
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(site), str(ROOT)]), "PCABENCH_HOME": str(tmp_path / "home")}

    def cli(*args):
        return subprocess.run(
            [sys.executable, "-m", "pcabench.cli", *args],
            capture_output=True,
            text=True,
            env=env,
            cwd=tmp_path,
            timeout=600,
        )

    helped = cli("run", "--help")
    assert NAME in helped.stdout  # in --solver's choices and the solvers' help
    assert helped.stderr.splitlines() == [  # the broken one: one line, no source line
        f"pcabench: warning: entry point 'missing' of group {ENTRY_POINT_GROUP} (broken_solver:Absent) left out: "
        "it does not load (AttributeError: module 'broken_solver' has no attribute 'Absent')"
    ]
    out = cli("run", "--solver", NAME, "--dx", "1", "--steps", "5", "--json")
    assert out.returncode == 0, out.stderr
    assert json.loads(out.stdout)["solver"] == NAME
    for option, words in ((("--threads", "2"), f"{NAME} is serial"), (("--pair-loop", "list"), "--pair-loop: ")):
        refused = cli("run", "--solver", NAME, "--dx", "1", *option)
        assert refused.returncode == 2 and words in refused.stderr.splitlines()[-1], refused.stderr
    results, reports = tmp_path / "results", tmp_path / "reports"
    # the matrix: the plug-in takes the loop and thread count it has; each run once
    out = cli(
        "study",
        "--solver",
        NAME,
        "linkedlist-cpu",
        "--pair-loop",
        "list",
        "gather",
        "--threads",
        "1",
        "2",
        "--dx",
        "1",
        "--steps",
        "5",
        "--results",
        str(results),
        "--reports",
        str(reports),
    )
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stderr.count("left out") == 1, out.stderr  # said once, by the sweep, not again by each run's process
    rows = [json.loads(line) for f in results.glob("*.jsonl") for line in f.read_text().splitlines()]
    assert sorted((r["solver"], r["pair_loop"], r["threads"]) for r in rows) == sorted(
        [(NAME, "gather", 1)] + [("linkedlist-cpu", loop, n) for loop in ("list", "gather") for n in (1, 2)]
    )
    assert all(r["status"] == "ok" for r in rows) and "5 runs on" in out.stderr
    assert NAME in "".join(p.read_text() for p in reports.rglob("report.md"))
    code = "from benchmarks.common import solver_names; print(' '.join(solver_names('cpu')))"
    names = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, cwd=ROOT)
    assert NAME in names.stdout.split(), names.stderr
