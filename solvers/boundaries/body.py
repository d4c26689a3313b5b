"""A rigid body inside the scene: its curved wall made by particles inside it (the boundary method:
solvers/boundaries/bodies/).

A body (``Scene.body``: a cylinder of radius a, its axis at x0, y0) holds the lattice sites inside it. The scene's
boundary method says which of them are the wall's particles (ghosts) and where they sit; the others inside are
inert (zero fields and no volume: no sum counts them). Before every sweep each ghost takes the fluid's values
mirrored across the wall (:meth:`RigidBody.fill`): drho (so the pressure) even, the normal velocity odd and the
tangential one even, the conditions of a rigid wall for the linear acoustic equations (u . n = 0 and dp/dn = 0),
sampled at the ghost's mirror point across the surface from the fluid particles within a cutoff of it by
first-order moving least squares (exact for linear fields; Shepard's average where too few neighbours make it
singular): the fixed ghost particles of Marrone et al. (2011). The body's particles never move (put back after
every advance: :meth:`RigidBody.pin`), and a fluid particle inside the body stops the run (BodyEntered).

Every solver applies a body through the same primitives, on any backend: the few particles near the body are
found on the device and their values copied to the host, where the sampling weights are built, once for
particles that do not move and before every sweep for those that do.
"""

from __future__ import annotations

import numpy as np

from solvers.boundaries.base import Boundary
from solvers.boundaries.bodies.base import FLUID, GHOST, INERT, BodyEntered
from solvers.sampling import mls_weights


