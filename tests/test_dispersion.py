"""The predicted error and stable step (solvers/reference/dispersion.py) against runs of the same scene.

The prediction is exact linear algebra of the `linear` model's discrete operator and the integrator's own
step program on an unbounded lattice, so a run must agree with it to many digits while the pulse and its
dispersive tail stay clear of the domain's ends, and the stable CFL it gives must be where runs blow up.
"""

from __future__ import annotations

import json

import pytest

from pcabench.execute.run import run
from pcabench.spec import RunSpec
from solvers import Scene
from solvers.reference.dispersion import largest_stable_z, predict, predicted_stable_cfl

from .conftest import cli_main


def strip_scene(dx, **kw) -> Scene:
    """The pulse's scene on a strip, 110 m long: its error waves stay clear of the ends (which the unbounded
    lattice of the prediction does not have) up to t = 10 s at every step tested."""
    return Scene(
        dx=dx,
        t_end=10.0,
        model="linear",
        x_min=-40.0,
        x_max=70.0,
        **kw,
        strip_height=Scene.thinnest_strip(dx, kw.get("cutoff_factor"), kw.get("h_factor"), kw.get("kernel")),
    )


@pytest.mark.parametrize(
    "kw",
    [
        dict(dx=0.2),
        dict(dx=0.1, h_factor=1.5),
        dict(dx=0.2, cfl=1.0),
        dict(dx=0.25, h_factor=1.3, cutoff_factor=2.5),
        dict(dx=0.2, integrator="kdk1"),
        dict(dx=0.2, kernel="wendland-c4", h_factor=1.6, cfl=1.5),
        dict(dx=0.2, kernel="wendland-c2"),
    ],
)
def test_predicted_error_is_the_measured_error(kw):
    scene = strip_scene(**kw)
    measured = run(RunSpec("linkedlist-cpu", scene))
    assert measured.status == "ok"
    predicted = predict(scene).predicted_error
    assert predicted == pytest.approx(measured.mse, rel=1e-8)


@pytest.mark.filterwarnings("ignore:divide by zero")  # the pulse has left the domain by the last step
def test_the_step_limit_is_where_runs_blow_up():
    scene = Scene(dx=0.5, steps=60, model="linear", strip_height=Scene.thinnest_strip(0.5))
    limit = predicted_stable_cfl(scene)
    assert run(RunSpec("linkedlist-cpu", scene.replace(cfl=0.95 * limit))).status == "ok"
    assert run(RunSpec("linkedlist-cpu", scene.replace(cfl=1.05 * limit))).status == "unstable"


def test_integrators_stability():
    assert largest_stable_z("verlet") == pytest.approx(2.0, abs=2e-3)  # the leapfrog's c0 |D| dt <= 2
    for grows in ("euler", "kdk1", "rk2"):
        assert largest_stable_z(grows) == 0.0


def test_the_leapfrog_lead_offsets_the_lattice_lag():
    """Why larger steps are more accurate at the paper's h: the step's phase lead cancels part of the lag."""
    small, large = (predict(strip_scene(0.25, cfl=c)) for c in (0.2, 4.0))
    assert small.lattice_phase_error < 0 and small.lattice_phase_error == large.lattice_phase_error
    assert abs(large.step_phase_error) < abs(small.step_phase_error)
    assert large.predicted_error < small.predicted_error


def test_accuracy_command_json(capsys):
    rc, out, err = cli_main("accuracy", "--dx", "0.2", "--t-end", "10", "--h-factor", "1.5", "--json", capsys=capsys)
    assert rc == 0, err
    data = json.loads(out)
    assert data["predicted_error"] == pytest.approx(predict(strip_scene(0.2, h_factor=1.5)).predicted_error, rel=1e-6)
    assert data["stable_cfl"] > 1
    rc, out, err = cli_main("accuracy", "--dx", "0.2", "--cfl", "0", capsys=capsys)
    assert rc == 2 and "cfl" in err and "Traceback" not in err
