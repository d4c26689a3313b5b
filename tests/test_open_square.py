"""Open y edges and the 2D pulse in the open plane (issue 41): free y edges in every solver, the split-field
PML, the open plane's exact reference (the CAA workshop's Bessel integral, with the images of an axis that
stays periodic) and what the open edges leave behind at oblique incidence.

The measure of an open edge is what the run leaves in the scored domain once the pulse has gone, against the
open plane's exact solution (``left_amplitude``, ``left_energy``: solvers/scenes/base.py); the dispersion
prediction on a lattice with room enough that no image comes back (solvers/reference/dispersion.unbounded) is
what a perfect absorber leaves.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from solvers import Scene, make_solver
from solvers.interface import Fields, Solver
from solvers.linkedlist_cpu import LinkedListCPU
from solvers.physics.integrators import evolve
from solvers.reference.dispersion import predict, predicted_fields_2d
from solvers.reference.pulse2d import OpenPulse, gaussian_pulse, open_domain, periodic_linear

from .conftest import cli_main

B, MACH, RHO0, C0 = 3.0, 0.05, 1.0, 1.0


def square(size=18.0, dx=0.25, **kw) -> Scene:
    half = 0.5 * size
    base = dict(dx=dx, name="acoustic-pulse", x_min=-half, x_max=half, y_min=-half, y_max=half, model="linear")
    return Scene(**{**base, **kw})


def test_the_open_reference_is_the_bessel_integral_at_any_point_and_the_periodic_one_with_its_images():
    """Interpolated from its table, the open plane's solution matches the Bessel integral at scattered points
    to 1e-9 of the peak and is the Gaussian at t = 0 (to 1e-8); with both axes' images summed it is the periodic
    square's spectral solution, wrapped waves and all, after the pulse has crossed the square (t = 30 s, 40 m)."""
    x = np.linspace(-20.0, 20.0, 81)
    rng = np.random.default_rng(1)
    px, py = rng.uniform(-19, 19, 400), rng.uniform(-19, 19, 400)
    ref = OpenPulse(x, x, 0.0, 0.0, (0.0, 0.0), B, MACH, RHO0, C0, 12.0)
    drho, u, v = ref.at(px, py)
    d_exact, u_r = open_domain(np.hypot(px, py), 12.0, B, MACH, RHO0, C0)
    r = np.hypot(px, py)
    assert np.abs(drho - d_exact).max() < 1e-9 * RHO0 * MACH
    assert np.abs(u - u_r * px / r).max() < 1e-9 * C0 * MACH and np.abs(v - u_r * py / r).max() < 1e-9 * C0 * MACH
    start = OpenPulse(x, x, 0.0, 0.0, (0.0, 0.0), B, MACH, RHO0, C0, 0.0)
    gx, gy = np.meshgrid(x, x)
    assert np.abs(start.drho - gaussian_pulse(gx**2 + gy**2, B, MACH, RHO0)).max() < 1e-8 * RHO0 * MACH
    n, dx = 80, 0.5
    periodic = periodic_linear(n, n, dx, -20.0, -20.0, 0.0, 0.0, B, MACH, RHO0, C0, 30.0)
    images = OpenPulse(periodic.x, periodic.y, 0.0, 0.0, (40.0, 40.0), B, MACH, RHO0, C0, 30.0)
    lone = OpenPulse(periodic.x, periodic.y, 0.0, 0.0, (0.0, 0.0), B, MACH, RHO0, C0, 30.0)
    assert np.abs(images.drho - periodic.drho).max() < 1e-8 * RHO0 * MACH
    assert np.abs(lone.drho - periodic.drho).max() > 1e-3 * RHO0 * MACH  # the images count by then


def test_the_prediction_of_an_open_square_is_the_open_planes_and_the_run_equals_it_before_the_layer():
    """Before the pulse reaches the layer, the linear run is the prediction (mode by mode, exact for linear),
    scored against the open plane; after the pulse has left, the periodic square's images would be back: the
    prediction's lattice has room for them not to be."""
    scene = square(size=40.0, dx=0.5, t_end=8.0, open="xy")
    fields = evolve(make_solver("linkedlist-cpu", pair_loop="list"), scene).output()
    got, expected = scene.kind.errors(scene, fields), predict(scene)
    assert abs(got["mse"] / expected.predicted_error - 1) < 1e-6, (got["mse"], expected.predicted_error)
    late = square(t_end=24.0, open="xy")
    gone = predict(late).measures
    x, y, drho, u, v, t = predicted_fields_2d(late.replace(open=""))  # the periodic square: its images are in
    closed = late.kind.errors(late, Fields(x=x.ravel(), y=y.ravel(), u=u.ravel(), v=v.ravel(), drho=drho.ravel(), t=t))
    assert gone["left_amplitude"] < 1e-3 and gone["left_energy"] < 1e-5, gone
    assert closed["left_amplitude"] > 30 * gone["left_amplitude"], (closed, gone)


