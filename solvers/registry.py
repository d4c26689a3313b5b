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

from solvers.interface import Solver
from solvers.plugins import NAME, PluginWarning, Registry, declares_a_name
from solvers.scene import SceneError

ENTRY_POINT_GROUP = "pcabench.solvers"
SOLVER_NAME = NAME  # the record's solver field (pcabench/store/schema.py): the one name rule
DEFAULT_SOLVER = "linkedlist-cpu"  # what a study runs when no solver is named: the paper's cell list, on the CPU
GPU_SOLVER = "linkedlist-gpu"  # the GPU runs' solver (the paper's GPU sweep, pcabench gpu-check): its cell list

SOLVERS = Registry(
    "solver",
    __package__,
    Solver,
    group=ENTRY_POINT_GROUP,
    order=lambda cls: cls.__module__,  # by module, as found
    option="solver",
    error=SceneError,
    declares=declares_a_name,  # a module is imported only if its source names a class: no GPU library touched
)

__all__ = ["PluginWarning", "SOLVERS"]


def registry() -> dict[str, type[Solver]]:
    """{name: solver class}: the built-in solvers first, then those of installed plug-ins."""
    return SOLVERS.all()


def solver_names() -> tuple[str, ...]:
    """Every solver's name, built-in first."""
    return SOLVERS.names()


def solver_class(name: str) -> type[Solver]:
    """The class of solver ``name``; SceneError naming ``solver`` and the choices otherwise."""
    return SOLVERS.get(name)


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
