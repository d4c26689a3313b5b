"""The CAA workshop's 2D acoustic pulse: a Gaussian pressure pulse at rest that spreads as a cylindrical wave.

drho = rho0 Ma exp(-ln2 r^2 / b^2), u = v = 0 at t = 0, r the distance to the
centre (``pulse_center``, the middle of the y range), b = ``pulse_width``
(3 m), in a square periodic in x and y (40 m by default, so that by t = 10 s
only the pulse's tail has wrapped). Its exact linear reference on the
periodic square evolves every Fourier mode of the sampled initial field with
the exact dispersion w = c0 |k| (solvers/reference/pulse2d.py: exact to round-off,
wrapped waves included, checked against the open-domain Bessel integral). The
lagrangian model is scored against the radially symmetric isothermal solution
(solvers/reference/isothermal_radial.py), which is the open-domain one: the wrapped
tail is not in it, so that score is given only while the wave front and three
widths of its tail (0.2 % of the peak) are inside the square's half side.

Error measures (the primary field is drho): relative RMS and max error of
drho and of the velocity vector over the domain, and the relative RMS of drho
along the lattice axes through the centre and along its diagonals, apart
(the lattice's phase error depends on the direction of travel).
"""

from __future__ import annotations

import math

import numpy as np

from solvers.fields import Fields
from solvers.reference.analytic import QUIET
from solvers.scenes.base import PULSE_REACH, SceneKind, left_behind, scored_axes

LN2 = math.log(2.0)


def centre(scene) -> tuple[float, float]:
    """The pulse's centre (x, y), m."""
    return scene.pulse_center, 0.5 * (scene.y_min + scene.y_max)


def _relative(diff, ref, amplitude: float = 0.0) -> float:
    """The relative RMS of ``diff`` against ``ref``; NaN where ``ref`` holds no pulse (its RMS below QUIET of
    ``amplitude``: solvers/reference/analytic.py)."""
    den = float(np.mean(np.abs(ref) ** 2))
    return float(np.sqrt(np.mean(np.abs(diff) ** 2) / den)) if den > (QUIET * amplitude) ** 2 else float("nan")


def measures(scene, x, y, drho, u, v, ref) -> dict:
    """The scene's error measures of the fields (drho, u, v at x, y) against ``ref`` (drho, u, v there)."""
    r_drho, r_u, r_v = ref
    d = np.asarray(drho, float) - r_drho
    du, dv = np.asarray(u, float) - r_u, np.asarray(v, float) - r_v
    if not (np.all(np.isfinite(d)) and np.all(np.isfinite(du)) and np.all(np.isfinite(dv))):
        nan = float("nan")
        return {"mse": nan, "me": nan, "velocity_rms": nan, "velocity_max": nan, "axis_rms": nan, "diagonal_rms": nan}
    px, py = offsets(scene, x, y)
    axis = (np.abs(px) < scene.dx) | (np.abs(py) < scene.dx)
    diagonal = (np.abs(px - py) < scene.dx) | (np.abs(px + py) < scene.dx)
    speed_err = np.hypot(du, dv)
    t = scene.t_final
    ray_axis = (py > 0) & (py < scene.dx) & (px > 0)  # the row just above the centre, to the right
    ray_diagonal = (np.abs(px - py) < 0.5 * scene.dx) & (px > 0)
    rho, speed = scene.rho0 * scene.mach, scene.mach * scene.c0  # the pulse's amplitudes: drho, velocity
    return {
        "mse": _relative(d, r_drho, rho),
        "me": float(np.max(np.abs(d))),
        "velocity_rms": _relative(speed_err, np.hypot(r_u, r_v), speed),
        "velocity_max": float(speed_err.max()),
        "axis_rms": _relative(d[axis], r_drho[axis], rho),
        "diagonal_rms": _relative(d[diagonal], r_drho[diagonal], rho),
        "front_axis": front_shift(
            px[ray_axis], py[ray_axis], np.asarray(drho, float)[ray_axis], r_drho[ray_axis], scene.c0 * t
        ),
        "front_diagonal": front_shift(
            px[ray_diagonal],
            py[ray_diagonal],
            np.asarray(drho, float)[ray_diagonal],
            r_drho[ray_diagonal],
            scene.c0 * t,
        ),
    }


def offsets(scene, x, y) -> tuple:
    """(px, py): the offsets of points ``x``, ``y`` from the pulse's centre, m, by the nearest image along the
    axes that are periodic (an open axis has no images)."""
    xc, yc = centre(scene)
    px, py = np.asarray(x, float) - xc, np.asarray(y, float) - yc
    if scene.periodic_x:
        px = wrapped(px, scene.x_max - scene.x_min)
    if scene.periodic_y:
        py = wrapped(py, scene.y_max - scene.y_min)
    return px, py


