"""Absorbing layers for open edges, one file each (see base.py), found by registry.py."""

from __future__ import annotations

from solvers.boundaries.absorbers.base import Absorber
from solvers.boundaries.absorbers.registry import (
    ABSORBERS,
    DEFAULT_ABSORBER,
    ENTRY_POINT_GROUP,
    absorber_named,
    absorber_names,
)

__all__ = ["Absorber", "ABSORBERS", "DEFAULT_ABSORBER", "ENTRY_POINT_GROUP", "absorber_named", "absorber_names"]
