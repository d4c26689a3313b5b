"""High-order SPH: the kernel gradient correction, the Laguerre-Gauss kernel and RK4 (design.md, 1c).

What must hold, each checked against something independent of the code under test:
- the corrected gradient is exact for linear fields at every fluid particle, the lattice's free edges and
  corners included (the analytic gradient), in every solver and pair loop;
- its continuity is the negative adjoint: the discrete energy's rate is zero for any fields, with free edges
  and with walls (what keeps a varying L from having growing modes);
- the runs converge at the orders the method promises (the analytic pulse) and equal the dispersion
  prediction (exact for the linear model), which knows the correction and RK4;
- the solvers agree with each other (the GPU kernels in numba's simulator too);
- bad input is one line naming the option; a particle that cannot be corrected fails the run at its step,
  naming where.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from pcabench.execute.run import run
from pcabench.spec import RunSpec
from solvers import Scene, SceneError, make_solver
from solvers.corrections import SingularMoments
from solvers.kernels import kernel_named
from solvers.reference.dispersion import largest_stable_z, predict, predicted_stable_cfl

from .conftest import in_simulator

HIGH = {"kernel": "laguerre-gauss", "h_factor": 1.5, "cutoff_factor": 4.0, "correction": "gradient"}
SOLVERS = [("allpair-cpu", "all-pairs"), ("linkedlist-cpu", "gather"), ("linkedlist-cpu", "list")]
# the default tier checks the gather loop; the second tier (pytest -m tier2, CI) every CPU solver and loop
EVERY_SOLVER = [
    pytest.param(*pair, marks=())
    if pair == ("linkedlist-cpu", "gather")
    else pytest.param(*pair, marks=pytest.mark.tier2)
    for pair in SOLVERS
]


def prepared(scene, solver="linkedlist-cpu", pair_loop="gather", threads=1):
    s = make_solver(solver, threads=threads, pair_loop=pair_loop)
    s.input(scene)
    s.init()
    s.snp()
    return s


def positions(s):
    sc, a = s.scene, s.arrays
    return (
        sc.x_lo + (np.asarray(a["lx"], float) + 0.5) * sc.dx + np.asarray(a["sx"], float),
        sc.y_lo + (np.asarray(a["ly"], float) + 0.5) * sc.dx + np.asarray(a["sy"], float),
    )


def open_square(**method):
    """The 2D pulse's square with all four edges open: the lattice ends in free edges and corners."""
    return Scene(dx=1.0, name="acoustic-pulse", open="xy", **{**HIGH, "model": "linear", "steps": 1, **method})


@pytest.mark.parametrize("solver,loop", EVERY_SOLVER)
def test_the_corrected_gradient_is_exact_for_linear_fields_at_every_particle(solver, loop):
    s = prepared(open_square(), solver, loop)
    x, y = positions(s)
    a = s.arrays
    a["drho"][:] = 0.3 + 0.02 * x - 0.05 * y
    a["u"][:] = a["v"][:] = 0.0
    s.rates(False, True)
    sc = s.scene
    assert np.allclose(a["ax"], -(sc.c0**2) * 0.02 / sc.rho0, rtol=0, atol=1e-12)
    assert np.allclose(a["ay"], +(sc.c0**2) * 0.05 / sc.rho0, rtol=0, atol=1e-12)
    # standard SPH is not: the edges lose half their neighbours, the interior keeps the lattice moment's error
    plain = prepared(open_square(correction="none"), solver, loop)
    plain.arrays["drho"][:] = 0.3 + 0.02 * x - 0.05 * y
    plain.rates(False, True)
    assert np.abs(plain.arrays["ax"] + 0.02).max() > 5e-3


TIE_FREE = {**HIGH, "cutoff_factor": 3.9}  # 5.85 dx: no lattice distance at the cutoff (6 dx is, for 4 h)


