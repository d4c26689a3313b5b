"""The conformance suite (pcabench/conformance.py): every built-in solver passes it, the README's plug-in
example passes it, and a deliberately broken solver fails the check it breaks.

The GPU solver runs it in numba's CUDA simulator (NUMBA_ENABLE_CUDASIM=1) in a subprocess, through the
command line, as CI does.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from pcabench.conformance import (
    CHECK_NAMES,
    SCENES,
    TOLERANCE,
    Subject,
    assert_conforms,
    check_solver,
    compare,
    lattice_neighbours,
    parametrize_with_checks,
)
from solvers import Scene, SceneError, registry
from solvers.linkedlist_cpu import LinkedListCPU

from .conftest import cli_main
from .test_registry import readme_example

ROOT = Path(__file__).resolve().parents[1]
CPU_SOLVERS = [name for name, cls in registry().items() if cls.device == "cpu"]
GPU_SOLVERS = [name for name, cls in registry().items() if cls.device == "gpu"]


def failures(results) -> list[str]:
    return [r.line() for r in results if r.failed]


@parametrize_with_checks(CPU_SOLVERS)
def test_every_builtin_cpu_solver_conforms(solver, check):
    """Each check of each CPU solver its own case (``-k "linkedlist-cpu and agreement"``); a serial solver
    skips the threads check, every other check passes."""
    if check.fn.__name__ == "threads" and not registry()[solver].threaded:
        with pytest.raises(pytest.skip.Exception, match="serial|thread"):
            check(solver)
        return
    assert check(solver).status == "ok"


def test_the_checks_are_the_suites_in_its_order():
    assert [f"{s}-{n}" for s in ("x",) for n in CHECK_NAMES] == [p.id for p in parametrize_with_checks(["x"]).args[1]]


@pytest.mark.tier2  # the whole conformance suite in numba-cuda's simulator: two minutes
@pytest.mark.parametrize("name", GPU_SOLVERS)
def test_the_gpu_solver_conforms_in_the_simulator(name):
    env = dict(
        os.environ,
        NUMBA_ENABLE_CUDASIM="1",
        PYTHONPATH=os.pathsep.join([str(ROOT)] + [p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p]),
    )
    proc = subprocess.run(
        [sys.executable, "-m", "pcabench.cli", "check-solver", name, "--quick", "--json"],
        capture_output=True,
        text=True,
        env=env,
        cwd=ROOT,
        timeout=1800,
    )
    assert proc.returncode == 0, (proc.stdout[-3000:], proc.stderr[-3000:])
    data = json.loads(proc.stdout.strip().splitlines()[-1])
    status = {c["name"]: c["status"] for c in data["checks"]}
    assert data["ok"] and status["agreement"] == status["claims"] == status["neighbours"] == "ok", data


def readme_solver():
    """The README's plug-in class ("Add your own solver"), defined here, not registered."""
    namespace = {}
    exec(compile(readme_example(), "argsort_solver.py", "exec"), namespace)  # noqa: S102 - our own README
    return namespace["ArgsortCellList"]


def test_the_readme_plugin_conforms_as_a_class():
    cls = readme_solver()
    search = cls.neighbour_search
    assert "cell_order" in search.__dict__ and "bin" not in search.__dict__  # it overrides one step of SNP
    assert cls.name not in registry()
    results = assert_conforms(cls, quick=True)
    assert {r.name: r.status for r in results}["stages"] == "ok"  # the harness ran it under its name
    assert cls.name not in registry()  # and the registry is as it was


class ScaledMomentum(LinkedListCPU):
    """Broken on purpose: its momentum sweep is 1 % too strong."""

    name = "scaled-momentum"

    def _sweep(self, continuity, momentum):
        super()._sweep(continuity, momentum)
        if momentum:
            self.arrays["ax"] *= 1.01
            self.arrays["ay"] *= 1.01


class RefusesFloat32(LinkedListCPU):
    """Broken on purpose: it claims float32 but refuses it."""

    name = "refuses-float32"

    def check_scene(self, scene):
        super().check_scene(scene)
        if scene.precision == "float32":
            raise SceneError("precision: float32 is not done yet")


class ClaimsTooLittle(LinkedListCPU):
    """Broken on purpose: it says it offers the verlet integrator alone, yet its supports() accepts any."""

    name = "claims-too-little"
    integrators = ("verlet",)

    @classmethod
    def supports(cls, scene):
        pass


class IgnoresMirrors(LinkedListCPU):
    """Broken on purpose: it claims wall-x, yet its pair-list sweeps leave out the mirror particles' part."""

    name = "ignores-mirrors"
    pair_loops = ("list",)

    def launch(self, name, *args):
        if name in ("wall_continuity", "wall_momentum"):
            return None
        return super().launch(name, *args)


