"""The absorber registry: every absorbing layer pcabench offers (solvers/boundaries/absorbers/, one file each; plug-ins
through the entry-point group ``pcabench.absorbers``), by the one :class:`~solvers.plugins.Registry` mechanism."""

from __future__ import annotations

from solvers.boundaries.absorbers.base import Absorber
from solvers.plugins import Registry

ENTRY_POINT_GROUP = "pcabench.absorbers"
DEFAULT_ABSORBER = "sponge"

ABSORBERS = Registry(
    "absorber",
    "solvers.boundaries.absorbers",
    Absorber,
    group=ENTRY_POINT_GROUP,
    default=DEFAULT_ABSORBER,
    make=lambda cls: cls(),
    option="--absorber",
)


def absorber_names() -> tuple[str, ...]:
    return ABSORBERS.names()


def absorber_named(name: str) -> Absorber:
    """The absorber ``name``; ValueError naming --absorber and the choices otherwise."""
    return ABSORBERS.get(name)
