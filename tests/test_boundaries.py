"""The boundaries as one family (solvers/boundaries/): each scene gets the models of its boundaries, and a model
added to the family acts on every solver at its points of a step."""

from __future__ import annotations

import math

import numpy as np
import pytest

import solvers.boundaries as boundaries
from pcabench.conformance import run_steps
from solvers import Scene, scenes
from solvers.boundaries import OpenLayer, RigidBody, RigidBody3D, Walls, boundary_models
from solvers.registry import make_solver


def kind_cases():
    for name, kind in scenes().items():
        for case in (kind.smallest, kind.smallest_open):
            if case:
                yield pytest.param(Scene(name=name, **case), id=f"{name}{'-open' if case.get('open') else ''}")


@pytest.mark.parametrize("scene", list(kind_cases()))
def test_each_scene_kind_gets_the_models_of_its_boundaries(scene):
    models = {type(m) for m in boundary_models(scene)}
    assert (Walls in models) == ("wall-x" in scene.boundaries) == bool(scene.walls)
    assert bool(models & {RigidBody, RigidBody3D}) == ("body" in scene.boundaries) == (scene.body is not None)
    assert (OpenLayer in models) == bool(scene.open) == (scene.n_layer > 0)


class UniformDamping(boundaries.Boundary):
    """A toy model: every particle's velocity and density damped at rate SIGMA (1/s), as a layer damps its own."""

    name = "uniform damping"
    SIGMA = 1.0

    @classmethod
    def applies(cls, scene) -> bool:
        return True

    def damp(self, solver, f, fields):
        factor = solver.dtype.type(math.exp(-0.5 * self.SIGMA * f * self.scene.dt))
        for name in ("u", "v") if fields == "velocity" else ("drho",):
            solver.arrays[name] *= factor


@pytest.mark.parametrize("solver", ["allpair-cpu", "linkedlist-cpu"])
def test_a_model_added_to_the_family_acts_on_every_solver_at_its_points(solver, monkeypatch):
    """A uniform damping commutes with the linear equations: the damped run is the undamped one times
    exp(-sigma t), to the splitting's error (sigma dt = 0.1: a few 1e-5 of the amplitude), on each solver, whose
    hooks damp the velocity around every kick and the density around every advance (the velocity alone: off by
    0.77 of the amplitude)."""
    scene = Scene(dx=0.5, steps=20, model="linear", strip_height=Scene.thinnest_strip(0.5))

    def fields():
        s = make_solver(solver)
        run_steps(s, scene)
        f = s.output()
        return np.concatenate([f.u, f.v, f.drho])

    free = fields()
    monkeypatch.setattr(boundaries, "MODELS", boundaries.MODELS + (UniformDamping,))
    damped = fields()
    decay = math.exp(-UniformDamping.SIGMA * scene.t_final)
    assert decay < 0.2  # the damping is no round-off
    np.testing.assert_allclose(damped, decay * free, rtol=0, atol=1e-3 * np.abs(free).max())
