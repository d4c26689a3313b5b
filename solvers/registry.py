"""The solver registry: every solver pcabench offers, found rather than listed.

A solver is a :class:`~solvers.interface.Solver` subclass with a ``name``.
Two places are searched, once per process:

* the modules of this package (a new built-in solver is one new file in
  ``solvers/``); a module is imported only if its source defines a class with
  a ``name = ...`` line, so that ``import solvers`` stays cheap and touches
  no GPU library;
* the entry-point group ``pcabench.solvers`` of installed packages, each
  entry naming a Solver subclass (``my-solver = my_package.module:MySolver``):
  once installed, the solver appears in ``pcabench run --solver``, studies,
  reports, asv and pytest-benchmark with no edit to pcabench.

Names are unique: an entry point that repeats a taken name, does not load, or
does not name a Solver subclass with a ``name`` of its own is left out with one
:class:`PluginWarning`.
"""

from __future__ import annotations

import ast
import importlib
import inspect
import pkgutil
import warnings
from functools import lru_cache
from importlib import metadata
from pathlib import Path

from .interface import Solver
from .plugins import NAME, name_problem
from .scene import SceneError

ENTRY_POINT_GROUP = "pcabench.solvers"
SOLVER_NAME = NAME  # the record's solver field (pcabench/schema.py): the one name rule
DEFAULT_SOLVER = "linkedlist-cpu"  # what a study runs when no solver is named: the paper's cell list, on the CPU


def _declares_a_solver(path: Path) -> bool:
    """Whether the module at ``path`` defines a class with a ``name`` attribute (without importing it)."""
    try:
        tree = ast.parse(path.read_text(encoding="utf-8"))
    except (OSError, SyntaxError, UnicodeDecodeError):
        return False
    return any(
        isinstance(node, ast.ClassDef)
        and any(
            isinstance(stmt, (ast.Assign, ast.AnnAssign))
            and any(
                getattr(t, "id", None) == "name"
                for t in (stmt.targets if isinstance(stmt, ast.Assign) else [stmt.target])
            )
            for stmt in node.body
        )
        for node in tree.body
    )


def _solver_classes(module) -> list[type[Solver]]:
    """The named, concrete Solver subclasses defined in ``module``."""
    return [
        cls
        for _, cls in inspect.getmembers(module, inspect.isclass)
        if issubclass(cls, Solver)
        and cls.__module__ == module.__name__
        and "name" in cls.__dict__
        and cls.name
        and not inspect.isabstract(cls)
    ]


def _builtin() -> list[type[Solver]]:
    package = Path(__file__).parent
    found = []
    for info in sorted(pkgutil.iter_modules([str(package)]), key=lambda m: m.name):
        if info.name != "registry" and _declares_a_solver(package / f"{info.name}.py"):
            found += _solver_classes(importlib.import_module(f"{__package__}.{info.name}"))
    return found


class PluginWarning(UserWarning):
    """A plug-in solver left out, or registered under another name than its entry point's."""


def _plugins(taken: set) -> list[type[Solver]]:
    found = []
    for entry in metadata.entry_points(group=ENTRY_POINT_GROUP):
        where = f"entry point {entry.name!r} of group {ENTRY_POINT_GROUP} ({entry.value})"

        def warn(what: str, where: str = where) -> None:
            warnings.warn(f"{where}{what}", PluginWarning, stacklevel=3)

        try:
            cls = entry.load()
        except BaseException as exc:  # noqa: BLE001 - a broken plug-in (even one calling sys.exit) is left out
            if isinstance(exc, KeyboardInterrupt):
                raise
            warn(f" left out: it does not load ({type(exc).__name__}: {exc})")
            continue
        if not (inspect.isclass(cls) and issubclass(cls, Solver)) or inspect.isabstract(cls):
            warn(" left out: not a concrete Solver subclass")
        elif not cls.__dict__.get("name"):  # a subclass of a built-in inherits its name: not its own
            warn(
                " left out: the class sets no name of its own"
                + (f" (it would inherit {cls.name!r})" if cls.name else "")
            )
        elif name_problem(cls.name, "solver"):
            warn(f" left out: {name_problem(cls.name, 'solver')}")
        elif cls.name in taken:
            warn(f" left out: the solver name {cls.name!r} is taken")
        else:
            if entry.name != cls.name:
                warn(f": registered as {cls.name!r}, its class's name")
            found.append(cls)
            taken.add(cls.name)
    return found


@lru_cache(maxsize=None)
def registry() -> dict[str, type[Solver]]:
    """{name: solver class}: the built-in solvers first, then those of installed plug-ins."""
    builtin = {cls.name: cls for cls in _builtin()}
    return {**builtin, **{cls.name: cls for cls in _plugins(set(builtin))}}


def solver_names() -> tuple[str, ...]:
    """Every solver's name, built-in first."""
    return tuple(registry())


def solver_class(name: str) -> type[Solver]:
    """The class of solver ``name``; SceneError naming ``solver`` and the choices otherwise."""
    try:
        return registry()[name]
    except (KeyError, TypeError):
        raise SceneError(f"solver must be one of {', '.join(registry())} (got {name!r})") from None


def check_pair_loop(name: str, requested: str) -> None:
    """SceneError unless solver ``name`` offers ``requested`` (or it is ``auto``)."""
    offered = solver_class(name).pair_loops
    if requested != "auto" and requested not in offered:
        has = (
            f"one pair loop, {offered[0]}: give auto"
            if len(offered) == 1
            else f"the pair loops {', '.join(offered)}: give one of them or auto"
        )
        raise SceneError(f"--pair-loop: {name} has {has} (got {requested!r})")


def resolve_pair_loop(name: str, scene, requested: str = "auto") -> str:
    """The pair loop solver ``name`` uses for ``scene``: ``requested``, or its own choice for ``auto``."""
    check_pair_loop(name, requested)
    return solver_class(name).choose_pair_loop(scene, requested)


def make_solver(name: str, threads: int = 1, pair_loop: str = "auto") -> Solver:
    """A new solver ``name`` on ``threads`` CPU threads with ``pair_loop``; SolverUnavailable if it cannot
    run here."""
    check_pair_loop(name, pair_loop)
    cls = solver_class(name)
    if threads not in (None, 1) and not cls.threaded:
        raise SceneError(f"threads: {name} is serial, {cls.serial_why} (got {threads})")
    cls.available()
    return cls(threads=1 if threads is None else threads, pair_loop=pair_loop)
