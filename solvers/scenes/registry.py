"""The scene registry: every scene pcabench offers, found rather than listed (like the solvers').

A scene kind is a :class:`~solvers.scenes.base.SceneKind` subclass with a
``name``: the modules of this package, then the entry-point group
``pcabench.scenes`` of installed packages (``my-scene = my_pkg.mod:MyScene``).
A plug-in that does not load, is not a SceneKind or repeats a taken name is
left out with one :class:`~solvers.registry.PluginWarning`.
"""

from __future__ import annotations

import importlib
import inspect
import pkgutil
import warnings
from functools import lru_cache
from importlib import metadata
from pathlib import Path

from .base import SceneKind

ENTRY_POINT_GROUP = "pcabench.scenes"
DEFAULT_SCENE = "plane-pulse"  # the paper's scene: what every run is unless --scene says otherwise


class ScenePluginWarning(UserWarning):
    """A plug-in scene left out."""


def _builtin() -> list[type[SceneKind]]:
    found = []
    for info in sorted(pkgutil.iter_modules([str(Path(__file__).parent)]), key=lambda m: m.name):
        if info.name in ("base", "registry"):
            continue
        module = importlib.import_module(f"{__package__}.{info.name}")
        found += [
            cls
            for _, cls in inspect.getmembers(module, inspect.isclass)
            if issubclass(cls, SceneKind) and cls.__module__ == module.__name__ and cls.__dict__.get("name")
        ]
    return found


def _plugins(taken: set) -> list[type[SceneKind]]:
    found = []
    for entry in metadata.entry_points(group=ENTRY_POINT_GROUP):
        where = f"entry point {entry.name!r} of group {ENTRY_POINT_GROUP} ({entry.value})"
        try:
            cls = entry.load()
        except Exception as exc:  # noqa: BLE001 - a broken plug-in must not take pcabench down
            warnings.warn(
                f"{where} left out: it does not load ({type(exc).__name__}: {exc})", ScenePluginWarning, stacklevel=2
            )
            continue
        if not (inspect.isclass(cls) and issubclass(cls, SceneKind)) or not cls.__dict__.get("name"):
            warnings.warn(
                f"{where} left out: not a SceneKind subclass with a name of its own", ScenePluginWarning, stacklevel=2
            )
        elif cls.name in taken:
            warnings.warn(f"{where} left out: the scene name {cls.name!r} is taken", ScenePluginWarning, stacklevel=2)
        else:
            found.append(cls)
            taken.add(cls.name)
    return found


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
