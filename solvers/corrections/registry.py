"""The correction registry: every kernel correction pcabench offers (solvers/corrections/, one file each;
plug-ins through the entry-point group ``pcabench.corrections``), by the one :class:`~solvers.plugins.Registry`
mechanism."""

from __future__ import annotations

from solvers.corrections.base import Correction
from solvers.plugins import Registry

ENTRY_POINT_GROUP = "pcabench.corrections"
DEFAULT_CORRECTION = "none"  # standard SPH: what every run uses unless --correction says otherwise

CORRECTIONS = Registry(
    "correction",
    "solvers.corrections",
    Correction,
    group=ENTRY_POINT_GROUP,
    default=DEFAULT_CORRECTION,
    make=lambda cls: cls(),
    option="--correction",
)


def correction_names() -> tuple[str, ...]:
    return CORRECTIONS.names()


def correction_named(name: str) -> Correction:
    """The correction ``name``; ValueError naming --correction and the choices otherwise."""
    return CORRECTIONS.get(name)
