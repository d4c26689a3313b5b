"""The cylinder scene (issue 42): bad input before any work, the boundary methods' ghosts (the wall's conditions,
their places, the scattered wave they make), probes read by MLS, a particle inside the body failing its run."""

from __future__ import annotations

import math

import numpy as np
import pytest

from pcabench.execute.run import run
from pcabench.spec import RunSpec
from solvers import Scene, SceneError, make_solver
from solvers.boundaries.bodies import GHOST, INERT, BodyEntered, boundary_method_names
from solvers.physics.integrators import step_program
from solvers.scenes.cylinder import probe_points

# a coarse copy of the workshop's problem: a wider pulse, so that dx = 0.05 resolves it (the scattered wave's
# reflection off the cylinder's front reaches (1.5, 0) at t = 3.5 s)
WIDE = dict(name="cylinder", dx=0.05, x_min=-5.0, x_max=5.0, y_min=-5.0, y_max=5.0, pulse_width=0.5, pulse_center=3.0)


@pytest.mark.parametrize(
    "changes, words",
    [
        (dict(cylinder_radius=0.0), "--cylinder-radius must be > 0"),
        (dict(cylinder_radius=-1.0), "--cylinder-radius must be > 0"),
        (dict(pulse_center=1.0), "--pulse-center: the pulse overlaps the cylinder"),
        (dict(pulse_center=5.7), "--pulse-center: the pulse must be inside the domain"),
        (dict(cylinder_radius=5.9), "--dx 0.05 with --cylinder-radius 5.9: the cutoff (0.32 m = 6.39 dx"),
        (dict(cylinder_radius=6.5), "--cylinder-radius 6.5: the cylinder (at the origin) must lie inside the domain"),
        (dict(dx=0.2), "--dx must be at most a quarter of the cylinder's radius"),
        (dict(open="x"), "--open: the cylinder scene is sound in the open plane"),
        (dict(probes=((0.6, 0.0),)), "--probe 0.6,0 is inside the body"),
        (dict(probes=((7.0, 0.0),)), "--probe 7,0 is outside the domain"),
        (dict(boundary_method="nope"), "--boundary-method"),
    ],
)
def test_bad_cylinder_input_is_one_line_naming_the_option(changes, words):
    with pytest.raises(SceneError) as err:
        Scene(**{"name": "cylinder", "dx": 0.05, "steps": 2, **changes})
    message = str(err.value)
    assert words in message and "\n" not in message, message


def test_a_body_parameter_on_a_scene_without_one_is_refused():
    for changes in (dict(cylinder_radius=0.5), dict(boundary_method="rings"), dict(sphere_radius=0.5)):
        with pytest.raises(SceneError, match="has no body"):
            Scene(dx=0.5, steps=2, **changes)
    with pytest.raises(SceneError, match="--sphere-radius: the cylinder scene has no body of that shape"):
        Scene(dx=0.05, name="cylinder", steps=2, sphere_radius=0.5)


def test_the_workshops_defaults_and_points():
    s = Scene(name="cylinder", dx=0.02, steps=1)
    assert (s.pulse_width, s.pulse_center, s.cylinder_radius, s.open) == (0.2, 4.0, 0.5, "xy")
    assert s.body == (0.0, 0.0, 0.5) and "body" in s.boundaries
    a, b, c = (probe_points(s)[k] for k in "ABC")
    assert a == pytest.approx((0.0, 5.0), abs=1e-12) and c == pytest.approx((-5.0, 0.0), abs=1e-12)
    assert b == pytest.approx((-5 / math.sqrt(2), 5 / math.sqrt(2)))
    assert Scene(dx=0.5).pulse_width == 3.0 and Scene(dx=0.5).cylinder_radius is None  # the paper's scene as was


def advanced(solver_name, scene, steps=None, **kw):
    solver = make_solver(solver_name, **kw)
    solver.input(scene)
    solver.init()
    for n in range(steps or scene.n_steps):
        for _stage, op in step_program(scene.integrator, solver, first=n == 0):
            op()
    return solver


def positions(solver):
    s, a = solver.scene, solver.arrays
    x = s.x_lo + (np.asarray(a["lx"], float) + 0.5) * s.dx + np.asarray(a["sx"], float)
    y = s.y_lo + (np.asarray(a["ly"], float) + 0.5) * s.dx + np.asarray(a["sy"], float)
    return x, y


