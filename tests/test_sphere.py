"""The rigid sphere (issue 65): the 3D body's scene, its weak wall and its one-line refusals. Its exact reference is
tests/test_sphere_reference.py's; the solvers' agreement on it is the conformance suite's (SceneKind.smallest)."""

from __future__ import annotations

import numpy as np
import pytest

from solvers import Scene, SceneError
from solvers.boundaries.bodies.base import INERT
from solvers.physics.integrators import evolve
from solvers.registry import make_solver

HIGH = dict(kernel="laguerre-gauss", h_factor=1.5, cutoff_factor=4.0, correction="gradient", cfl=0.5)


@pytest.mark.parametrize(
    "changes, words",
    [
        ({}, "--boundary-method rings: the sphere scene's body is 3D"),  # standard SPH: no wall in 3D
        (dict(**HIGH, boundary_method="lattice"), "whose wall is --boundary-method cut or weak alone"),
        (dict(**HIGH, open="x"), "its six faces are always open"),
        (dict(**HIGH, probes=((0.3, 0.0, 0.0),)), "--probe 0.3,0,0 is inside the body"),
        (dict(**HIGH, pulse_center=0.7), "--pulse-center: the pulse's centre must be at least a pulse width"),
        (dict(**HIGH, cylinder_radius=0.5), "--cylinder-radius: the sphere scene has no body of that shape"),
    ],
)
def test_bad_sphere_input_is_one_line_naming_the_option(changes, words):
    with pytest.raises(SceneError) as err:
        Scene(0.1, "sphere", steps=2, **changes)
    assert words in str(err.value) and "\n" not in str(err.value), str(err.value)


def test_the_sphere_defaults_are_the_issues_problem():
    scene = Scene(0.1, "sphere", t_end=4.0, **HIGH)
    assert scene.body == (0.0, 0.0, 0.5) and scene.pulse_width == 0.4 and scene.pulse_center == 1.5
    assert scene.open == "xyz" and scene.boundary_method_used == "cut" and scene.absorber_used == "pml"
    assert scene.probe_points() == {"A": (0.0, 1.5, 0.0), "B": (-1.0607, 1.0607, 0.0), "C": (-1.5, 0.0, 0.0)}


def test_the_bodys_particles_are_massless_and_stay_silent():
    """Inside the sphere every site is inert, massless and zero after every step; outside the pulse moves."""
    kw = dict(x_min=-1.0, x_max=2.0, y_min=-1.0, y_max=1.0, z_min=-1.0, z_max=1.0, pulse_center=1.2, layer_width=0.5)
    method = dict(kernel="wendland-c2", h_factor=1.3, correction="gradient", cfl=0.5)
    scene = Scene(0.125, "sphere", steps=4, model="linear", **method, **kw)
    solver = evolve(make_solver("linkedlist-cpu"), scene)
    solver.prepare_boundaries()
    a = solver.arrays
    inert = a["role"] == INERT
    assert inert.sum() > 100 and np.all(a["mass"][inert] == 0)
    assert all(np.all(a[name][inert] == 0) for name in ("u", "v", "w", "drho"))
    fluid = ~inert
    assert np.all(np.isfinite(a["drho"][fluid])) and np.abs(a["u"][fluid]).max() > 0


@pytest.mark.tier2  # the series' spectrum, 7 s
def test_accuracy_predicts_the_sphere_at_its_own_end_time(capsys):
    """``accuracy --scene sphere``: the bulk's share of the probes' error (the series with the method's dispersion,
    the wall exact), at the scene's own --t-end (the window's end, 4 s) when none is given."""
    import json

    from .conftest import cli_main

    method = "--kernel laguerre-gauss --cutoff 4 --h-factor 1.5 --correction gradient --cfl 0.5".split()
    rc, out, err = cli_main("accuracy", "--scene", "sphere", "--dx", "0.1", *method, "--json", capsys=capsys)
    assert rc == 0, err
    got = json.loads(out)
    assert got["t_end"] == pytest.approx(4.0) and 0.05 < got["predicted_error"] < 0.5, got


def test_a_wall_without_ghosts_takes_the_free_ends_stable_step():
    """The weak wall and its cut cells leave the fluid beside the body part of its neighbours, as a free edge
    does: the sphere's and the cylinder's stable CFL with them is the free end's measured one (below the periodic
    lattice's), the cylinder's ghost rings keep the lattice's."""
    from pcabench.predict.stability import stable_cfl
    from solvers.method import Method
    from solvers.reference.dispersion import predicted_stable_cfl

    method = {k: v for k, v in HIGH.items() if k != "cfl"}
    free_end = stable_cfl(Scene(0.25, "plane-pulse", model="linear", **method))
    lattice = predicted_stable_cfl(Method.of(Scene(0.5, "acoustic-pulse-3d", model="linear", **method)))
    assert free_end < 0.8 * lattice
    for scene in (
        Scene(0.125, "sphere", model="linear", **method),
        Scene(0.125, "sphere", model="linear", boundary_method="weak", **method),
        Scene(0.05, "cylinder", model="linear", boundary_method="weak", **method),
    ):
        assert stable_cfl(scene) == free_end, scene.boundary_method_used
    rings = Scene(0.05, "cylinder", model="linear")
    assert rings.boundary_method_used == "rings" and stable_cfl(rings) == predicted_stable_cfl(Method.of(rings))


@pytest.mark.tier2  # two runs of the sphere at dx 0.125, about a minute
def test_the_spheres_wall_lowers_its_stable_step_to_the_measured_one():
    """The body's wall (cut cells) blows up below the periodic lattice's stable step, and the suite's stable CFL
    for the sphere is the measured one (pcabench/predict/measured_limits.csv): a run at advise's share of it holds,
    one at 0.93 of the lattice's blows up within a few steps and is recorded so."""
    from pcabench.execute.run import run as run_spec
    from pcabench.predict.stability import margin, stable_cfl
    from pcabench.spec import RunSpec
    from solvers.reference.dispersion3d import predicted_stable_cfl

    method = {k: v for k, v in HIGH.items() if k != "cfl"}
    scene = Scene(0.125, "sphere", model="linear", boundary_method="cut", steps=40, **method)
    lattice, limit = predicted_stable_cfl(scene), stable_cfl(scene)
    assert limit < 0.8 * lattice, (limit, lattice)
    held = run_spec(RunSpec("linkedlist-cpu", scene.replace(cfl=margin("linear") * limit)))
    blown = run_spec(RunSpec("linkedlist-cpu", scene.replace(cfl=0.93 * lattice, steps=12)))
    assert held.status == "ok" and blown.status == "unstable" and 0 < blown.failed_step < 12, (held, blown)


@pytest.mark.parametrize(
    "size, words",
    [
        ("-3", "--domain-size must be > 0 m (got -3)"),
        ("1", "--pulse-center must be inside the domain"),
        ("3.2", "--pulse-center: the pulse must be inside the cube, 1.5 pulse widths from its faces"),
    ],
)
def test_the_spheres_cube_from_domain_size_is_checked_in_one_line(size, words, capsys):
    from .conftest import cli_main

    method = "--kernel laguerre-gauss --cutoff 4 --h-factor 1.5 --correction gradient".split()
    rc, _out, err = cli_main(
        "run", "--solver", "linkedlist-cpu", "--scene", "sphere", "--dx", "0.125", "--steps", "1", "--domain-size",
        size, *method, capsys=capsys,
    )  # fmt: skip
    assert rc == 2 and words in err and len(err.strip().splitlines()) == 1, err