class RigidBody(Boundary):
    """A scene's body in a solver: its particles' roles and places (:meth:`place`, at init), the ghosts'
    values before every sweep (:meth:`fill`), the body's particles put back after every advance (:meth:`pin`)."""

    name = "body"
    kind = "body"

    def __init__(self, scene):
        from solvers.boundaries.bodies import boundary_method_named

        super().__init__(scene)
        self.method = boundary_method_named(scene.boundary_method_used)
        self.x0, self.y0, self.a = scene.body
        # the fluid a ghost's sample point can reach: a cutoff beyond the deepest mirror point
        self.reach = self.a + 2.0 * scene.cutoff + 2.0 * scene.dx
        self.key = None

    def place(self, x, y) -> tuple:
        """(role, sx, sy): each site's role (FLUID, GHOST, INERT) and shift to its place (m), float64 arrays in
        site order, from the sites' positions ``x``, ``y`` (m)."""
        s = self.scene
        x, y = np.asarray(x, float), np.asarray(y, float)
        ghost, inert, gx, gy = self.method.place(s, x, y)
        role = np.full(x.size, FLUID)
        role[ghost], role[inert] = GHOST, INERT
        sx, sy = np.zeros(x.size), np.zeros(x.size)
        sx[ghost], sy[ghost] = gx - x[ghost], gy - y[ghost]
        self.body_ids = np.flatnonzero(role != FLUID)  # site ids (id = row * nx + column), sorted
        self.body_sx, self.body_sy = sx[self.body_ids], sy[self.body_ids]
        self.ghost_ids = np.flatnonzero(ghost)
        px, py, nx, ny = self.method.sample_points(s, gx, gy)
        self.samples = np.stack([px, py], axis=1)
        self.normals = np.stack([nx, ny], axis=1)
        self.n_ghosts, self.n_inert = int(ghost.sum()), int(inert.sum())
        return role, sx, sy

    def _ids(self, a, idx, to_host, xp=np):
        """The site ids of the particles at solver indices ``idx`` (host int array)."""
        s = self.scene
        where = idx if xp is np else xp.asarray(idx)  # a device array is indexed on the device
        lx, ly = (np.rint(to_host(a[k][where])).astype(np.int64) for k in ("lx", "ly"))
        return (ly % s.ny) * s.nx + lx % s.nx

    def locate(self, solver) -> None:
        """The body's particles and the fluid near it in the solver's current order, and the sampling matrix;
        BodyEntered if a fluid particle is inside the body."""
        s, a, xp, to_host = self.scene, solver.arrays, solver.xp, solver.to_host
        px = s.x_lo + (a["lx"].astype(xp.float64) + 0.5) * s.dx + a["sx"]
        py = s.y_lo + (a["ly"].astype(xp.float64) + 0.5) * s.dx + a["sy"]
        near_dev = xp.flatnonzero((px - self.x0) ** 2 + (py - self.y0) ** 2 < self.reach**2)  # on the device
        near = to_host(near_dev).astype(np.int64)
        role = to_host(a["role"][near_dev])
        pos = np.stack([to_host(px[near_dev]), to_host(py[near_dev])], axis=1)
        fluid = role == FLUID
        r = np.hypot(pos[:, 0] - self.x0, pos[:, 1] - self.y0)
        depth = self.method.entry_depth(2)
        entered = fluid & (r < self.a - depth * s.dx)
        if entered.any():
            raise BodyEntered(
                f"{int(entered.sum())} fluid particle(s) inside the cylinder, past {depth:g} spacings below its "
                f"surface (r < {self.a - depth * s.dx:.4g} m, the deepest at r = {r[entered].min():.4g} m): "
                "the wall let them through"
            )
        body = near[~fluid]
        order = np.searchsorted(self.body_ids, self._ids(a, body, to_host, xp))
        self.body_idx, self.body_at = body, order  # solver indices, and each one's entry in body_ids
        ghosts = role[~fluid] == GHOST
        ghost_idx = body[ghosts]
        self.ghost_idx = ghost_idx
        self.ghost_at = np.searchsorted(self.ghost_ids, self._ids(a, ghost_idx, to_host, xp))
        self.inert_idx = body[~ghosts]
        self.fluid_idx = near[fluid]
        self.weights = mls_weights(s, self.samples[self.ghost_at], pos[fluid], s.dx * s.dx)
        self.normal = self.normals[self.ghost_at]
        dev = (lambda v: xp.asarray(v)) if xp is not np else (lambda v: v)
        self.dev_ghost, self.dev_inert, self.dev_body = dev(ghost_idx), dev(self.inert_idx), dev(body)
        self.dev_fluid = dev(self.fluid_idx)
        self.dev_body_sx, self.dev_body_sy = (dev(v[order].astype(solver.dtype)) for v in (self.body_sx, self.body_sy))

    def fill(self, solver) -> None:
        """The ghosts' fields from the fluid's, mirrored across the wall; the inert particles' zero."""
        key = getattr(solver, "reordered", 0)
        if solver.moving or key != self.key:
            self.locate(solver)
            self.key = key
        a, xp, to_host, dt = solver.arrays, solver.xp, solver.to_host, solver.dtype
        fid = self.dev_fluid
        drho, u, v = (self.weights @ to_host(a[k][fid]).astype(np.float64) for k in ("drho", "u", "v"))
        un = u * self.normal[:, 0] + v * self.normal[:, 1]
        u, v = u - 2.0 * un * self.normal[:, 0], v - 2.0 * un * self.normal[:, 1]
        for name, values in (("drho", drho), ("u", u), ("v", v)):
            a[name][self.dev_ghost] = xp.asarray(values.astype(dt))
            a[name][self.dev_inert] = 0
        if "drho_x" in a:  # a split absorber's x part: half (the layer is far from the body)
            a["drho_x"][self.dev_ghost] = xp.asarray((0.5 * drho).astype(dt))
            a["drho_x"][self.dev_inert] = 0

    def pin(self, solver) -> None:
        """The body's particles back at their places (for moving particles, after every advance)."""
        if self.key is None:
            return
        a = solver.arrays
        a["sx"][self.dev_body] = self.dev_body_sx
        a["sy"][self.dev_body] = self.dev_body_sy

    @classmethod
    def applies(cls, scene) -> bool:
        return scene.body is not None and scene.dims == 2

    def start(self, solver, x, y, drho, z=None) -> None:
        """The body's particles' roles and places (``role``, their shifts), their fields zero and the inert ones
        massless."""
        a, xp, dt = solver.arrays, solver.xp, solver.dtype
        self.key = None  # located at the first fill
        role, shift_x, shift_y = (xp.asarray(v) for v in self.place(solver.to_host(x), solver.to_host(y)))
        a["role"] = role.astype(dt)
        a["sx"], a["sy"] = shift_x.astype(dt), shift_y.astype(dt)
        for name in ("u", "v", "drho"):
            a[name][role != 0] = 0
        a["mass"][role == INERT] = 0  # no volume: no sum counts the inert particles
        fractions = self.method.volume_fractions(self.scene, solver.to_host(x), solver.to_host(y))
        if fractions is not None:  # cut cells: each site its cell's fluid volume
            a["mass"] *= xp.asarray(fractions.astype(dt))

    def before_sweep(self, solver) -> bool:
        self.fill(solver)
        return True

    def moved(self, solver) -> None:
        self.pin(solver)