def test_a_pulse_leaves_an_open_square_within_the_issues_bound_and_the_sponge_reflects_its_wake():
    """The 2D pulse (18 m square, dx 0.25: 12 particles a pulse width) through all four edges at oblique
    incidence: the default layer (two pulse widths, the PML) leaves at most 1e-3 of the amplitude behind and
    1e-4 of the energy, against the open plane's exact solution at t = 24 s, when the front has passed the
    corners; the sponge damps the slow wake behind the front and sends it back, ten times as much."""
    scene = square(t_end=24.0, open="xy")
    assert scene.absorber_used == "pml"
    pml = scene.kind.errors(scene, evolve(make_solver("linkedlist-cpu", pair_loop="list"), scene).output())
    assert pml["left_amplitude"] < 1e-3 and pml["left_energy"] < 1e-4, pml
    sponge_scene = scene.replace(absorber="sponge")
    fields = evolve(make_solver("linkedlist-cpu", pair_loop="list"), sponge_scene).output()
    sponge = sponge_scene.kind.errors(sponge_scene, fields)
    assert sponge["left_amplitude"] > 10 * pml["left_amplitude"], (sponge, pml)


@pytest.mark.parametrize("absorber", ["pml", "sponge"])
@pytest.mark.parametrize("model", ["linear", "lagrangian"])
def test_every_cpu_solver_and_pair_loop_runs_free_y_edges_alike(model, absorber):
    scene = square(size=12.0, dx=0.5, steps=30, model=model, open="xy", layer_width=3.0, pulse_width=1.5)
    scene = scene.replace(pulse_center=3.0, mach=0.2, absorber=absorber)
    ref = evolve(make_solver("allpair-cpu"), scene).output()
    for kw in (dict(pair_loop="list"), dict(pair_loop="gather"), dict(pair_loop="list", threads=2)):
        got = evolve(make_solver("linkedlist-cpu", **kw), scene).output()
        for name in ("u", "v", "drho", "x", "y"):
            assert np.abs(getattr(got, name) - getattr(ref, name)).max() < 1e-12, (kw, name)
    other = scene.replace(open="x")  # y periodic again: the pulse's images across the y seams
    assert np.abs(evolve(make_solver("allpair-cpu"), other).output().drho - ref.drho).max() > 1e-4


class TwoSweeps(LinkedListCPU):
    """The pair list with the PML's x part by a second sweep with v = 0 (``Solver.continuity_parts``, as the
    gather loop, the all-pair and the GPU solvers compute it) instead of in the rate's own pass."""

    name = "two-sweeps"

    def continuity_parts(self):
        Solver.continuity_parts(self)


@pytest.mark.parametrize("threads", [1, 2])
@pytest.mark.parametrize("model", ["linear", "lagrangian"])
def test_the_pair_lists_one_pass_gives_the_pmls_x_part_of_two_sweeps_to_the_bit(model, threads):
    scene = square(size=12.0, dx=0.5, steps=30, model=model, open="xy", layer_width=3.0, pulse_width=1.5)
    scene = scene.replace(pulse_center=3.0, mach=0.2, absorber="pml")
    one = evolve(LinkedListCPU(threads=threads, pair_loop="list"), scene)
    two = evolve(TwoSweeps(threads=threads, pair_loop="list"), scene)
    for name in ("u", "v", "drho", "drho_x", "sx", "sy"):
        assert np.array_equal(one.arrays[name], two.arrays[name]), name
    assert np.abs(one.arrays["drho_x"]).max() > 0  # the layer's x part was at work


def test_open_x_alone_keeps_the_y_images():
    """--open x on the 2D pulse: open in x, still periodic in y; the reference sums the y images, so that the
    linear run is its prediction to round-off once the wrapped waves are in (t = 14 s in a 24 m square)."""
    scene = square(size=24.0, dx=0.5, t_end=14.0, open="x")
    assert scene.periodic_y and not scene.periodic_x and scene.ny == 48 and scene.nx == 48 + 2 * 12
    fields = evolve(make_solver("linkedlist-cpu", pair_loop="list"), scene).output()
    got = scene.kind.errors(scene, fields)
    mirrored = predict(scene)
    assert abs(got["axis_rms"] / mirrored.measures["axis_rms"] - 1) < 5e-2, (got, mirrored.measures)


# The GPU solver on open edges (free y, the PML, the sponge) in the simulator: check-solver's open scenes
# (tests/test_conformance.py runs linkedlist-gpu through them), and gpu-check's open stage, both precisions, which
# CI rehearses.


def test_the_command_line_runs_the_open_square_and_stores_what_is_left(capsys):
    code, out, err = cli_main(
        "run", "--solver", "linkedlist-cpu", "--scene", "acoustic-pulse", "--domain-size", "12",
        "--pulse-width", "1.5", "--dx", "0.5", "--steps", "3", "--open", "xy", "--model", "linear", "--json",
        capsys=capsys,
    )  # fmt: skip
    assert code == 0, err
    record = json.loads(out)
    assert record["status"] == "ok" and record["scene"]["open"] == "xy", record
    assert "left_amplitude" in record["errors"] and "left_energy" in record["errors"], record["errors"]
    # a linear run against a perfect absorber's answer: 3 steps in, only the pulse's far flank (1e-5 of its peak)
    # is in the layer
    assert record["errors"]["reflected_amplitude"] < 1e-6, record["errors"]
    predicted = predict(square(size=12.0, dx=0.5, steps=3, open="xy", pulse_width=1.5)).measures
    assert "left_amplitude" in predicted and "reflected_amplitude" not in predicted  # not scored by itself
    code, _, err = cli_main("run", "--solver", "linkedlist-cpu", "--dx", "1", "--open", "xy", capsys=capsys)
    assert code == 2 and len(err.strip().splitlines()) == 1 and "--open y" in err and "plane wave" in err, err
