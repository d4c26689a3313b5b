"""Finding the classes of a registry (the scenes', the kernels'): the built-in ones, one per module of their
package, and third-party ones through an entry-point group, a broken plug-in left out with one warning."""

from __future__ import annotations

import importlib
import inspect
import pkgutil
import warnings
from importlib import metadata
from pathlib import Path
from typing import Callable


def builtin_classes(package: str, folder: Path, base: type) -> list[type]:
    """The subclasses of ``base`` with a ``name`` of their own defined in the modules of ``package`` (in
    ``folder``), but for its ``base`` and ``registry`` modules."""
    found = []
    for info in sorted(pkgutil.iter_modules([str(folder)]), key=lambda m: m.name):
        if info.name in ("base", "registry"):
            continue
        module = importlib.import_module(f"{package}.{info.name}")
        found += [
            cls
            for _, cls in inspect.getmembers(module, inspect.isclass)
            if issubclass(cls, base) and cls.__module__ == module.__name__ and cls.__dict__.get("name")
        ]
    return found


def entry_point_classes(
    group: str, problem: Callable[[object, set], str | None], taken: set, warning: type[Warning]
) -> list[type]:
    """The classes of entry-point group ``group`` that ``problem(cls, taken)`` finds nothing wrong with (each
    other one left out with a ``warning`` saying why); ``taken`` gains the names of those kept."""
    found = []
    for entry in metadata.entry_points(group=group):
        where = f"entry point {entry.name!r} of group {group} ({entry.value})"
        try:
            cls = entry.load()
        except Exception as exc:  # noqa: BLE001 - a broken plug-in must not take pcabench down
            warnings.warn(f"{where} left out: it does not load ({type(exc).__name__}: {exc})", warning, stacklevel=3)
            continue
        why = problem(cls, taken)
        if why:
            warnings.warn(f"{where} left out: {why}", warning, stacklevel=3)
        else:
            found.append(cls)
            taken.add(cls.name)
    return found
