"""Open edges (issue 41, first part): the plane pulse leaves through an absorbing layer of particles beyond its
domain, every solver runs the layer alike, the scored domain is the closed scene's, and bad input is one line.

The reference for an open edge is the open domain's answer: the dispersion prediction on a lattice long enough
that nothing reaches its ends (``solvers.reference.dispersion.predicted_velocity``), which is what a perfect
absorber leaves; the free end's reflection is the contrast.
"""

from __future__ import annotations

import numpy as np
import pytest

from pcabench.execute.run import run
from pcabench.paths import reference_results
from pcabench.spec import RunSpec, scene_from_row, stored_parameters
from pcabench.store import read_rows
from solvers import Scene, SceneError, make_solver
from solvers.boundaries.absorbers.sponge import Sponge
from solvers.physics.integrators import evolve
from solvers.reference.dispersion import predicted_velocity

from .conftest import cli_main

T_GONE = 64.0  # s: the pulse (from x = 0) left x = 40 m at t ~ 45 s, and what the layer's far end reflects is back


def plane(dx=0.25, **kw) -> Scene:
    return Scene(**{"dx": dx, "model": "linear", "strip_height": Scene.thinnest_strip(dx), **kw})


def departure(scene: Scene, solver: str = "linkedlist-cpu") -> tuple[float, float]:
    """(largest |u - u_open| over the amplitude, the energy of u - u_open over the pulse's) in the scored domain,
    u_open the open domain's answer at the same time (the prediction on a lattice 100 m longer each way)."""
    fields = evolve(make_solver(solver), scene).output()
    far = scene.replace(open="", x_min=scene.x_min - 100.0, x_max=scene.x_max + 100.0)
    x, u_open, _ = predicted_velocity(far)
    x0, u0, _ = predicted_velocity(far.replace(t_end=None, steps=1))
    row = np.isclose(fields.y, fields.y.min())  # the plane pulse is the same on every row
    gap = fields.u[row] - np.interp(fields.x[row], x, u_open)
    pulse = np.interp(fields.x[row], x0, u0)
    return float(np.abs(gap).max() / (scene.mach * scene.c0)), float(np.sum(gap**2) / np.sum(pulse**2))


def test_a_plane_pulse_leaves_through_an_open_end_within_the_issues_bounds():
    """With the default layer (1.5 pulse widths, the sponge at its default strength) what the pulse leaves
    behind is below 1 % of its amplitude and 1e-4 of its energy; the free end sends back nearly all of it."""
    amplitude, energy = departure(plane(open="x", t_end=T_GONE))
    assert amplitude < 1e-2 and energy < 1e-4, (amplitude, energy)
    free_amplitude, free_energy = departure(plane(t_end=T_GONE))
    assert free_amplitude > 0.5 and free_energy > 0.5, (free_amplitude, free_energy)


def test_a_thinner_or_weaker_layer_leaves_more_behind():
    """The measure can fail: half a pulse width of layer, or a tenth of the strength, leaves far more."""
    best, _ = departure(plane(open="x", t_end=T_GONE))
    thin, _ = departure(plane(open="x", layer_width=1.5, t_end=T_GONE))
    weak, _ = departure(plane(open="x", absorber_strength=0.2, t_end=T_GONE))
    assert thin > 10 * best and weak > 10 * best, (best, thin, weak)


def test_the_scored_domain_is_the_closed_scenes_and_the_layer_adds_its_columns():
    closed, opened = plane(dx=0.5, steps=2), plane(dx=0.5, steps=2, open="x", layer_width=6.0)
    assert opened.n_particles == closed.n_particles + 2 * 12 * closed.ny and opened.n_scored == closed.n_particles
    a = evolve(make_solver("linkedlist-cpu"), closed).output()
    b = evolve(make_solver("linkedlist-cpu"), opened).output()
    assert np.array_equal(a.x, b.x) and np.array_equal(a.y, b.y)
    record = run(RunSpec("linkedlist-cpu", opened))
    assert record.status == "ok" and record.n_particles == opened.n_particles, record.message


def test_each_absorber_brings_its_own_default_layer():
    """The sponge's default layer is 1.5 pulse widths (the thinnest inside the targets, above), the PML's two:
    on the paper's domain (dx 0.1) the sponge's layer adds 18 % to its 100,000 particles."""
    paper, sponge = Scene(dx=0.1), Scene(dx=0.1, open="x")
    assert sponge.absorber_used == "sponge" and sponge.layer == pytest.approx(1.5 * sponge.pulse_width)
    assert sponge.n_particles == paper.n_particles + 2 * 45 * paper.ny
    pml = Scene(dx=0.1, open="x", absorber="pml")
    assert pml.layer == pytest.approx(2 * pml.pulse_width) and pml.strength == pytest.approx(12 * pml.c0 / 6.0)


