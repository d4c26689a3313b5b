"""No ghosts: the wall imposed weakly by the energy-keeping corrected operators (summation by parts).

The lattice sites inside the body are all inert and carry no volume, so no fluid particle's sum reaches into
the body: the fluid near the wall has truncated neighbourhoods. With the kernel gradient correction
(solvers/corrections/gradient.py) the momentum gradient is still exact for linear fields there, and the
continuity's divergence, its negative adjoint, then has no flux through the fluid's edge: u . n = 0 holds
weakly (the summation-by-parts boundary of finite differences), and the discrete energy is kept, so the wall
has no growing modes. Ghosts filled from the fluid (rings, lattice) break that adjoint pairing: with a
negative-lobe kernel they grow near the wall. The wall sits where the fluid's volume ends, about half a
spacing beyond its outermost particles: on the lattice cut by a circle, at the surface on average (first order
in dx). Needs the correction: without it the body is a hole with a free edge, not a wall.
"""

from __future__ import annotations

import numpy as np

from solvers.boundaries.bodies.base import BoundaryMethod, sites_inside


class Weak(BoundaryMethod):
    """Every lattice site inside the body inert with no volume; the corrected operators' adjoint pairing makes the
    fluid's edge a rigid wall (u . n = 0 weakly). Needs --correction gradient."""

    name = "weak"
    summary = (
        "no ghosts: the body's sites carry no volume, the corrected operators make the wall (--correction gradient)"
    )
    dims = (2, 3)
    needs_correction = True
    free_end = True  # no ghosts: beside the wall a particle's neighbours inside the body are missing

    def place(self, scene, x, y) -> tuple:
        _r, inside = sites_inside(scene, x, y)
        none = np.zeros_like(inside)
        return none, inside, x[none], y[none]
