"""Scenes: what to simulate and what it is scored against, one file per scene kind (see base.py)."""

from __future__ import annotations

from solvers.scenes.base import BOUNDARY_KINDS, SceneKind
from solvers.scenes.registry import DEFAULT_SCENE, ENTRY_POINT_GROUP, SCENES, scene_kind, scene_names, scenes

__all__ = [
    "BOUNDARY_KINDS",
    "SceneKind",
    "DEFAULT_SCENE",
    "ENTRY_POINT_GROUP",
    "SCENES",
    "scene_kind",
    "scene_names",
    "scenes",
]
