"""The scene registry: every scene pcabench offers, found rather than listed (like the solvers').

A scene kind is a :class:`~solvers.scenes.base.SceneKind` subclass with a
``name``: the modules of this package, then the entry-point group
``pcabench.scenes`` of installed packages (``my-scene = my_pkg.mod:MyScene``).
A plug-in that does not load, is not a SceneKind or repeats a taken name is
left out with one :class:`~solvers.plugins.PluginWarning`: the one
:class:`~solvers.plugins.Registry` mechanism (:data:`SCENES`).
"""

from __future__ import annotations

from solvers.plugins import PluginWarning, Registry
from solvers.scenes.base import SceneKind

ENTRY_POINT_GROUP = "pcabench.scenes"
DEFAULT_SCENE = "plane-pulse"  # the paper's scene: what every run is unless --scene says otherwise

ScenePluginWarning = PluginWarning  # the one warning of every registry

SCENES = Registry(
    "scene",
    __package__,
    SceneKind,
    group=ENTRY_POINT_GROUP,
    default=DEFAULT_SCENE,
    make=lambda cls: cls(),
    option="--scene",
)


def scenes() -> dict[str, SceneKind]:
    """{name: scene kind (an instance)}: the paper's scene first, the other built-ins, then plug-ins'."""
    return SCENES.all()


def scene_names() -> tuple[str, ...]:
    return SCENES.names()


def scene_kind(name: str) -> SceneKind:
    """The scene kind ``name``; ValueError naming --scene and the choices otherwise."""
    return SCENES.get(name)
