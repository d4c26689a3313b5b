"""A rigid body in a 3D scene (a sphere): its wall the weak one, the only one a 3D body has.

The sphere (``Scene.body``: radius a, its centre at x0, y0 and z = 0) holds the lattice sites inside it; every one
is inert (solvers/boundaries/bodies/weak.py): zero fields and no mass, so no sum counts it and the fluid near the wall
has truncated neighbourhoods, where the gradient-corrected operators make the wall (u . n = 0 weakly, the
summation-by-parts boundary). The inert particles never move (put back after every advance of moving particles)
and a fluid particle half a spacing inside the sphere stops the run (BodyEntered). The ghost bodies of 2D
(solvers/boundaries/body.py) are refused on a 3D scene (Scene's body check).
"""

from __future__ import annotations

from solvers.boundaries.base import Boundary
from solvers.boundaries.bodies.base import FLUID, INERT, BodyEntered

FIELDS = ("u", "v", "w", "drho", "drho_x", "drho_y")  # with a PML's parts of drho where the layer carries them


class RigidBody3D(Boundary):
    """A 3D scene's body in a solver: its sites' roles (``role``: INERT inside, FLUID outside), their fields kept
    zero before every sweep, their places kept after every advance."""

    name = "body"
    kind = "body"

    def __init__(self, scene):
        from solvers.boundaries.bodies import boundary_method_named

        super().__init__(scene)
        self.method = boundary_method_named(scene.boundary_method_used)
        self.x0, self.y0, self.a = scene.body

    @classmethod
    def applies(cls, scene) -> bool:
        return scene.body is not None and scene.dims == 3

    def start(self, solver, x, y, drho, z=None) -> None:
        a, xp, dt = solver.arrays, solver.xp, solver.dtype
        host = [solver.to_host(c) for c in (x, y, z)]
        fractions = self.method.volume_fractions(self.scene, *host)
        if fractions is None:
            inside = (x - self.x0) ** 2 + (y - self.y0) ** 2 + z**2 < self.a**2
        else:  # cut cells: a site inert where its cell has no fluid, else its cell's fluid volume
            inside = xp.asarray(fractions == 0.0)
            a["mass"] *= xp.asarray(fractions.astype(dt))
        a["role"] = xp.where(inside, INERT, FLUID).astype(dt)
        for name in FIELDS:
            if name in a:
                a[name][inside] = 0
        a["mass"][inside] = 0  # no volume: no sum counts the inert particles
        self.n_inert = int(inside.sum())

    def inert(self, solver):
        return solver.arrays["role"] != 0

    def before_sweep(self, solver) -> bool:
        """The inert particles' fields zero (their own sums gave them values no fluid particle reads); a fluid
        particle inside the sphere stops the run."""
        a = solver.arrays
        inert = self.inert(solver)
        for name in FIELDS:
            if name in a:
                a[name][inert] = 0
        if solver.moving:
            self.check_entered(solver, inert)
        return True

    def check_entered(self, solver, inert) -> None:
        s, a, xp = self.scene, solver.arrays, solver.xp
        r2 = sum(
            (lo + (a[f"l{c}"].astype(xp.float64) + 0.5) * s.dx + a[f"s{c}"] - c0) ** 2
            for lo, c, c0 in ((s.x_lo, "x", self.x0), (s.y_lo, "y", self.y0), (s.z_lo, "z", 0.0))
        )
        depth = self.method.entry_depth(3)
        deep = (self.a - depth * s.dx) ** 2
        entered = (r2 < deep) & ~inert
        if bool(entered.any()):
            raise BodyEntered(
                f"{int(entered.sum())} fluid particle(s) inside the sphere, past {depth:g} spacings below its surface "
                f"(r < {self.a - depth * s.dx:.4g} m): the wall let them through"
            )

    def moved(self, solver) -> None:
        """The inert particles back at their sites."""
        a = solver.arrays
        inert = self.inert(solver)
        for name in ("sx", "sy", "sz"):
            a[name][inert] = 0
