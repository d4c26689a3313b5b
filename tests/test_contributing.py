"""CONTRIBUTING.md's recipes run as they stand, and each does what it says.

Each recipe is the one ```python block under its heading ("## Add a solver", ...). It runs here, in this
process, with a temporary ``PCABENCH_HOME`` and temporary folder, on a tiny scene; then its claim is
checked from outside: the solver it registers is in the solver registry and agrees with allpair-cpu, the
scene is in the scene registry with finite initial fields, the section is in the report it writes, the
preset expands to runs that a sweep stores. Every recipe unregisters what it registered: the registries
are checked to be as they were.
"""

from __future__ import annotations

import re
import tempfile
from pathlib import Path

import numpy as np
import pytest

from pcabench import store, studies
from pcabench.conformance import registered
from pcabench.execute.run import run
from pcabench.reports.section import SECTIONS, in_order
from pcabench.spec import RunSpec
from solvers import Scene, registry, solver_names
from solvers.scenes import SCENES, scene_names

ROOT = Path(__file__).resolve().parents[1]
RECIPES = (
    "Add a solver",
    "Add a kernel",
    "Add a scene",
    "Add a study",
    "Add an absorber",
    "Add a boundary method",
)


def recipe(title: str) -> str:
    """The one Python block under CONTRIBUTING.md's heading ``## {title}``."""
    text = (ROOT / "CONTRIBUTING.md").read_text()
    part = re.search(rf"^## {re.escape(title)}\n(.*?)(?=^## |\Z)", text, re.S | re.M)
    assert part, f"CONTRIBUTING.md has no section '## {title}'"
    blocks = re.findall(r"^```python\n(.*?)^```", part.group(1), re.S | re.M)
    assert len(blocks) == 1, f"'## {title}' holds {len(blocks)} python blocks, not one"
    return blocks[0]


@pytest.fixture
def run_recipe(tmp_path, monkeypatch):
    """``run_recipe(title)``: the recipe executed in a namespace of its own (returned), in a scratch home."""
    monkeypatch.setenv("PCABENCH_HOME", str(tmp_path / "home"))
    monkeypatch.setattr(tempfile, "tempdir", str(tmp_path))  # the recipe's mkdtemp() lands in the test's folder
    solvers_before, scenes_before = dict(registry()), scene_names()
    sections_before, presets_before = SECTIONS.all(), studies.PRESETS.all()

    def execute(title: str) -> dict:
        namespace = {"__name__": "__recipe__"}
        exec(compile(recipe(title), f"CONTRIBUTING.md: {title}", "exec"), namespace)  # noqa: S102 - our own docs
        return namespace

    yield execute
    # each recipe unregisters what it registered
    assert dict(registry()) == solvers_before and scene_names() == scenes_before
    assert SECTIONS.all() == sections_before
    assert studies.PRESETS.all() == presets_before


def test_every_recipe_has_one_block_and_the_workflow_is_named():
    for title in RECIPES:
        assert recipe(title).strip()
    text = (ROOT / "CONTRIBUTING.md").read_text()
    assert "\n## Dev workflow\n" in text
    for command in ("python -m pytest", "ruff check .", ".ci/run", "asv"):
        assert command in text, command


def test_the_solver_recipe_registers_a_solver_that_agrees_with_allpair(run_recipe, tmp_path):
    ns = run_recipe("Add a solver")
    cls = ns["TakeGather"]
    assert ns["ours"].solver == cls.name == "take-gather-cpu" and ns["ours"].status == "ok"
    assert cls.name not in solver_names()  # unregistered once its block ended
    scene = Scene(dx=1.0, steps=5)
    with registered(cls):
        assert solver_names()[-1] == cls.name
        ours = run(RunSpec(cls.name, scene), fields_path=tmp_path / "ours.npz")
    reference = run(RunSpec("allpair-cpu", scene), fields_path=tmp_path / "allpair.npz")
    assert ours.status == reference.status == "ok"
    a, b = np.load(tmp_path / "ours.npz"), np.load(tmp_path / "allpair.npz")
    for name in ("x", "y", "u", "v", "drho"):  # particle-id order: the same particles, the same fields
        assert np.allclose(a[name], b[name], rtol=0, atol=1e-12 * max(1.0, float(np.abs(b[name]).max()))), name
    assert np.max(np.abs(a["u"])) > 0.01  # the pulse is there: not two empty fields agreeing


def test_the_kernel_recipe_is_a_normalised_kernel_that_both_solvers_and_the_prediction_take(run_recipe):
    from scipy import integrate

    from solvers import kernel_names

    ns = run_recipe("Add a kernel")
    assert "cubic-spline" not in kernel_names()  # unregistered once its block ended
    ours, reference, prediction = ns["ours"], ns["reference"], ns["prediction"]
    assert ours.status == reference.status == "ok" and 0 < ours.mse < 1
    assert ours.mse == pytest.approx(reference.mse, rel=1e-10)  # the two searches agree to round-off
    assert np.isfinite(prediction.predicted_error) and 0 < prediction.stable_cfl < 10
    kernel, h = ns["CubicSpline"](), 0.7
    total, _ = integrate.quad(lambda r: 2 * np.pi * r * kernel.value(r, h), 0, 2 * h, points=[h])
    assert total == pytest.approx(1.0, rel=1e-10)  # W is normalised in 2D
    r = np.linspace(0.05, 1.95, 40) * h
    slope = (kernel.value(r + 1e-7, h) - kernel.value(r - 1e-7, h)) / 2e-7
    assert np.allclose(kernel.gradient(r, h), slope / r, rtol=1e-5, atol=1e-9)  # G = W'(r) / r


