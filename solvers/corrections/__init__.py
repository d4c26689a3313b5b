"""Kernel corrections, one file each (see base.py), found by registry.py."""

from __future__ import annotations

from solvers.corrections.base import Correction, SingularMoments
from solvers.corrections.registry import (
    CORRECTIONS,
    DEFAULT_CORRECTION,
    ENTRY_POINT_GROUP,
    correction_named,
    correction_names,
)

__all__ = [
    "Correction",
    "SingularMoments",
    "CORRECTIONS",
    "DEFAULT_CORRECTION",
    "ENTRY_POINT_GROUP",
    "correction_named",
    "correction_names",
]