def left_by_direction(scene, x, y, drho, ref) -> dict:
    """What the open edges left behind by direction of travel from the pulse's centre: the largest error of drho
    over the initial peak within 15 degrees of the lattice's axes (``left_axis``: the sound met the edges at
    normal incidence there) and beyond 30 degrees from them (``left_diagonal``: towards the corners, at oblique
    incidence)."""
    px, py = offsets(scene, x, y)
    angle = np.degrees(np.arctan2(np.abs(py), np.abs(px)))
    angle = np.minimum(angle, 90.0 - angle)  # 0 along an axis, 45 along a diagonal
    d = np.abs(np.asarray(drho, float) - ref) / (scene.rho0 * scene.mach)
    if not np.all(np.isfinite(d)):
        return {"left_axis": float("nan"), "left_diagonal": float("nan")}
    return {"left_axis": float(d[angle < 15.0].max()), "left_diagonal": float(d[angle > 30.0].max())}


def peak_radius(r, values, beyond: float) -> float:
    """Radius of the largest value past ``beyond`` (m), by a parabola through it and its two neighbours."""
    order = np.argsort(r)
    r, values = r[order], values[order]
    out = np.flatnonzero(r > beyond)
    if out.size < 3:
        return float("nan")
    i = out[0] + int(np.argmax(values[out]))
    if i == 0 or i >= r.size - 1:
        return float(r[i])
    a, b, _c = np.polyfit(r[i - 1 : i + 2] - r[i], values[i - 1 : i + 2], 2)
    return float(r[i] - b / (2 * a)) if a < 0 else float(r[i])


def front_shift(px, py, drho, ref, travelled: float) -> float:
    """The wave front's speed error along a ray, c / c0 - 1: how far the run's outgoing peak of drho is from
    the exact one's, over the distance travelled (``travelled`` = c0 t, m); NaN before the front has left
    the pulse (t < pulse width)."""
    if not travelled > 0:
        return float("nan")
    r = np.hypot(px, py)
    return (peak_radius(r, drho, 0.5 * travelled) - peak_radius(r, ref, 0.5 * travelled)) / travelled


def wrapped(d, period: float):
    """Offsets ``d`` to their minimum image in a period, m."""
    return d - period * np.round(d / period)


