"""Ghosts fitted to the surface: rings at r = a - (i + 1/2) dx, about dx apart along each."""

from __future__ import annotations

import math

import numpy as np

from solvers.boundaries.bodies.base import GHOSTS_BREAK_CORRECTION, BoundaryMethod, ring_count, sites_inside


class Rings(BoundaryMethod):
    """The body's ghosts on rings fitted to its surface, r_i = a - (i + 1/2) dx for as many rings as a cutoff
    needs (i < ceil(cutoff / dx), and inside the body), each about dx along, every other ring turned by half a
    spacing; each takes one of the body's lattice sites (the outermost first, matched by angle), the sites left
    are inert. Each ghost's values are the fluid's at its mirror point, r -> 2a - r."""

    name = "rings"
    summary = "ghost particles on rings fitted to the body's surface, values from their mirror points"
    fails_with_correction = GHOSTS_BREAK_CORRECTION

    def rings(self, scene, available: int) -> tuple:
        """(radius, angle) of every ring particle, m and rad, the outer ring first; at most ``available``."""
        _x0, _y0, a = scene.body
        radii, angles = [], []
        for i in range(int(math.ceil(scene.cutoff / scene.dx - 1e-9))):
            radius = a - (i + 0.5) * scene.dx
            if radius <= 0:
                break
            n = ring_count(radius, scene.dx)
            if len(radii) + n > available:
                break
            radii += [radius] * n
            angles += list(2.0 * math.pi * (np.arange(n) + 0.5 * (i % 2)) / n)
        return np.array(radii), np.array(angles)

    def place(self, scene, x, y) -> tuple:
        x0, y0, _a = scene.body
        r, inside = sites_inside(scene, x, y)
        sites = np.flatnonzero(inside)
        radius, angle = self.rings(scene, sites.size)
        theta = np.arctan2(y[sites] - y0, x[sites] - x0) % (2.0 * math.pi)
        by_radius = sites[np.lexsort((theta, -r[sites]))]  # the outermost sites first, each ring's by angle
        ghost = np.zeros(x.size, bool)
        gx, gy = np.empty(x.size), np.empty(x.size)
        start = 0
        for ring in np.unique(radius)[::-1]:
            on = np.flatnonzero(radius == ring)
            take = by_radius[start : start + on.size]
            take = take[np.argsort(np.arctan2(y[take] - y0, x[take] - x0) % (2.0 * math.pi))]
            ghost[take] = True
            gx[take] = x0 + ring * np.cos(angle[on])
            gy[take] = y0 + ring * np.sin(angle[on])
            start += on.size
        return ghost, inside & ~ghost, gx[ghost], gy[ghost]