@pytest.mark.tier2  # runs of seconds each: the second tier (README's command stays within 8 minutes)
@pytest.mark.parametrize("method", ["rings", "lattice"])
def test_the_ghosts_hold_the_walls_conditions_and_stay_put(method):
    """After lagrangian steps: every ghost holds the fluid's drho at its mirror point and the normal velocity
    reversed (u . n of the ghost = - that of the fluid at the mirror point); the body's particles have not moved;
    the ghosts cover a cutoff's depth of the wall (rings: on their rings)."""
    scene = Scene(**{**WIDE, "boundary_method": method, "model": "lagrangian", "mach": 0.2, "t_end": 2.5, "cfl": 1.0})
    solver = advanced("linkedlist-cpu", scene)
    a = solver.arrays
    x0, y0, r0 = scene.body
    x, y = positions(solver)
    role = np.asarray(a["role"])
    r = np.hypot(x - x0, y - y0)
    assert r[role == 0].min() >= r0 - 0.5 * scene.dx  # no fluid inside (past the ghosts' outer ring)
    ghosts, inert = role == GHOST, role == INERT
    assert ghosts.sum() > 0 and r[ghosts].max() < r0 and r[ghosts].min() < r0 - scene.cutoff + scene.dx
    if method == "rings":  # fitted: each ghost on a ring a - (i + 1/2) dx
        depth = (r0 - r[ghosts]) / scene.dx - 0.5
        assert np.allclose(depth, np.round(depth), atol=1e-9)
    assert not (ghosts & inert).any() and r[inert].max(initial=0.0) < r0
    body = solver.body
    solver.prepare_boundaries()  # the ghosts' values as the next sweep sees them
    n = body.normal
    sampled = {k: body.weights @ np.asarray(a[k])[body.fluid_idx] for k in ("drho", "u", "v")}
    assert np.abs(sampled["drho"]).max() > 1e-4 * scene.rho0 * scene.mach  # the pulse is at the wall by now
    assert np.allclose(np.asarray(a["drho"])[body.ghost_idx], sampled["drho"], rtol=0, atol=1e-15)
    un_fluid = sampled["u"] * n[:, 0] + sampled["v"] * n[:, 1]
    un_ghost = np.asarray(a["u"])[body.ghost_idx] * n[:, 0] + np.asarray(a["v"])[body.ghost_idx] * n[:, 1]
    ut_fluid = -sampled["u"] * n[:, 1] + sampled["v"] * n[:, 0]
    ut_ghost = -np.asarray(a["u"])[body.ghost_idx] * n[:, 1] + np.asarray(a["v"])[body.ghost_idx] * n[:, 0]
    np.testing.assert_allclose(un_ghost, -un_fluid, atol=1e-15)
    np.testing.assert_allclose(ut_ghost, ut_fluid, atol=1e-15)
    # the body's particles are where they were placed (by site id: the arrays are in cell order now)
    fresh = make_solver("linkedlist-cpu")
    fresh.input(scene)
    fresh.init()
    before, after = placed(fresh), placed(solver)
    assert before.keys() == after.keys()
    assert max(math.dist(before[k], after[k]) for k in before) < 1e-12


def placed(solver) -> dict:
    """{site id: (x, y)} of the body's particles."""
    a = solver.arrays
    ids = np.rint(np.asarray(a["ly"])).astype(int) * solver.scene.nx + np.rint(np.asarray(a["lx"])).astype(int)
    x, y = positions(solver)
    body = np.asarray(a["role"]) > 0
    return {int(i): (float(px), float(py)) for i, px, py in zip(ids[body], x[body], y[body])}


@pytest.mark.tier2  # runs of seconds each: the second tier (README's command stays within 8 minutes)
@pytest.mark.parametrize("method", ["rings", "lattice"])
def test_the_cylinder_sends_back_the_scattered_wave(method):
    """At (1.5, 0), between the pulse and the cylinder, the wave the cylinder's front sends back arrives at
    t = 3.5 s: the run follows the exact solution with the cylinder, not the free pulse (whose wave has passed)."""
    scene = Scene(**{**WIDE, "boundary_method": method, "model": "linear", "cfl": 1.0, "t_end": 4.5, "h_factor": 1.0})
    scene = scene.replace(probes=((1.5, 0.0),))  # h = dx: the pulse's own dispersion well below the reflection
    record = run(RunSpec("linkedlist-cpu", scene))
    assert record.status == "ok", record.message
    t, p = np.array(record.probes["t"]), np.array(record.probes["P1"])
    window = (t >= 3.0) & (t <= 4.5)
    ref = scene.kind.reference(scene, 4.5)
    exact = ref.drho(np.array([1.5]), np.array([0.0]), t[window])[:, 0]
    free = ref.free(np.array([1.5]), np.array([0.0]), t[window])[:, 0]
    scattered = np.sqrt(np.mean((exact - free) ** 2))
    assert scattered > 0.05 * np.abs(free).max()  # there is a reflection to see here
    err = np.sqrt(np.mean((p[window] - exact) ** 2))
    err_free = np.sqrt(np.mean((p[window] - free) ** 2))
    assert err < 0.2 * err_free, (err, err_free)  # the run has the reflection
    assert err < 0.2 * scattered, (err, scattered)  # and its size (measured: 11-15 % of it)


