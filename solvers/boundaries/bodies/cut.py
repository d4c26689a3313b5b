"""The weak wall with cut cells: a lattice site whose cell the body's surface cuts carries the fluid's share of it.

The weak wall (solvers/boundaries/bodies/weak.py) makes the wall from the corrected operators' adjoint pairing: the
fluid's volume ends where the sites carrying it end, a staircase about the surface, first order in dx. Here each site
carries the volume of its cell (a square, a cube in 3D, of side dx about it) that lies outside the body, m = f
rho dx^d with f the cell's fluid fraction (:func:`~solvers.boundaries.bodies.base.cell_fractions`): the volume sums (the
corrected operators' quadrature) then hold the fluid's true domain to second order, and a site whose centre is
inside the surface but whose cell is not (at most half a cell's diagonal deep) carries its cell's fluid part as a
fluid particle (a fluid particle has entered the body past that depth, :meth:`Cut.entry_depth`). Nothing else
changes: a site's own rate never reads its own volume, only its neighbours', so a small cut cell is no stiffer.
Measured on the CAA cylinder (docs/accuracy.md "A wall as accurate as the bulk").
"""

from __future__ import annotations

import math

import numpy as np

from solvers.boundaries.bodies.base import cell_fractions
from solvers.boundaries.bodies.weak import Weak

ENTRY_MARGIN = 0.05  # spacings: round-off never reads a cut site's own place as an entry


class Cut(Weak):
    """The weak wall whose sites the surface cuts carry their cells' fluid volume; needs --correction gradient."""

    name = "cut"
    summary = (
        "the weak wall with cut cells: a site the surface cuts carries its cell's fluid volume (--correction gradient)"
    )

    def place(self, scene, x, y) -> tuple:
        inert = cell_fractions(scene, x, y) == 0.0
        none = np.zeros_like(inert)
        return none, inert, x[none], y[none]

    def entry_depth(self, dims: int) -> float:
        """Past half a cell's diagonal (a cut site's deepest) and a margin."""
        return 0.5 * math.sqrt(dims) + ENTRY_MARGIN

    def volume_fractions(self, scene, x, y, z=None):
        return cell_fractions(scene, x, y, z)
