"""Rigid bodies' curved walls: the boundary methods, one file each (see base.py), found by registry.py."""

from __future__ import annotations

from solvers.boundaries.bodies.base import GHOST, INERT, BodyEntered, BoundaryMethod
from solvers.boundaries.bodies.registry import (
    BOUNDARY_METHODS,
    CORRECTED_BOUNDARY_METHOD,
    DEFAULT_BOUNDARY_METHOD,
    ENTRY_POINT_GROUP,
    boundary_method_named,
    boundary_method_names,
)

__all__ = [
    "GHOST",
    "INERT",
    "BodyEntered",
    "BoundaryMethod",
    "BOUNDARY_METHODS",
    "CORRECTED_BOUNDARY_METHOD",
    "DEFAULT_BOUNDARY_METHOD",
    "ENTRY_POINT_GROUP",
    "boundary_method_named",
    "boundary_method_names",
]