def test_every_solver_agrees_on_the_cylinder():
    from pcabench.conformance import SCENES

    scene = Scene(**SCENES["cylinder"], steps=8, model="lagrangian")
    ref = advanced("allpair-cpu", scene).output()
    for name, kw in (("linkedlist-cpu", {"pair_loop": "list"}), ("linkedlist-cpu", {"pair_loop": "gather"})):
        out = advanced(name, scene, **kw).output()
        np.testing.assert_allclose(out.drho, ref.drho, rtol=0, atol=1e-13 * np.abs(ref.drho).max())
    assert set(boundary_method_names()) >= {"rings", "lattice"}


def test_a_probe_reads_a_linear_field_exactly():
    scene = Scene(**{**WIDE, "model": "linear", "steps": 1})
    solver = make_solver("linkedlist-cpu")
    solver.input(scene)
    solver.init()
    x, y = positions(solver)
    solver.arrays["drho"][:] = 0.3 + 0.02 * x - 0.05 * y  # MLS of first order: exact for a linear field
    points = np.array([[2.0, 1.0], [-1.3, 2.7], [0.9, -0.1]])
    np.testing.assert_allclose(solver.sample(points), 0.3 + 0.02 * points[:, 0] - 0.05 * points[:, 1], atol=1e-12)


def test_a_particle_inside_the_body_fails_the_run_at_its_step(monkeypatch):
    from solvers.boundaries.body import RigidBody

    real = RigidBody.locate
    calls = {"n": 0}

    def locate(self, solver):
        calls["n"] += 1
        if solver.t > 2.5 * solver.scene.dt:  # in the third step
            raise BodyEntered("1 fluid particle(s) inside the cylinder (test)")
        return real(self, solver)

    monkeypatch.setattr(RigidBody, "locate", locate)
    scene = Scene(name="cylinder", dx=0.1, steps=6, model="lagrangian", cfl=0.5)
    record = run(RunSpec("linkedlist-cpu", scene))
    assert record.status == "error" and record.failed_step == 3
    assert record.message.startswith("BodyEntered: 1 fluid particle(s) inside the cylinder")
    assert "\n" not in record.message  # the message says it all: no traceback


def test_the_reference_field_equals_its_series():
    from solvers.reference.cylinder import CylinderPulse

    c = CylinderPulse(0.5, 0.2, 4.0, 0.0, 0.05, t_max=8.0, r_max=8.6)
    rng = np.random.default_rng(3)
    x, y = rng.uniform(-6, 6, 40), rng.uniform(-6, 6, 40)
    keep = np.hypot(x, y) > 0.5
    x, y = x[keep], y[keep]
    np.testing.assert_allclose(c.field(x, y, 7.0), c.drho(x, y, [7.0])[0], atol=1e-8 * 0.05)


def test_a_solver_that_skips_the_ghosts_fails_check_solver_on_the_cylinder():
    from pcabench.conformance import check_solver
    from solvers.linkedlist_cpu import LinkedListCPU

    class SkipsGhosts(LinkedListCPU):
        """Broken on purpose: it claims a body, yet never gives the ghosts the fluid's values."""

        name = "skips-ghosts"

        def prepare_boundaries(self):
            return False

    (result,) = check_solver(SkipsGhosts, quick=True, only=("agreement",))
    assert result.failed and "cylinder" in result.message and "differs" in result.message, result.line()
    assert "plane-pulse" not in result.message.replace("plane-pulse-3200", "")  # the other scenes agree