@pytest.mark.parametrize(
    "scene, threads",
    [
        (Scene(dx=0.2, strip_height=3.6, model="lagrangian", steps=8, cfl=0.5, **TIE_FREE), 1),  # periodic seams
        (Scene(dx=0.2, strip_height=3.6, model="lagrangian", steps=8, precision="float32", **TIE_FREE), 2),
        (Scene(dx=0.5, name="pulse-wall", model="lagrangian", steps=8, **TIE_FREE), 2),  # walls: the mirrors' part
        (open_square(model="lagrangian", steps=3, cutoff_factor=3.9), 1),  # free edges and corners
        (Scene(dx=0.05, name="cylinder", boundary_method="weak", model="lagrangian", steps=2, **TIE_FREE), 1),
        (Scene(dx=0.05, name="cylinder", boundary_method="lattice", model="lagrangian", steps=2, **TIE_FREE), 2),
    ],
    ids=["periodic-moved", "float32-threads", "walls-moved", "free-edges", "weak-body", "ghosts-threads"],
)
def test_the_pair_lists_moments_equal_the_gather_loops(scene, threads):
    """Where particles move, the pair list sums the moments from its kernel factors and the positions (no kernel
    evaluation): M and Gamma equal the gather loop's, which evaluates the kernel at every pair, after particles
    moved across the periodic seams, at walls (the mirrors), free edges and bodies, on one thread and on two."""
    from solvers.interface import Solver

    s = prepared(scene, pair_loop="list", threads=threads)
    for _ in range(scene.steps):  # moved: the seams crossed, sx, sy != 0
        s.rates(False, True)
        s.kick(20.0)
        s.advance(20.0)
        s.snp()
    assert float(np.abs(s.arrays["sx"]).max()) > 1e-4 * scene.dx
    s.coefficients(True, False)
    listed = s.moments()
    swept = Solver.moments(s)  # the gather loop over the same cells
    tol = 2e-5 if scene.precision == "float32" else 1e-12
    for name, a, b in zip(("M_xx", "M_xy", "M_yy", "Gamma_x", "Gamma_y"), listed, swept):
        assert np.allclose(np.asarray(a), np.asarray(b), rtol=0, atol=tol), name
    assert abs(float(np.median(np.asarray(listed[0]))) - 1.0) < 0.05  # the moments are there (1 in the lattice)


def test_the_corrected_divergence_is_exact_inside_the_lattice():
    s = prepared(open_square())
    x, y = positions(s)
    a = s.arrays
    a["u"][:] = 0.01 * x + 0.03 * y
    a["v"][:] = -0.02 * x + 0.04 * y
    s.rates(True, False)
    sc = s.scene
    far = 2 * sc.cutoff  # the neighbours' own neighbourhoods are whole: L is the lattice's scalar there
    inside = (x > x.min() + far) & (x < x.max() - far) & (y > y.min() + far) & (y < y.max() - far)
    assert inside.sum() > 100
    assert np.allclose(a["dd"][inside], -sc.rho0 * (0.01 + 0.04), rtol=0, atol=1e-12)


@pytest.mark.parametrize(
    "scene",
    [
        open_square(),
        open_square(kernel="gaussian", h_factor=2.13, cutoff_factor=3.0),
        Scene(dx=0.5, name="pulse-wall", model="linear", steps=1, **HIGH),
    ],
    ids=["free-edges", "free-edges-gaussian", "walls"],
)
@pytest.mark.parametrize("solver,loop", EVERY_SOLVER)
def test_the_corrected_operators_keep_the_discrete_energy(scene, solver, loop):
    """sum_i V_i (rho0 u_i . a_i + c0^2 drho_i dd_i / rho0) = 0 for any fields: momentum's corrected gradient and
    continuity's divergence are negative adjoints, wherever L varies (edges, corners, walls)."""
    s = prepared(scene, solver, loop)
    a = s.arrays
    rng = np.random.default_rng(7)
    for name in ("u", "v", "drho"):
        a[name][:] = rng.standard_normal(a[name].shape)
    s.rates(True, True)
    sc = s.scene
    vol = sc.dx**2
    kinetic = vol * sc.rho0 * (a["u"] * a["ax"] + a["v"] * a["ay"])
    potential = vol * sc.c0**2 * a["drho"] * a["dd"] / sc.rho0
    assert abs(kinetic.sum() + potential.sum()) < 1e-11 * np.abs(kinetic).sum()
    assert np.abs(kinetic).sum() > 1.0  # the fields do move