def test_the_scene_recipe_registers_a_scene_with_finite_initial_fields(run_recipe):
    ns = run_recipe("Add a scene")
    kind = ns["StandingWave"]()
    assert kind.name not in scene_names()  # unregistered once its block ended
    assert ns["record"].status == "ok" and 0 < ns["record"].mse < 0.05
    assert ns["record"].scene["name"] == kind.name
    with SCENES.registered(ns["StandingWave"]) as kind:
        assert kind.name in scene_names()
        scene = Scene(name=kind.name, dx=0.5, steps=2, model="linear")
        assert scene.periodic_x and scene.n_particles == 40 * 40
        x, y = np.meshgrid(
            scene.x_lo + (np.arange(scene.nx) + 0.5) * scene.dx, scene.y_lo + (np.arange(scene.ny) + 0.5) * scene.dx
        )
        u, v, drho = kind.initial_fields(scene, x, y, np)
    assert all(np.all(np.isfinite(f)) for f in (u, v, drho))
    assert np.isclose(np.abs(drho).max(), scene.rho0 * scene.mach, rtol=1e-2) and not u.any() and not v.any()
    assert kind.name not in scene_names()


def study_files(title: str = "Add a study") -> dict[str, str]:
    """The files a recipe writes: each ```python block titled with its path, {path: text}."""
    text = (ROOT / "CONTRIBUTING.md").read_text()
    part = re.search(rf"^## {re.escape(title)}\n(.*?)(?=^## |\Z)", text, re.S | re.M).group(1)
    return dict(re.findall(r'^```python title="([^"]+)"\n(.*?)^```', part, re.S | re.M))


@pytest.fixture
def study_folder(tmp_path):
    """The recipe's folder written as it says, on the studies' path (in the house: pcabench/studies/), the
    registries searching it; afterwards neither it nor its modules are left."""
    import sys

    import pcabench.studies

    files = study_files()
    assert files and all(path.startswith("pcabench/studies/tiny/") for path in files), list(files)
    root = tmp_path / "house"
    for path, text in files.items():
        (root / path).parent.mkdir(parents=True, exist_ok=True)
        (root / path).write_text(text)
    pcabench.studies.__path__.append(str(root / "pcabench" / "studies"))
    studies.PRESETS.cache_clear()
    SECTIONS.cache_clear()
    try:
        yield root
    finally:
        pcabench.studies.__path__.remove(str(root / "pcabench" / "studies"))
        for name in [m for m in sys.modules if m.startswith("pcabench.studies.tiny")]:
            del sys.modules[name]
        studies.PRESETS.cache_clear()
        SECTIONS.cache_clear()


def test_the_study_recipe_is_one_folder_that_the_command_line_and_the_report_find(study_folder, run_recipe):
    assert "tiny" in studies.PRESETS and "statuses" in SECTIONS  # found in its folder, with no other edit
    assert [s.name for s in in_order()][-1] == "statuses"
    ns = run_recipe("Add a study")
    specs = ns["specs"]
    assert [s.scene.dx for s in specs] == [1.0, 0.8, 0.5] and {s.preset for s in specs} == {"tiny"}
    rows = store.read_rows(ns["store_path"])
    assert len(rows) == 3 and {r["preset"] for r in rows} == {"tiny"} and {r["status"] for r in rows} == {"ok"}
    assert sorted(r["n_particles"] for r in rows) == sorted(s.scene.n_particles for s in specs)
    (report,) = [p.read_text() for p in (ns["folder"] / "reports").glob("*/report.md")]
    assert "- [Runs by status](#runs-by-status)" in report  # in the report's contents list
    assert "| ok | 3 |" in report.split("## Runs by status")[1].split("\n## ")[0]


def test_a_study_folder_is_not_found_without_its_files(study_folder):
    """The registries find a study by its files: a folder without plan.py offers no preset."""
    import importlib

    (study_folder / "pcabench" / "studies" / "tiny" / "plan.py").unlink()
    importlib.invalidate_caches()
    studies.PRESETS.cache_clear()
    assert "tiny" not in studies.PRESETS and "statuses" in SECTIONS


def test_the_boundary_method_recipe_registers_a_method_the_cylinder_runs(run_recipe):
    from solvers.boundaries.bodies import boundary_method_names

    ns = run_recipe("Add a boundary method")
    assert "about-itself" not in boundary_method_names()  # unregistered once its block ended
    assert 0 < ns["lattice"] < 0.2 and 0 < ns["mine"] and ns["mine"] != ns["lattice"]  # the method named ran


def test_the_absorber_recipe_registers_an_absorber_that_every_solver_applies(run_recipe):
    from solvers.boundaries.absorbers import absorber_names

    ns = run_recipe("Add an absorber")
    assert "ramp" not in absorber_names()  # unregistered once its block ended
    assert 0 < ns["ramp"] < 0.05 and 0 < ns["sponge"] < 0.01
    assert ns["ramp"] != ns["sponge"]  # the absorber named is the one that ran
