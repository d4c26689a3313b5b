"""The paper's scene: a right-travelling plane Gaussian pulse (the CAA workshop's 1D pulse).

u = c0 Ma exp(-((x - x_c - c0 t)/w)^2), v = 0, drho = rho0 u / c0 on
x in [-10, 40] m, y in [-10, 10] m, periodic in y, free left and right
edges. The fields do not depend on y, so a y-periodic strip gives the same
answer. Scored on u (the paper's eq. 11); the lagrangian model also against
the 1D isothermal solution (solvers/reference/isothermal1d.py), which steepens into a
shock at t_b = w / (c0 Ma sqrt(2/e)) (70 s at the defaults).
"""

from __future__ import annotations

import math

from solvers.fields import Fields
from solvers.reference.analytic import errors as analytic_errors
from solvers.scenes.base import PULSE_REACH, SceneKind, left_behind


class PlanePulse(SceneKind):
    name = "plane-pulse"
    summary = "the paper's right-travelling plane Gaussian pulse, periodic in y, free ends in x (1D)"
    periodic = ("y",)
    fields = ("u",)
    primary = "u"
    has_isothermal = True
    strip = True

    def initial_fields(self, scene, x, y, xp):
        xi = (x - scene.pulse_center) / scene.pulse_width
        u = scene.c0 * scene.mach * xp.exp(-xi * xi)
        return u, xp.zeros_like(u), scene.rho0 * u / scene.c0

    def exact_fields(self, scene, t: float):
        import numpy as np

        from solvers.reference.analytic import pulse_velocity

        x = scene.x_lo + (np.arange(scene.nx) + 0.5) * scene.dx
        u = pulse_velocity(scene, x, t)
        return Fields(x=x, y=np.zeros_like(x), u=u, v=np.zeros_like(u), drho=scene.rho0 * u / scene.c0, t=t)

    def breaking_time(self, scene) -> float:
        """The simple wave's characteristics (speed u + c0) cross at t_b = 1 / max du/dx."""
        return scene.pulse_width / (scene.c0 * scene.mach * math.sqrt(2.0 / math.e))

    smallest = {"dx": 1.0, "x_min": -8.0, "x_max": 8.0}
    # open x edges: an absorbing layer beyond the domain, the pulse's flank in it from the start (a solver that
    # skips the layer's damping, Solver.absorb around each kick and advance, or scores the layer's particles
    # fails agreement here)
    smallest_open = {"dx": 1.0, "x_min": -8.0, "x_max": 8.0, "open": "x", "layer_width": 3.0, "pulse_center": 5.0}
    card_open = {"dx": 0.25, "open": "x"}  # the paper's pulse with open x edges (the sponge)

    def pulse_inside(self, scene, t: float) -> bool:
        """The right-going pulse's front (its peak and :data:`PULSE_REACH` widths) has not reached x_max (an open
        edge, or the free end it leaves by)."""
        return scene.pulse_center + scene.c0 * t + PULSE_REACH * scene.pulse_width <= scene.x_max

    def errors(self, scene, fields) -> dict:
        err = analytic_errors(scene, fields.x, fields.u, fields.t)
        out = {"mse": err.mse, "me": err.me}
        if scene.open or not self.pulse_inside(scene, fields.t):  # what the ends leave behind, against the line's
            import numpy as np

            from solvers.reference.analytic import pulse_velocity

            u = pulse_velocity(scene, np.asarray(fields.x, float), fields.t)
            out.update(left_behind(scene, fields, (scene.rho0 * u / scene.c0, u, np.zeros_like(u))))
        return out

    def isothermal_errors(self, scene, fields) -> float | None:
        """None once the pulse and four widths of its tail have left by the free right end: there is then no
        pulse to score (against the linear pulse the relative error is NaN then: its reference is zero)."""
        from solvers.reference.isothermal1d import isothermal_errors

        if scene.pulse_center + scene.c0 * fields.t - 4.0 * scene.pulse_width > scene.x_max:
            return None
        return isothermal_errors(scene, fields.x, fields.u, fields.t).mse

    def predict(self, scene):
        from solvers.reference.dispersion import predict_plane

        return predict_plane(scene)