@pytest.mark.tier2
@pytest.mark.parametrize("model", ["lagrangian", "linear"])
def test_every_cpu_solver_and_loop_runs_the_same_correction(model, tmp_path):
    scene = Scene(dx=0.5, name="pulse-wall", model=model, steps=6, integrator="rk4", cfl=0.5, **HIGH)
    fields = {}
    for solver, loop in SOLVERS + [("linkedlist-cpu", "list")]:
        threads = 2 if (solver, loop) == ("linkedlist-cpu", "list") and len(fields) == 3 else 1
        path = tmp_path / f"{solver}-{loop}-{threads}.npz"
        record = run(RunSpec(solver, scene, threads, pair_loop=loop), fields_path=path)
        assert record.status == "ok", record.message
        fields[(solver, loop, threads)] = dict(np.load(path))
    first, *rest = fields.values()
    for other in rest:
        for name in ("u", "v", "drho", "x"):
            assert np.allclose(other[name], first[name], rtol=0, atol=1e-12), name


def plane(dx, **method):
    """The plane pulse at t = 10 s on a 5 m strip (or the thinnest the cutoff allows at coarse dx: a plane wave's
    answer does not depend on the strip's height)."""
    method = {**HIGH, "integrator": "rk4", "cfl": 1.0, **method}
    kernel, h, cut = method["kernel"], method["h_factor"], method["cutoff_factor"]
    height = max(5.0, Scene.thinnest_strip(dx, kernel=kernel, h_factor=h, cutoff_factor=cut))
    return Scene(dx=dx, strip_height=height, model="linear", t_end=10.0, **method)


def measured(scene, tmp_path) -> float:
    record = run(RunSpec("linkedlist-cpu", scene), fields_path=tmp_path / "f.npz")
    assert record.status == "ok", record.message
    return record.mse


def test_the_high_order_method_is_fourth_order_and_its_runs_equal_the_prediction(tmp_path):
    """Laguerre-Gauss, h 1.5 dx, cut at 4 h, corrected, RK4 at CFL 1, on the plane pulse at t = 10 s."""
    coarse, fine = measured(plane(0.4), tmp_path), measured(plane(0.2), tmp_path)
    assert math.log2(coarse / fine) >= 3.5
    assert fine < 5e-4
    for dx, error in ((0.4, coarse), (0.2, fine)):
        assert error == pytest.approx(predict(plane(dx)).predicted_error, rel=2e-3)
    # without the correction the same kernel keeps its lattice moment's phase-speed error: a floor that shows
    # from dx 0.1 (the prediction equals the runs)
    plain, corrected = (predict(plane(0.1, correction=c)).predicted_error for c in ("none", "gradient"))
    assert corrected < 1e-4 < plain


def test_the_sixth_order_kernel_is_sixth_order_where_the_step_allows_and_its_runs_equal_the_prediction(tmp_path):
    """Laguerre-Gauss of sixth order (h 1.5 dx, cut at 5 h, corrected), RK4 at CFL 0.5 on the plane pulse: order
    about 5 from dx 0.4 to 0.2 (RK4's fourth-order step bends it), a run at dx 0.4 equal to the prediction, and
    twenty times below the fourth-order kernel's error there."""
    six = {"kernel": "laguerre-gauss-6", "cutoff_factor": 5.0, "cfl": 0.5}
    coarse, fine = (predict(plane(dx, **six)).predicted_error for dx in (0.4, 0.2))
    assert math.log2(coarse / fine) >= 4.7
    assert measured(plane(0.4, **six), tmp_path) == pytest.approx(coarse, rel=2e-3)
    assert coarse < predict(plane(0.4, cfl=0.5)).predicted_error / 20