def test_stored_open_rows_come_back_with_the_layer_they_ran(monkeypatch):
    """A row keeps its layer's width (the derived key ``layer``); a row stored before it did ran every absorber's
    layer at two pulse widths and comes back so, not at today's default; every open run of the reference store
    comes back with the particles it ran."""
    scene = plane(dx=0.5, steps=2, open="x")
    row = {"scene": scene.as_dict(), "n_particles": scene.n_particles}
    assert scene_from_row(row) == scene and scene_from_row(row).n_particles == scene.n_particles
    old = {k: v for k, v in scene.as_dict().items() if k != "layer"}
    assert scene_from_row({"scene": old}).layer == pytest.approx(2 * scene.pulse_width)
    # the PML's default is still two pulse widths: an old row and a new one are one configuration
    pml = scene.replace(absorber="pml")
    new_row, old_row = pml.as_dict(), {k: v for k, v in pml.as_dict().items() if k != "layer"}
    assert stored_parameters(new_row) == stored_parameters(old_row)
    assert stored_parameters(old_row)["layer_width"] is None
    # a default that changes after a row was stored: the row still reads as the layer it ran
    sponge = plane(dx=0.5, steps=2, open="x")
    stored = {"scene": sponge.as_dict(), "n_particles": sponge.n_particles}
    monkeypatch.setattr(Sponge, "default_widths", 2.0)
    assert scene_from_row(stored).layer == pytest.approx(4.5) and scene_from_row(stored) != sponge.replace()
    rows = [r for r in read_rows(reference_results()) if (r.get("scene") or {}).get("open")]
    assert rows and all(scene_from_row(r).n_particles == r["n_particles"] for r in rows)


@pytest.mark.parametrize("model", ["linear", "lagrangian"])
def test_every_cpu_solver_and_pair_loop_runs_the_layer_alike(model):
    scene = plane(dx=1.0, steps=30, model=model, open="x", layer_width=6.0, mach=0.2, pulse_center=30.0)
    ref = evolve(make_solver("allpair-cpu"), scene).output()
    for kw in (dict(pair_loop="list"), dict(pair_loop="gather"), dict(pair_loop="list", threads=2)):
        got = evolve(make_solver("linkedlist-cpu", **kw), scene).output()
        assert np.abs(got.u - ref.u).max() < 1e-12 and np.abs(got.drho - ref.drho).max() < 1e-12, kw
    closed = evolve(make_solver("allpair-cpu"), scene.replace(open="")).output()
    assert np.abs(closed.u - ref.u).max() > 1e-3  # the layer acted: the pulse was at the right edge


@pytest.mark.parametrize(
    "kw, words",
    [
        (dict(open="y"), "--open y: the y edges of plane-pulse are periodic"),
        (dict(open="y", name="pulse-wall"), "--open y: the y edges of pulse-wall are periodic"),
        (dict(open="xy", name="acoustic-pulse", layer_width=41.0), "--layer-width must be at most the domain's"),
        (dict(open="x", name="plane-wall", strip_height=None), "--open x: the x edge x_max of plane-wall is a wall"),
        (dict(open="x", layer_width=0.0), "--layer-width must be > 0"),
        (dict(open="x", layer_width=60.0), "--layer-width must be at most the domain's width 50 m"),
        (dict(open="x", absorber_strength=-1.0), "--absorber-strength must be > 0"),
        (dict(open="x", absorber="nope"), "--absorber must be one of sponge, pml"),
        (dict(open="x", name="plane-wall", strip_height=None, absorber="nope"), "--absorber must be one of"),
        (dict(open="z"), "--open must be one of x, y, xy"),
    ],
)
def test_bad_open_edges_are_one_line_naming_the_option(kw, words):
    with pytest.raises(SceneError, match=words.replace("(", r"\(")):
        Scene(**{"dx": 0.5, "steps": 2, "model": "linear", **kw})


def test_the_command_line_runs_an_open_edge_and_refuses_a_periodic_one(capsys):
    code, out, err = cli_main(
        "run", "--solver", "linkedlist-cpu", "--dx", "1", "--steps", "3", "--open", "x", "--quiet", capsys=capsys
    )
    assert code == 0 and "status           ok" in out, err
    code, out, err = cli_main("run", "--solver", "linkedlist-cpu", "--dx", "1", "--open", "y", capsys=capsys)
    assert code == 2 and len(err.strip().splitlines()) == 1 and "--open y" in err and "Traceback" not in err
