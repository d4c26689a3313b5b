"""Open edges: an absorbing layer beyond each, damping what leaves the domain (the absorber:
solvers/boundaries/absorbers/).

``Scene.edges`` (solvers/edges.py) says which edges are open and the layer's width and strength; the lattice
holds the layer's columns (rows) beyond the domain (``Scene.n_layer``), whose particles are not scored. Around
each kick and advance the layer damps its fields by half of the update's decay, before and after it (stable at
the closed scene's CFL: solvers/boundaries/absorbers/base.py), with a rate sigma rising with each particle's depth
beyond the domain's edges (:meth:`OpenLayer.factors`). A split absorber (the PML) carries drho's x part
``drho_x`` and its rate ``ddx`` (the continuity sweep with v = 0: ``Solver.continuity_parts``) as arrays of the
state; in 3D the y part too (``drho_y``, ``ddy``: the sweep with u = w = 0), the z part being what is left.
"""

from __future__ import annotations

import inspect

from solvers.boundaries.absorbers.base import product
from solvers.boundaries.base import Boundary


class OpenLayer(Boundary):
    """The absorbing layer beyond the scene's open edges."""

    name = "open layer"

    def __init__(self, scene):
        from solvers.boundaries.absorbers import absorber_named

        super().__init__(scene)
        self.absorber = absorber_named(scene.absorber_used)
        self.split = bool(self.absorber.split)
        parts = scene.dims - 1 if self.split else 0  # the parts carried: every axis's but the last
        self.state = ("drho_x", "drho_y")[:parts]
        self.rates = ("ddx", "ddy")[:parts]
        self.key, self.sigma, self.cache = None, (), {}
        self.legacy = len(inspect.signature(self.absorber.damp).parameters) == 4  # (arrays, fx, fy, fields)

    @classmethod
    def applies(cls, scene) -> bool:
        return bool(scene.open)

    def start(self, solver, x, y, drho, z=None) -> None:
        """A split absorber's parts of drho (each axis an equal share: the last axis's is what is left) and of its
        rate."""
        self.key, self.sigma, self.cache = None, (), {}
        if self.split:
            xp, dt, n = solver.xp, solver.dtype, self.scene.n_particles
            for part, rate in zip(self.state, self.rates):
                solver.arrays[part] = (drho / self.scene.dims).astype(dt)
                solver.arrays[rate] = xp.zeros(n, dt)
            solver.no_velocity = xp.zeros(n, dt)  # the other components zero in a part's sweep (never permuted)

    def damp(self, solver, f: float, fields: str) -> None:
        factors = self.factors(solver, f)
        if self.legacy:  # a plug-in's damp(arrays, fx, fy, fields) of before 3D: y and z damp together
            self.absorber.damp(solver.arrays, factors[0], product(factors[1:]), fields)
            return
        self.absorber.damp(solver.arrays, factors, fields)

    def advanced(self, solver, f: float) -> None:
        """drho_x += f dt ddx (and drho_y += f dt ddy): a split absorber's parts of drho, updated with drho."""
        a, c = solver.arrays, solver.dtype.type(f * self.scene.dt)
        for part, rate in zip(self.state, self.rates):
            a[part] += c * a[rate]

    def factors(self, solver, f: float) -> tuple:
        """(fx, fy) (and fz in 3D): exp(-sigma f dt / 2) of each axis, sigma from each particle's depth beyond the
        domain's edges (0 inside the domain; 1 on a closed axis), kept until the particles move or are put in a
        new order."""
        key = (solver.reordered, solver.moves)
        if self.key != key:
            self.key, self.sigma, self.cache = key, self.rates_now(solver), {}
        factors = self.cache.get(f)
        if factors is None:
            h = 0.5 * f * self.scene.dt
            factors = tuple(
                solver.dtype.type(1.0) if sigma is None else solver.xp.exp(-sigma * h).astype(solver.dtype)
                for sigma in self.sigma
            )
            self.cache[f] = factors
        return factors

    def rates_now(self, solver) -> tuple:
        """(sigma_x, sigma_y) in 1/s at each particle's current position (None on a closed axis)."""
        s, xp, a = self.scene, solver.xp, solver.arrays
        rates = []
        axes = [("x", s.x_lo, s.x_min, s.x_max, "lx", "sx"), ("y", s.y_lo, s.y_min, s.y_max, "ly", "sy")]
        if s.dims == 3:
            axes.append(("z", s.z_lo, s.z_min, s.z_max, "lz", "sz"))
        for axis, lo, near, far, lattice, shift in axes:
            if axis not in s.open:
                rates.append(None)
                continue
            pos = lo + (a[lattice].astype(xp.float64) + 0.5) * s.dx + a[shift]
            depth = xp.maximum(xp.maximum(near - pos, pos - far), 0.0)
            rates.append(self.absorber.sigma(depth, s.layer, s.strength, xp))
        return tuple(rates)