@pytest.mark.parametrize(
    "kernel,h_factor",
    [
        ("gaussian", 2.13),
        ("gaussian", 1.0),
        ("wendland-c2", 2.0),
        ("wendland-c4", 1.6),
        ("laguerre-gauss", 1.5),
        ("laguerre-gauss-6", 1.5),
    ],
)
def test_every_kernel_converges_at_fixed_h_over_dx_once_corrected(kernel, h_factor):
    """Predicted (exact for the linear model; the runs equal it, above): order >= 1.9 between dx 0.2 and 0.1
    with the correction; standard SPH's phase-speed error holds the Gaussian at h = dx near order 1."""

    def error(dx, correction):
        cut = kernel_named(kernel).order_cutoff or 3.0
        scene = plane(dx, kernel=kernel, h_factor=h_factor, correction=correction, cutoff_factor=cut)
        if kernel.startswith("wendland"):
            scene = scene.replace(cutoff_factor=Scene.default("cutoff_factor"))
        return predict(scene).predicted_error

    assert math.log2(error(0.2, "gradient") / error(0.1, "gradient")) >= 1.9
    if (kernel, h_factor) == ("gaussian", 1.0):
        assert math.log2(error(0.2, "none") / error(0.1, "none")) < 1.5


def test_rk4_is_a_step_program_the_prediction_and_stability_know():
    assert largest_stable_z("rk4") == pytest.approx(2 * math.sqrt(2), abs=2e-3)
    cfl = predicted_stable_cfl(plane(0.2))
    assert cfl == pytest.approx(predicted_stable_cfl(plane(0.2, correction="none")) * _slope(plane(0.2)), rel=1e-9)


def _slope(scene):
    """M_xx of a lattice particle: the corrected symbol is the standard one divided by it."""
    from solvers.corrections import correction_named

    return 1.0 / correction_named("gradient").lattice_factor(scene)


def test_a_particle_that_cannot_be_corrected_fails_the_run_at_its_step_naming_where():
    # h below the lattice: the nearest neighbours sit on the Laguerre-Gauss kernel's negative lobe (M < 0)
    scene = Scene(
        dx=1.0,
        model="linear",
        steps=3,
        kernel="laguerre-gauss",
        h_factor=0.5,
        cutoff_factor=2.1,
        correction="gradient",
        strip_height=Scene.thinnest_strip(1.0, 2.1, 0.5),
    )
    record = run(RunSpec("linkedlist-cpu", scene))
    assert record.status == "error" and record.failed_step == 1
    assert "--correction gradient: the particle at (" in record.message and "Traceback" not in record.message
    # a particle that drifted away from the others (moving particles: at the next search)
    s = prepared(open_square(model="lagrangian"))
    s.rates(True, True)
    s.arrays["sx"][0] -= 30.0  # 30 m beyond the lattice's left edge
    s.moved()
    s.snp()
    with pytest.raises(SingularMoments, match=r"the particle at \(.*\) m has a moment matrix"):
        s.rates(True, True)


def test_an_unknown_correction_or_integrator_is_one_line_naming_the_option(capsys):
    from .conftest import cli_main

    for option, value in (("--correction", "shepard2"), ("--integrator", "rk5")):
        code, out, err = cli_main("run", "--solver", "linkedlist-cpu", "--dx", "1", option, value, capsys=capsys)
        assert code == 2 and out == ""
        (line,) = err.strip().splitlines()
        assert option in line and value in line
    with pytest.raises(SceneError, match="correction must be one of none, gradient"):
        Scene(dx=1.0, correction="shepard2")


