"""Particles that never leave their lattice sites: the separations without the displacements
(solvers/physics/pairs.py and pairs3d.py, ``separation_rule``) give the same bits as with them, in 2D and in 3D
(where every particle is searched on the sites' grid, solvers/search/sites.py); a run takes that variant only
where every displacement is zero."""

from __future__ import annotations

import numpy as np
import pytest

from solvers import Scene
from solvers.physics.integrators import advance_steps
from solvers.registry import make_solver

CASES = {  # (solver, options, scene): a 2D wall's mirrors, the 2D all-pair search, the 3D stencil's seams
    "2D wall, gather": ("linkedlist-cpu", {"pair_loop": "gather"}, dict(dx=0.5, name="pulse-wall", steps=5)),
    "2D all-pair": ("allpair-cpu", {}, dict(dx=0.5, name="acoustic-pulse", steps=4)),
    "3D, corrected": (
        "linkedlist-cpu",
        {},
        dict(
            dx=0.5,
            name="acoustic-pulse-3d",
            **{f"{a}_{e}": s * 4.0 for a in "xyz" for e, s in (("min", -1), ("max", 1))},
            pulse_width=1.5,
            pulse_center=1.0,
            kernel="wendland-c2",
            h_factor=1.3,
            correction="gradient",
            steps=4,
        ),
    ),
}


def fields(solver: str, options: dict, scene: Scene, displaced: bool | None):
    run = make_solver(solver, **options)
    run.input(scene)
    run.init()
    decided = run.displaced
    if displaced is not None:
        run.displaced = displaced  # the general rule forced on particles that stay on their sites
        run.nnps = run.search_for_scene()  # and its search
    advance_steps(run, scene.integrator, scene.steps)
    f = run.output()
    return decided, {c: getattr(f, c) for c in ("x", "y", "z", "u", "v", "w", "drho") if getattr(f, c) is not None}


@pytest.mark.parametrize("case", CASES)
def test_fixed_particles_give_the_same_bits_without_their_displacements(case):
    solver, options, scene = CASES[case]
    scene = Scene(**{"model": "linear", **scene})
    decided, fixed = fields(solver, options, scene, None)
    assert decided is False  # the linear model on the lattice: every displacement zero
    _, general = fields(solver, options, scene, True)
    assert np.abs(fixed["drho"]).max() > 1e-6  # the pulse is there
    for c, values in fixed.items():  # 3D: both on the sites' grid (solvers/search/sites.py), in the same order
        assert np.array_equal(values, general[c]), c


def test_moving_particles_and_a_bodys_shifted_sites_keep_the_displacements():
    """The Lagrangian model moves particles; the 2D ring body (the cylinder's default) places its particles off
    their sites."""
    moving = make_solver("linkedlist-cpu")
    moving.input(Scene(dx=0.5, name="acoustic-pulse", model="lagrangian"))
    moving.init()
    body = make_solver("linkedlist-cpu")
    body.input(Scene(dx=0.1, name="cylinder", model="linear"))
    body.init()
    assert moving.displaced and body.displaced
    assert np.any(body.arrays["sx"])  # why: the body's sites are off the lattice
