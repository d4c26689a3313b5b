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
SUBCELLS = {2: 16, 3: 12}  # points a side at which a cell the surface may cut is sampled (256 and 1,728 a cell)


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
    dims: tuple = (2,)  # the dimensions of the bodies it models (the ghost bodies place particles in a plane)
    needs_correction: bool = False  # whether it makes a wall only with a kernel correction (solvers/corrections/)
    # Whether the fluid at its wall has part of its neighbourhood empty, as at a free edge: a run's stable step is
    # then the free end's (pcabench/predict/stability.py, measured_limits.csv)
    free_end: bool = False
    # Where its wall is known to blow up with a kernel correction: what was measured, one clause ("" where it holds)
    fails_with_correction: str = ""

    def place(self, scene, x, y) -> tuple:
        """(ghost, inert, gx, gy) for the lattice sites at ``x``, ``y`` (m, float64 arrays, site order): which
        sites are ghosts and which inert (boolean arrays), and the ghosts' positions (m, in the order of their
        sites)."""
        raise NotImplementedError

    def entry_depth(self, dims: int) -> float:
        """How many spacings below the surface a fluid particle has entered the body (:data:`ENTRY_DEPTH`)."""
        return ENTRY_DEPTH

    def volume_fractions(self, scene, x, y, z=None):
        """Each site's volume as a fraction of dx^d (a float64 array in site order), or None: every fluid site a
        whole cell, every body site none (the default)."""
        return None

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


def cell_fractions(scene, x, y, z=None) -> np.ndarray:
    """The fraction of each site's cell (a square of side dx centred on the site; a cube in 3D, about a sphere
    centred at z = 0) that lies outside the body: 1 and 0 where the surface is more than half a cell's diagonal
    away, else the share of SUBCELLS points a side that are outside (float64, site order): a site up to half a
    cell's diagonal inside the surface can hold fluid in its cell's corner."""
    x0, y0, a = scene.body
    dx, dims = scene.dx, 2 if z is None else 3
    offsets = [np.asarray(x, float) - x0, np.asarray(y, float) - y0] + ([] if z is None else [np.asarray(z, float)])
    r = np.sqrt(sum(c * c for c in offsets))
    out = (r >= a).astype(np.float64)
    near = np.flatnonzero(np.abs(r - a) < 0.5 * math.sqrt(dims) * dx)
    count = SUBCELLS[dims]
    s = ((np.arange(count) + 0.5) / count - 0.5) * dx
    grid = [g.ravel() for g in np.meshgrid(*([s] * dims), indexing="ij")]
    for chunk in np.array_split(near, max(1, near.size // 4096)):
        if chunk.size:
            r2 = sum((c[chunk][:, None] + g[None, :]) ** 2 for c, g in zip(offsets, grid))
            out[chunk] = (r2 >= a * a).mean(axis=1)
    return out