class AcousticPulse(SceneKind):
    name = "acoustic-pulse"
    summary = (
        "the CAA workshop's 2D acoustic pulse: a Gaussian pressure pulse at rest in a periodic square "
        "(--open xy: in the open plane)"
    )
    periodic = ("x", "y")
    images = ("x", "y")  # the square's seams are the open pulse's images: --open x, y or xy opens them
    domain = {"x_min": -20.0, "x_max": 20.0, "y_min": -20.0, "y_max": 20.0}
    fields = ("drho", "velocity")
    primary = "drho"
    has_isothermal = True
    strip = False

    def initial_fields(self, scene, x, y, xp):
        xc, yc = centre(scene)
        r2 = (x - xc) ** 2 + (y - yc) ** 2
        drho = scene.rho0 * scene.mach * xp.exp(-LN2 * r2 / scene.pulse_width**2)
        zero = xp.zeros_like(drho)
        return zero, zero.copy(), drho

    def reference_lattice(self, scene) -> tuple[int, tuple]:
        """(columns, image centres): the periodic lattice the exact reference is computed on, from x_lo, and the
        x of further pulses summed with the first (here the scene's own lattice and none; a walled scene's is
        its doubled, even-extended lattice with the pulse's mirror image)."""
        return scene.nx, ()

    def reference(self, scene, t: float):
        """The exact linear solution on the reference lattice at ``t`` (solvers/reference/pulse2d.py); with open
        edges, the open plane's (the Bessel integral) on the scored domain's lattice, with the images of the
        axes that stay periodic."""
        from solvers.reference.pulse2d import OpenPulse, periodic_linear

        xc, yc = centre(scene)
        if scene.open:
            x, y = scored_axes(scene)
            periods = (
                scene.x_max - scene.x_min if scene.periodic_x else 0.0,
                scene.y_max - scene.y_min if scene.periodic_y else 0.0,
            )
            return OpenPulse(x, y, xc, yc, periods, scene.pulse_width, scene.mach, scene.rho0, scene.c0, t)
        columns, images = self.reference_lattice(scene)
        return periodic_linear(
            columns,
            scene.ny,
            scene.dx,
            scene.x_lo,
            scene.y_lo,
            xc,
            yc,
            scene.pulse_width,
            scene.mach,
            scene.rho0,
            scene.c0,
            t,
            images=images,
        )

    def exact_fields(self, scene, t: float):

        ref = self.reference(scene, t)
        x, y = np.meshgrid(ref.x, ref.y)
        return Fields(x=x.ravel(), y=y.ravel(), u=ref.u.ravel(), v=ref.v.ravel(), drho=ref.drho.ravel(), t=t)

    smallest = {"dx": 1.0, "x_min": -10.0, "x_max": 10.0, "y_min": -10.0, "y_max": 10.0}
    # all four edges open (free y edges) with the split-field PML (the x part of the continuity rate): the pulse
    # off-centre, its flank in the right and the corner layers from the start
    smallest_open = {
        "dx": 1.0,
        "x_min": -6.0,
        "x_max": 6.0,
        "y_min": -6.0,
        "y_max": 6.0,
        "pulse_width": 1.5,
        "pulse_center": 3.0,
        "open": "xy",
        "layer_width": 3.0,
    }
    # a 24 m open square (free y edges, the PML)
    card_open = {"dx": 0.25, "x_min": -12.0, "x_max": 12.0, "y_min": -12.0, "y_max": 12.0, "open": "xy"}

    def pulse_inside(self, scene, t: float) -> bool:
        """The ring (its radius c0 t and :data:`PULSE_REACH` half-widths) has not reached an open edge."""
        xc, yc = centre(scene)
        gaps = {"x": (xc - scene.x_min, scene.x_max - xc), "y": (yc - scene.y_min, scene.y_max - yc)}
        nearest = min((gap for axis in scene.open for gap in gaps[axis]), default=math.inf)
        return scene.c0 * t + PULSE_REACH * scene.pulse_width <= nearest

    def errors(self, scene, fields) -> dict:
        ref = self.reference(scene, fields.t)
        if scene.model == "lagrangian":  # particles moved: the reference at their positions
            values = ref.at(fields.x, fields.y, order=3)  # Taylor about each site: 1e-7
        else:
            values = (ref.drho.ravel(), ref.u.ravel(), ref.v.ravel())
        out = measures(scene, fields.x, fields.y, fields.drho, fields.u, fields.v, values)
        if scene.open:
            out.update(left_behind(scene, fields, values))
            out.update(left_by_direction(scene, fields.x, fields.y, fields.drho, values[0]))
        return out

    def isothermal_errors(self, scene, fields) -> float | None:
        from solvers.reference.isothermal_radial import isothermal_pulse_radial_cached

        sides = [scene.x_max - scene.x_min] * scene.periodic_x + [scene.y_max - scene.y_min] * scene.periodic_y
        if sides and scene.c0 * fields.t + 3.0 * scene.pulse_width > 0.5 * min(sides):
            return None  # the periodic images have come in: the open-domain solution is no reference
        px, py = offsets(scene, fields.x, fields.y)
        r = np.hypot(px, py)
        r_max = (
            (0.5 if not scene.open else 1.0) * math.hypot(scene.x_max - scene.x_min, scene.y_max - scene.y_min)
            + scene.c0 * fields.t
            + 4 * scene.pulse_width
        )
        rr, drho, _u = isothermal_pulse_radial_cached(
            fields.t, scene.pulse_width, scene.mach, scene.rho0, scene.c0, round(r_max, 3)
        )
        ref = np.interp(r, rr, drho)
        d = np.asarray(fields.drho, float) - ref
        return _relative(d, ref, scene.rho0 * scene.mach) if np.all(np.isfinite(d)) else float("nan")

    def predict(self, scene):
        from solvers.reference.dispersion import predict_2d

        return predict_2d(scene, self)

    def sized_domain(self, size: float) -> dict:
        """A square of side ``size`` m centred on the origin."""
        return {"x_min": -0.5 * size, "x_max": 0.5 * size, "y_min": -0.5 * size, "y_max": 0.5 * size}

    def check(self, scene) -> list[str]:
        out = super().check(scene)
        xc, yc = centre(scene)
        half = 0.5 * min(scene.x_max - scene.x_min, scene.y_max - scene.y_min)
        if not 3 * scene.pulse_width <= half:
            out.append(
                f"--domain-size must be at least 6 pulse widths ({6 * scene.pulse_width:g} m) so that the "
                f"pulse fits in the square (got {2 * half:g} m)"
            )
        if not scene.x_min <= xc <= scene.x_max:
            out.append(f"pulse_center must be inside the square [{scene.x_min:g}, {scene.x_max:g}] m (got {xc:g})")
        return out
