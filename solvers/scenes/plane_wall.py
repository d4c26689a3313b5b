"""The paper's plane pulse meeting a rigid wall: the CAA workshop's pulse reflected by a wall, in 1D.

The plane Gaussian pulse of the paper's scene (u = c0 Ma exp(-((x - x_c)/w)^2),
drho = rho0 u / c0) travels right into a rigid wall at x_w (the domain's
right edge, ``--wall-x``, 6 m by default: at t = 10 s the pulse has met it
and travels back); the left edge at -10 m is free as in the paper, the scene
periodic in y (a strip gives the same answer). The exact linear solution is
the pulse plus its mirror image, a left-travelling pulse from 2 x_w - x_c:

    u = f(x - x_c - c0 t) - f(2 x_w - x - x_c - c0 t),
    drho = (rho0 / c0) (f(x - x_c - c0 t) + f(2 x_w - x - x_c - c0 t)),

which is also the initial field (so that the image's tail, 2 % of the peak at
the wall at t = 0 for the defaults, is in it and u = 0 at the wall at all
times). The wall acts through mirror particles (solvers/physics/pairs.py); the
lattice ends half a spacing from it, so the `linear` model's run is the even
extension of a free one and the dispersion prediction holds for it exactly
(solvers/reference/dispersion.py). Scored on u against the reflected solution, over the
domain and apart near the wall (within a cutoff: the particles that have
mirror neighbours) and in the bulk. There is no isothermal reference: two
simple waves crossing are not one.
"""

from __future__ import annotations

from solvers.fields import Fields
from solvers.reference.analytic import pulse_velocity, relative_errors
from solvers.scenes.base import PULSE_REACH, left_behind, wall_measures
from solvers.scenes.plane_pulse import PlanePulse

DEFAULT_WALL = 6.0  # m: the wall of plane-wall and pulse-wall by default, two pulse widths right of the pulse
# a walled scene at its smallest (182 particles): the narrow kernel (h 1.3 dx) lets a 14 x 13 m box hold the
# 3 cells of a cutoff across; the pulse is narrow and 4 m from the right wall (clear of its support, 3.9 m), so
# that its tail is at the wall and every mirror pair counts from the first step
SMALLEST_WALLED = {
    "dx": 1.0,
    "x_min": -8.0,
    "x_max": 6.0,
    "y_min": -6.5,
    "y_max": 6.5,
    "h_factor": 1.3,
    "pulse_width": 1.5,
    "pulse_center": 2.0,
}


def image_x(scene, x):
    """Positions ``x`` mirrored across the right wall, m."""
    return 2.0 * scene.walls["x_max"] - x


def wall_check(scene) -> list[str]:
    """The pulse must start inside the domain, clear of every wall: at least a pulse width and a cutoff from it
    (the wall's support: the particles that have mirror neighbours), one line each."""
    out = []
    wall = scene.walls["x_max"]
    clear = max(scene.pulse_width, scene.cutoff)
    left = scene.walls.get("x_min")
    if not scene.x_min < scene.pulse_center < wall:
        out.append(
            f"--pulse-center must be inside the domain ({scene.x_min:g}, {wall:g}) m, left of the wall "
            f"(got {scene.pulse_center:g}); or move the wall with --wall-x"
        )
    elif wall - scene.pulse_center < clear:
        out.append(
            f"--wall-x must be at least max(pulse width, cutoff) = {clear:g} m right of the pulse's centre "
            f"{scene.pulse_center:g} m (got the wall at {wall:g} m): the pulse would start inside the wall's support"
        )
    elif left is not None and scene.pulse_center - left < clear:
        out.append(
            f"--pulse-center must be at least max(pulse width, cutoff) = {clear:g} m right of the left wall at "
            f"{left:g} m (got {scene.pulse_center:g}): the pulse would start inside the wall's support"
        )
    return out


class PlaneWall(PlanePulse):
    name = "plane-wall"
    summary = "the paper's plane pulse reflected by a rigid wall at --wall-x (mirror particles), free left end"
    walls = ("x_max",)
    domain = {"x_max": DEFAULT_WALL}
    fields = ("u",)
    primary = "u"
    has_isothermal = False
    strip = True
    smallest = SMALLEST_WALLED
    smallest_open = None  # its x edge is a wall, its y a plane wave's: nothing to open
    card_open = None

    def initial_fields(self, scene, x, y, xp):
        incident, image = (
            (x - scene.pulse_center) / scene.pulse_width,
            (image_x(scene, x) - scene.pulse_center) / scene.pulse_width,
        )
        a, b = xp.exp(-incident * incident), xp.exp(-image * image)
        u = scene.c0 * scene.mach * (a - b)
        return u, xp.zeros_like(u), scene.rho0 * scene.mach * (a + b)

    def exact_velocity(self, scene, x, t: float):
        """u of the reflected solution at ``x`` (m) and ``t`` (s), m/s."""
        return pulse_velocity(scene, x, t) - pulse_velocity(scene, image_x(scene, x), t)

    def exact_fields(self, scene, t: float):
        import numpy as np

        x = scene.x_lo + (np.arange(scene.nx) + 0.5) * scene.dx
        a, b = pulse_velocity(scene, x, t), pulse_velocity(scene, image_x(scene, x), t)
        return Fields(x=x, y=np.zeros_like(x), u=a - b, v=np.zeros_like(x), drho=scene.rho0 * (a + b) / scene.c0, t=t)

    def pulse_inside(self, scene, t: float) -> bool:
        """The reflected pulse's front (its peak, from the image's place 2 x_wall - x_c, and :data:`PULSE_REACH`
        widths) has not reached the free left end."""
        image = 2.0 * scene.walls["x_max"] - scene.pulse_center
        return image - scene.c0 * t - PULSE_REACH * scene.pulse_width >= scene.x_min

    def errors(self, scene, fields) -> dict:
        ref = self.exact_velocity(scene, fields.x, fields.t)
        err = relative_errors(fields.u, ref, amplitude=scene.mach * scene.c0)
        out = {
            "mse": err.mse,
            "me": err.me,
            **wall_measures(scene, fields.x, fields.u - ref, ref, scene.mach * scene.c0),
        }
        if not self.pulse_inside(scene, fields.t):  # what the free end leaves behind, against the reflection
            import numpy as np

            x = np.asarray(fields.x, dtype=np.float64)
            a, b = pulse_velocity(scene, x, fields.t), pulse_velocity(scene, image_x(scene, x), fields.t)
            out.update(left_behind(scene, fields, (scene.rho0 * (a + b) / scene.c0, a - b, np.zeros_like(x))))
        return out

    def isothermal_errors(self, scene, fields) -> float | None:
        return None

    def check(self, scene) -> list[str]:
        return super().check(scene) + wall_check(scene)
