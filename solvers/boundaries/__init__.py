"""A scene's boundaries as one family of models, one file each (see base.py): rigid walls at x edges (walls.py),
the absorbing layer beyond open edges (layer.py) and a rigid body inside the domain (body.py; a 3D scene's:
body3d.py). How each is made is a plug-in of its own where there are choices: the layer's absorber
(solvers/boundaries/absorbers/), the body's boundary method (solvers/boundaries/bodies/)."""

from __future__ import annotations

from solvers.boundaries.base import Boundary
from solvers.boundaries.body import RigidBody
from solvers.boundaries.body3d import RigidBody3D
from solvers.boundaries.layer import OpenLayer
from solvers.boundaries.walls import Walls, across

MODELS = (Walls, OpenLayer, RigidBody, RigidBody3D)  # in the order a solver calls them


def boundary_models(scene) -> tuple:
    """The boundary models of ``scene`` (those that apply to it), each built for it, in :data:`MODELS`' order."""
    return tuple(model(scene) for model in MODELS if model.applies(scene))


__all__ = ["Boundary", "MODELS", "OpenLayer", "RigidBody", "RigidBody3D", "Walls", "across", "boundary_models"]
