"""The boundary-method registry: every way pcabench models a body's curved wall (solvers/boundaries/bodies/, one file
each; plug-ins through the entry-point group ``pcabench.boundary_methods``), by the one
:class:`~solvers.plugins.Registry` mechanism."""

from __future__ import annotations

from solvers.boundaries.bodies.base import BoundaryMethod
from solvers.plugins import Registry

ENTRY_POINT_GROUP = "pcabench.boundary_methods"
DEFAULT_BOUNDARY_METHOD = "rings"  # standard SPH's body
# A corrected method's body (--correction other than none): the one whose wall holds with it (ghosts blow up), with
# its cut cells (solvers/boundaries/bodies/cut.py: second order; the staircase, ``weak``, was the default until
# 2026-12-07: a stored row says which it ran, ``boundary_method_used``; pcabench.spec.stored_parameters reads older
# ones)
CORRECTED_BOUNDARY_METHOD = "cut"

BOUNDARY_METHODS = Registry(
    "boundary method",
    "solvers.boundaries.bodies",
    BoundaryMethod,
    group=ENTRY_POINT_GROUP,
    default=DEFAULT_BOUNDARY_METHOD,
    make=lambda cls: cls(),
    option="--boundary-method",
)


def boundary_method_names() -> tuple[str, ...]:
    return BOUNDARY_METHODS.names()


def boundary_method_named(name: str) -> BoundaryMethod:
    """The boundary method ``name``; ValueError naming --boundary-method and the choices otherwise."""
    return BOUNDARY_METHODS.get(name)
