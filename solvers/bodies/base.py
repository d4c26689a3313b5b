"""What a boundary method is: how a rigid body's curved wall is modelled by particles inside it, one file each.

A body (``Scene.body``: a cylinder of radius a, its axis at x0, y0) holds the lattice sites inside it. A boundary
method says which of them are the wall's particles (ghosts) and where they sit (:meth:`BoundaryMethod.place`);
the others inside are inert, and where the fluid is sampled for the ghosts' values
(:meth:`BoundaryMethod.sample_points`: by default their mirror points across the surface). The body in a solver,
its ghosts filled before every sweep and its particles pinned after every advance, is the boundary model
solvers/boundaries/body.py (``RigidBody``).
"""

from __future__ import annotations

import math

import numpy as np

FLUID, GHOST, INERT = 0.0, 1.0, 2.0  # a particle's role (the solver's ``role`` array)
# A fluid particle has entered the body once it is this many spacings below the surface: where the ghosts' outer
# ring sits (a lattice site can start on the surface itself and move in by round-off, which is no entry).
ENTRY_DEPTH = 0.5


class BodyEntered(RuntimeError):
    """A fluid particle moved inside the body: the run has failed at this step."""


# A ghost body with a corrected kernel: ghosts filled from the fluid break the corrected operators' adjoint pairing
GHOSTS_BREAK_CORRECTION = (
    "ghosts filled from the fluid break the corrected operators' adjoint pairing; the corrected Laguerre-Gauss "
    "method (h 1.5 dx, 4 h, Verlet CFL 0.5, dx 0.04) blew up at the body with rings at t = 1.8 s and with the "
    "lattice's ghosts near t = 4 s (docs/accuracy.md)"
)


class BoundaryMethod:
    """Where a body's ghost particles sit (:meth:`place`) and where the fluid is sampled for their values
    (:meth:`sample_points`: by default their mirror points across the wall)."""

    name: str = ""
    summary: str = ""
    needs_correction: bool = False  # whether it makes a wall only with a kernel correction (solvers/corrections/)
    # Where its wall is known to blow up with a kernel correction: what was measured, one clause ("" where it holds)
    fails_with_correction: str = ""

    def place(self, scene, x, y) -> tuple:
        """(ghost, inert, gx, gy) for the lattice sites at ``x``, ``y`` (m, float64 arrays, site order): which
        sites are ghosts and which inert (boolean arrays), and the ghosts' positions (m, in the order of their
        sites)."""
        raise NotImplementedError

    def sample_points(self, scene, gx, gy) -> tuple:
        """(sx, sy, nx, ny): where the fluid is sampled for each ghost at ``gx``, ``gy`` and the wall's outward
        normal there: the mirror point across the cylinder's surface, r -> 2a - r."""
        x0, y0, a = scene.body
        px, py = gx - x0, gy - y0
        r = np.maximum(np.hypot(px, py), 1e-12 * a)
        nx, ny = px / r, py / r
        mirror = 2.0 * a - r
        return x0 + mirror * nx, y0 + mirror * ny, nx, ny

    def __repr__(self) -> str:
        return f"<boundary method {self.name}>"


def sites_inside(scene, x, y):
    """(r, inside): the sites' distances from the body's axis (m) and which are inside it (r < a)."""
    x0, y0, a = scene.body
    r = np.hypot(np.asarray(x, float) - x0, np.asarray(y, float) - y0)
    return r, r < a


def ring_count(radius: float, dx: float) -> int:
    """Particles on a ring of ``radius`` m about dx apart."""
    return max(int(round(2.0 * math.pi * radius / dx)), 1)