class NoWalls(LinkedListCPU):
    """Honest without walls: it claims every boundary but wall-x."""

    name = "no-walls"
    boundaries = tuple(b for b in LinkedListCPU.boundaries if b != "wall-x")


def walled_scenes() -> list[str]:
    return [name for name, overrides in SCENES.items() if Scene(**overrides).walls]


def test_the_suite_checks_both_walled_scenes_with_every_model():
    assert set(walled_scenes()) == {"plane-wall", "pulse-wall"}
    configs = Subject(LinkedListCPU, quick=True).configurations()
    for scene in walled_scenes():
        assert {c["model"] for c in configs if c["scene"] == scene} == set(LinkedListCPU.models), scene


def test_the_lattice_count_includes_the_mirrors():
    one_wall, two_walls = Scene(**SCENES["plane-wall"]), Scene(**SCENES["pulse-wall"])
    free = Scene(**{**SCENES["plane-wall"], "name": "plane-pulse"})  # the same lattice, free ends
    assert lattice_neighbours(free) < lattice_neighbours(one_wall) < lattice_neighbours(two_walls)


def test_a_solver_that_ignores_the_mirrors_fails_the_agreement_check_on_the_walled_scenes_only():
    (result,) = check_solver(IgnoresMirrors, quick=True, only=("agreement",))
    assert result.failed and "differs" in result.message, result.line()
    subject, failed = Subject(IgnoresMirrors, quick=True), set()
    for config in subject.configurations():
        scene = subject.scene_of(config)
        got, _ = subject.evolve(scene, pair_loop="list")
        reference, _ = subject.evolve(scene, reference=True)
        if compare(got, reference, scene, TOLERANCE[scene.precision]):
            failed.add(config["scene"])
    assert failed == set(walled_scenes())


def test_a_solver_without_walls_is_refused_a_walled_scene_in_one_line_and_conforms():
    for scene in walled_scenes():
        with pytest.raises(SceneError) as refused:
            NoWalls.supports(Scene(**SCENES[scene]))
        message = str(refused.value)
        assert len(message.splitlines()) == 1 and "wall-x" in message and scene in message, message
    (claims,) = check_solver(NoWalls, quick=True, only=("claims",))
    assert claims.status == "ok", claims.line()
    assert Subject(NoWalls, quick=True).claimed_scenes() == [  # the scene registry's order, each kind's open case next
        "plane-pulse",
        "plane-pulse-open",
        "acoustic-pulse",
        "acoustic-pulse-open",
        "acoustic-pulse-3d",
        "acoustic-pulse-3d-open",
        "cylinder",
        "sphere",
    ]


def test_a_broken_momentum_sweep_fails_the_agreement_check():
    results = check_solver(ScaledMomentum, quick=True, only=("agreement",))
    assert [r.status for r in results] == ["failed"]
    assert "velocity differs" in results[0].message
    failed, of = map(int, re.match(r"(\d+) of (\d+) configurations", results[0].message).groups())
    assert 0 < failed <= of  # configurations, not the fields that differ in them (issue 39: "45 of 17")
    with pytest.raises(AssertionError, match="agreement: FAILED"):
        assert_conforms(ScaledMomentum, only=("agreement",))


def test_a_false_claim_fails_the_claims_check():
    (refused,) = check_solver(RefusesFloat32, quick=True, only=("claims",))
    assert refused.failed and "float32" in refused.message and "refused" in refused.message
    (loose,) = check_solver(ClaimsTooLittle, quick=True, only=("claims",))
    assert loose.failed and "integrator euler is not claimed but supports() accepts it" in loose.message


def test_a_solver_that_cannot_run_here_is_skipped_not_failed():
    from solvers import SolverUnavailable

    class NoDevice(LinkedListCPU):
        name = "no-device"

        @classmethod
        def available(cls):
            raise SolverUnavailable("no such device on this machine")

    results = check_solver(NoDevice, quick=True)
    assert {r.status for r in results} == {"skipped"} and all("no such device" in r.message for r in results)


def test_the_command_line(capsys):
    rc, out, err = cli_main("check-solver", "allpair-cpu", "--quick", capsys=capsys)
    lines = out.strip().splitlines()
    assert rc == 0, out + err
    assert [line.split(":")[0] for line in lines[:-1]] == list(CHECK_NAMES)
    assert "threads: skipped: allpair-cpu is serial" in out and "agreement: ok" in out
    assert lines[-1].startswith("allpair-cpu: conforms")
    rc, out, err = cli_main("check-solver", "no-such-solver", capsys=capsys)
    assert rc == 2 and len(err.strip().splitlines()) == 1 and "no-such-solver" in err and "Traceback" not in err


