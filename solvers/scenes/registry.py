"""The scene registry: every scene pcabench offers, found rather than listed (like the solvers').

A scene kind is a :class:`~solvers.scenes.base.SceneKind` subclass with a
``name``: the modules of this package, then the entry-point group
``pcabench.scenes`` of installed packages (``my-scene = my_pkg.mod:MyScene``).
A plug-in that does not load, is not a SceneKind or repeats a taken name is
left out with one :class:`~solvers.registry.PluginWarning`.
"""

from __future__ import annotations

import inspect
from functools import lru_cache
from pathlib import Path

from ..plugins import builtin_classes, entry_point_classes, name_problem
from .base import SceneKind

ENTRY_POINT_GROUP = "pcabench.scenes"
DEFAULT_SCENE = "plane-pulse"  # the paper's scene: what every run is unless --scene says otherwise


class ScenePluginWarning(UserWarning):
    """A plug-in scene left out."""


def _builtin() -> list[type[SceneKind]]:
    return builtin_classes(__package__, Path(__file__).parent, SceneKind)


def _problem(cls, taken) -> str | None:
    """Why ``cls`` cannot be a scene under its name (None: it can)."""
    if not (inspect.isclass(cls) and issubclass(cls, SceneKind)) or not cls.__dict__.get("name"):
        return "not a SceneKind subclass with a name of its own"
    if name_problem(cls.name, "scene"):
        return name_problem(cls.name, "scene")
    if cls.name in taken:
        return f"the scene name {cls.name!r} is taken"
    return None


def _plugins(taken: set) -> list[type[SceneKind]]:
    return entry_point_classes(ENTRY_POINT_GROUP, _problem, taken, ScenePluginWarning)


@lru_cache(maxsize=None)
def scenes() -> dict[str, SceneKind]:
    """{name: scene kind (an instance)}: the paper's scene first, the other built-ins, then plug-ins'."""
    builtin = sorted(_builtin(), key=lambda cls: (cls.name != DEFAULT_SCENE, cls.name))
    kinds = {cls.name: cls() for cls in builtin}
    kinds.update({cls.name: cls() for cls in _plugins(set(kinds))})
    return kinds


def scene_names() -> tuple[str, ...]:
    return tuple(scenes())


def scene_kind(name: str) -> SceneKind:
    """The scene kind ``name``; ValueError naming --scene and the choices otherwise."""
    try:
        return scenes()[name]
    except (KeyError, TypeError):
        raise ValueError(f"--scene must be one of {', '.join(scenes())} (got {name!r})") from None