SIM_SCRIPT = r"""
import json, sys, tempfile, numpy as np
from pathlib import Path
from pcabench.execute.run import run
from pcabench.spec import RunSpec
from solvers import Scene
scene = Scene(dx=1.0, name="pulse-wall", model=sys.argv[1], steps=4, integrator="rk4", cfl=0.5,
              kernel="laguerre-gauss", h_factor=1.5, cutoff_factor=4.0, correction="gradient")
out = {}
with tempfile.TemporaryDirectory() as d:
    for solver in ("linkedlist-cpu", "linkedlist-gpu"):
        p = Path(d) / (solver + ".npz")
        rec = run(RunSpec(solver, scene, pair_loop="gather"), fields_path=p)
        out[solver] = {"status": rec.status, "message": rec.message[:800]}
        if rec.status == "ok":
            out[solver]["fields"] = {k: np.load(p)[k].tolist() for k in ("u", "v", "drho", "x")}
print(json.dumps(out))
"""


@pytest.mark.tier2
@pytest.mark.parametrize("model", ["lagrangian"])
def test_the_gpu_kernels_run_the_correction_and_rk4_in_the_simulator(model):
    out = in_simulator(SIM_SCRIPT, model)
    cpu, gpu = out["linkedlist-cpu"], out["linkedlist-gpu"]
    assert cpu["status"] == "ok" and gpu["status"] == "ok", (cpu["message"], gpu["message"])
    for name in ("u", "v", "drho", "x"):
        assert np.allclose(gpu["fields"][name], cpu["fields"][name], rtol=0, atol=1e-12), name


def test_the_weak_wall_keeps_the_energy_where_ghosts_do_not():
    """A body without ghosts (the body's sites carry no volume): the corrected operators stay each other's negative
    adjoint over the fluid, so the energy's rate is zero for any fields; ghosts filled from the fluid break it
    (and grow: docs/accuracy.md)."""
    from pcabench.conformance import SCENES

    rates = {}
    for method in ("weak", "lattice"):
        scene = Scene(**{**SCENES["cylinder"], "model": "linear", "steps": 1, "boundary_method": method, **HIGH})
        s = prepared(scene)
        a = s.arrays
        rng = np.random.default_rng(3)
        fluid = a["role"] == 0
        for name in ("u", "v", "drho"):
            a[name][:] = np.where(fluid, rng.standard_normal(a[name].shape), 0.0)
        s.rates(True, True)
        vol = np.where(fluid, scene.dx**2, 0.0)
        kinetic = vol * scene.rho0 * (a["u"] * a["ax"] + a["v"] * a["ay"])
        potential = vol * scene.c0**2 * a["drho"] * a["dd"] / scene.rho0
        rates[method] = abs(kinetic.sum() + potential.sum()) / np.abs(kinetic).sum()
    assert rates["weak"] < 1e-11
    assert rates["lattice"] > 1e-4
    with pytest.raises(SceneError, match="--boundary-method weak makes a wall only with a kernel correction"):
        Scene(**{**SCENES["cylinder"], "boundary_method": "weak"})


def test_what_a_correction_needs_is_asked_of_it_not_read_from_its_name():
    """The pair list keeps moment sums for moving particles where the correction sums moments (asked:
    ``Correction.moments``), whatever it is called: a plug-in correction that sums none keeps none, one named
    otherwise that does keeps them."""
    from solvers.corrections import CORRECTIONS, Correction
    from solvers.search.pairlist import MOMENT_SUMS, list_bytes

    class Plain(Correction):
        name = "plain-test"

    class Summing(Correction):
        name = "summing-test"
        moments = True

    base = Scene(0.1, model="lagrangian")
    item = np.dtype(base.precision).itemsize
    with CORRECTIONS.registered(Plain), CORRECTIONS.registered(Summing):
        assert list_bytes(base.replace(correction="plain-test")) == list_bytes(base)
        extra = list_bytes(base.replace(correction="summing-test")) - list_bytes(base)
    assert extra == base.n_particles * MOMENT_SUMS * item
    assert list_bytes(base.replace(correction="gradient")) - list_bytes(base) == extra