class WrongPastFourHundred(LinkedListCPU):
    """A linked-list solver whose velocity goes wrong only on a lattice of more than 400 particles."""

    name = "wrong-past-400"

    def output(self):
        fields = super().output()
        if self.scene.n_particles > 400:
            fields.u[len(fields.u) // 2] += 1e-3
        return fields


def test_the_quick_check_fails_a_solver_wrong_only_past_the_tiny_lattices():
    (result,) = check_solver(WrongPastFourHundred, quick=True, only=("agreement",))
    assert result.failed and "plane-pulse-3200" in result.message, result.message


class IgnoresTheLayer(LinkedListCPU):
    """The cell list without the open edges' damping: the layer reflects like a free end."""

    name = "ignores-the-layer"

    def absorb(self, f, fields):
        pass


def test_a_solver_that_skips_the_open_edges_layer_fails_agreement_on_the_open_scene_only():
    (result,) = check_solver(IgnoresTheLayer, quick=True, only=("agreement",))
    assert result.failed and "plane-pulse-open" in result.message, result.message
    assert "plane-wall" not in result.message and "acoustic-pulse/" not in result.message, result.message


class IgnoresTheSplit(LinkedListCPU):
    """The cell list with the PML's x part of the continuity rate left at zero: drho_x never changes."""

    name = "ignores-the-split"

    def rates(self, continuity, momentum):
        super().rates(continuity, momentum)
        if self.split:
            self.arrays["ddx"][:] = 0


def test_a_solver_that_skips_the_pmls_split_fails_agreement_on_the_open_square_only():
    (result,) = check_solver(IgnoresTheSplit, quick=True, only=("agreement",))
    assert result.failed and "acoustic-pulse-open" in result.message, result.message
    assert "plane-pulse-open" not in result.message and "acoustic-pulse/" not in result.message, result.message


def test_a_new_scene_kind_is_checked_everywhere_with_no_list_to_edit():
    """Issue 58: the conformance suite and the GPU check read their cases from the scene kinds
    (SceneKind.smallest, smallest_open, card, card_open): a kind registered now is in both."""
    from pcabench.conformance import Subject, scene_cases
    from pcabench.studies.open_edges import gpu as open_gpu
    from pcabench.studies.walls import gpu as walls_gpu
    from solvers.scenes import SCENES
    from solvers.scenes.plane_pulse import PlanePulse
    from solvers.scenes.plane_wall import PlaneWall

    class ShortDuct(PlaneWall):
        name = "short-duct"
        summary = "a walled duct (a test's plug-in)"

    class OpenLine(PlanePulse):
        name = "open-line"
        summary = "the plane pulse again (a test's plug-in)"
        card_open = {"dx": 0.5, "open": "x"}

    with SCENES.registered(ShortDuct), SCENES.registered(OpenLine):
        cases = scene_cases()
        assert cases["short-duct"]["name"] == "short-duct" and "short-duct-open" not in cases  # a wall: no open case
        assert cases["open-line-open"]["open"] == "x"
        claimed = Subject(LinkedListCPU, quick=True).claimed_scenes()
        assert {"short-duct", "open-line", "open-line-open"} <= set(claimed)
        Scene(**cases["short-duct"], steps=1)  # a case the Scene takes
        assert {"name": "short-duct", "dx": 0.5} in walls_gpu.cases(rehearse=False).scenes
        assert {"name": "open-line", "dx": 0.5, "open": "x"} in open_gpu.cases(rehearse=False).scenes
    assert "short-duct" not in scene_cases() and "short-duct" not in str(walls_gpu.cases(rehearse=False).scenes)


def test_an_all_pair_class_checks_itself_on_the_cases_its_n_squared_affords():
    """The all-pair solver (order 2) runs its own checks on the cases of at most QUADRATIC_MOST particles (its
    larger ones, the 3D body's 13,068, run as every cell list's reference); it still claims them all, and a cell
    list runs every case it claims."""
    from pcabench.conformance import QUADRATIC_MOST, Subject
    from solvers import solver_class

    quadratic, cells = (Subject(solver_class(name), quick=True) for name in ("allpair-cpu", "linkedlist-cpu"))
    big = [n for n in quadratic.claimed_scenes() if quadratic.scene(name=n).n_particles > QUADRATIC_MOST]
    assert "sphere" in big and not set(big) & set(quadratic.run_scenes())
    assert set(quadratic.run_scenes()) | set(big) == set(quadratic.claimed_scenes())
    assert cells.run_scenes() == cells.claimed_scenes() and "sphere" in cells.run_scenes()
