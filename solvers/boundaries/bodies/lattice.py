"""Ghosts on the lattice: the sites inside the body within a cutoff of its wall, a staircase."""

from __future__ import annotations

from solvers.boundaries.bodies.base import GHOSTS_BREAK_CORRECTION, BoundaryMethod, sites_inside


class Lattice(BoundaryMethod):
    """The lattice's own sites inside the body, within a cutoff of the wall, are its ghosts where they stand
    (the wall a staircase of sites); deeper sites are inert. Each ghost's values are the fluid's at its mirror
    point across the true, round surface."""

    name = "lattice"
    summary = "the lattice's sites inside the body as its ghosts (a staircase), values from their mirror points"
    fails_with_correction = GHOSTS_BREAK_CORRECTION

    def place(self, scene, x, y) -> tuple:
        _x0, _y0, a = scene.body
        r, inside = sites_inside(scene, x, y)
        ghost = inside & (r >= a - scene.cutoff)
        return ghost, inside & ~ghost, x[ghost], y[ghost]
