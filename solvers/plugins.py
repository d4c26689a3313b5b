"""Finding the classes of a registry (the scenes', the kernels'): the built-in ones, one per module of their
package, and third-party ones through an entry-point group, a broken plug-in left out with one warning."""

from __future__ import annotations

import importlib
import inspect
import pkgutil
import re
import warnings
from importlib import metadata
from pathlib import Path
from typing import Callable

# The one name rule of every registry (solvers, kernels, scenes): a name is stored in records, becomes part of
# file names and command lines, and is printed in Markdown tables, so it holds nothing a shell, a path or a
# table would read as syntax.
NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9._-]{0,31}", re.ASCII)
NAME_RULE = "letters, digits, '.', '_', '-', starting with a letter or digit, at most 32"


def name_problem(name, what: str) -> str | None:
    """Why ``name`` cannot name a ``what`` (a solver, a kernel, a scene) under :data:`NAME` (None: it can)."""
    if not isinstance(name, str) or not NAME.fullmatch(name):
        return f"the {what} name {name!r:.80} is not a plain name ({NAME_RULE}): it names stored records"
    return None


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
        except BaseException as exc:  # noqa: BLE001 - a broken plug-in (even one calling sys.exit) is left out
            if isinstance(exc, KeyboardInterrupt):
                raise
            warnings.warn(f"{where} left out: it does not load ({type(exc).__name__}: {exc})", warning, stacklevel=3)
            continue
        why = problem(cls, taken)
        if why:
            warnings.warn(f"{where} left out: {why}", warning, stacklevel=3)
        else:
            found.append(cls)
            taken.add(cls.name)
    return found