@pytest.mark.tier2  # runs of seconds each: the second tier (README's command stays within 8 minutes)
def test_the_sections_orders_target_and_figures_come_from_the_stored_runs(tmp_path):
    """Two dx per boundary method (stored rows with chosen errors): the orders are log(e1 / e2) / log 2, the
    target line names the best run at dx >= 0.02 and that it is not reached; both figures are drawn."""
    from types import SimpleNamespace

    from pcabench import store
    from pcabench.reports import frame
    from pcabench.studies.cylinder import section as S

    from .test_study import row

    path = tmp_path / "store" / "m.jsonl"
    t = [6.0 + 0.1 * i for i in range(41)]
    errors = {
        ("lattice", 0.04): (0.8, 0.02),
        ("lattice", 0.02): (0.2, 0.005),
        ("rings", 0.04): (0.8, 0.1),
        ("rings", 0.02): (0.4, 0.08),
    }
    for (method, dx), (probes, near) in errors.items():
        r = row(
            name="cylinder",
            dx=dx,
            t_end=10.0,
            model="linear",
            cfl=1.0,
            h_factor=1.0,
            boundary_method=method,
            steps=int(round(10 / dx)),
        )
        r.errors = {
            "probe_rms": probes,
            "probe_A": probes,
            "probe_B": probes,
            "probe_C": probes,
            "near_rms": near,
            "far_rms": 2 * probes,
        }
        r.probes = {"t": t, **{k: [1e-3 * math.sin(x) for x in t] for k in "ABC"}}
        store.append(r, path)
    data = S.rows(frame.load(path.parent))
    orders = {o["key"][2]: o for o in data["orders"]}
    assert orders["lattice"]["probes"] == pytest.approx(2.0) and orders["lattice"]["near"] == pytest.approx(2.0)
    assert orders["rings"]["probes"] == pytest.approx(1.0) and orders["rings"]["near"] == pytest.approx(math.log2(1.25))
    text = "\n".join(S.text(data, None))
    assert "has 0.2 (gaussian, h 1dx, 3h, lattice, dx = 0.02 m): not reached" in text
    ctx = SimpleNamespace(out=tmp_path, name="m")
    assert S.probes_figure(data, ctx).exists() and S.error_figure(data, ctx).exists()


def test_the_table_says_which_error_limits_each_run():
    """The wall's share of a run's probes' error is what the bulk's (the prediction with the wall exact) leaves,
    in quadrature; the larger share limits the run (the sixth-order kernel with cut cells at dx 0.02: the wall;
    the fourth-order one: the bulk; a run at or below its prediction: the bulk, its wall's share 0)."""
    from pcabench.studies.cylinder import section as S

    sixth, fourth = {"probes": 0.00139, "predicted": 0.00097}, {"probes": 0.00661, "predicted": 0.0066}
    assert S.wall_share(sixth) == pytest.approx(math.sqrt(0.00139**2 - 0.00097**2)) and S.limited_by(sixth) == "wall"
    assert S.wall_share(fourth) < 0.1 * fourth["predicted"] and S.limited_by(fourth) == "bulk"
    below = {"probes": 0.005, "predicted": 0.006}
    assert S.wall_share(below) == 0.0 and S.limited_by(below) == "bulk"
    assert S.wall_share({"probes": 0.1, "predicted": None}) is None
    assert S.limited_by({"probes": None, "predicted": 1}) == "-"


@pytest.mark.parametrize(
    "words, says",
    [
        (["study", "--front", "--scene", "cylinder"], "runs against dx are `pcabench study --cylinder`"),
        (
            ["run", "--solver", "linkedlist-cpu", "--scene", "cylinder", "--dx", "0.05", "--probe", "0.6,0"],
            "--probe 0.6,0 is inside the body",
        ),
    ],
)
def test_what_the_cylinder_cannot_do_is_one_line(words, says, tmp_path):
    import os
    import subprocess
    import sys

    env = {**os.environ, "PCABENCH_HOME": str(tmp_path)}
    proc = subprocess.run([sys.executable, "-m", "pcabench.cli", *words], capture_output=True, text=True, env=env)
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode != 0 and len(lines) == 1 and says in lines[0], proc.stderr


def test_the_near_bands_grid_scale_part_parts_noise_from_sound():
    """``grid_scale_part`` keeps a checkerboard (the lattice's own scale) but exp(-pi^2) of it and leaves of a wave
    of 40 dx a part of 1 - exp(-(k dx)^2 / 2): the near band's `near_grid_rms` counts noise, not sound."""
    from solvers.scenes.cylinder import grid_scale_part

    dx = 0.05
    iy, ix = np.mgrid[0:120, 0:100]
    x, y = (ix * dx).ravel() - 2.5, (iy * dx).ravel() - 3.0
    checker = ((-1.0) ** (ix + iy)).ravel()
    assert np.allclose(grid_scale_part(x, y, checker, dx), (1 - math.exp(-(math.pi**2))) * checker, atol=1e-9)
    k = 2 * np.pi / (40 * dx)
    wave = np.cos(k * (x + 0.3 * y))
    inner = (np.abs(x) < 1.5) & (np.abs(y) < 2.0)  # away from the FFT's wrap at the box's edges
    part = grid_scale_part(x, y, wave, dx)[inner]
    kk = (k * dx) ** 2 * (1 + 0.09)
    assert np.sqrt(np.mean(part**2)) == pytest.approx((1 - np.exp(-kk / 2)) / np.sqrt(2), rel=0.05)
