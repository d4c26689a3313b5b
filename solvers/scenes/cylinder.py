"""The CAA workshop's pulse scattered by a rigid circular cylinder (Second CAA Workshop, category 1, problem 2).

A cylinder of radius a = ``cylinder_radius`` (0.5 m) with its axis at the origin, the Gaussian pulse
drho = rho0 Ma exp(-ln2 ((x - xp)^2 + y^2) / b^2) at rest at (xp, 0) = (``pulse_center``, 0) = (4, 0) m with
b = ``pulse_width`` = 0.2 m, c0 = 1 m/s, in the open plane: the square [-6, 6]^2 m with its four edges open
(an absorbing layer beyond each: the scene is an open problem, its edges are always open). The cylinder's wall
is modelled by a boundary method (``boundary_method``, solvers/boundaries/bodies/). The exact linear reference is the
series solution (solvers/reference/cylinder.py: the free pulse plus the scattered field).

The workshop observes p = c0^2 drho at A (r = 5 m, 90 deg), B (5 m, 135 deg) and C (5 m, 180 deg) over
6 <= t <= 10 s. Error measures (the primary field is drho, over the fluid of the scored domain): the relative
RMS and max error, and apart the RMS near the body (the fluid within 3 cutoffs of its surface, ``near_rms``)
and away from it (``far_rms``), each over the RMS of the reference over the whole fluid (their squares,
weighted by each band's share of the particles, add up to the whole's square); of the near band's, the part at the
lattice's own scale apart (``near_grid_rms``: the error less its Gaussian low-pass of width dx, wavelengths of a
few dx that no acoustic wave of the scene has).
"""

from __future__ import annotations

import math

import numpy as np

from solvers.fields import Fields
from solvers.scenes.base import PULSE_WIDTH_RANGE, SceneKind, window_probe_errors

LN2 = math.log(2.0)
NEAR_CUTOFFS = 3.0  # the near-body band: the fluid within this many cutoffs of the surface
CLEAR_WIDTHS = 4.5  # the pulse's edge: exp(-ln2 4.5^2) = 8e-7 of its peak; the body keeps clear of it
EDGE_WIDTHS = 3.0  # the domain's edges keep 3 widths from the pulse's centre (2e-3 of its peak; the layer beyond)
PROBES = {"A": (5.0, 90.0), "B": (5.0, 135.0), "C": (5.0, 180.0)}  # the workshop's points: r (m), angle (deg)
WINDOW = (6.0, 10.0)  # the workshop's window of p(t) at the probes, s
SMOOTH_DX = 1.0  # the low-pass that parts the near band's error: exp(-(k w)^2 / 2), w this many dx


def grid_scale_part(x, y, d, dx: float) -> np.ndarray:
    """The part of the error ``d`` at the points (x, y) (m; lattice sites, or particles within a fraction of dx of
    them) at the lattice's own scale: d less its Gaussian low-pass of width ``SMOOTH_DX`` dx, taken on the lattice
    by FFT (each point binned to its nearest site; sites without a point, the body's inside, count as zero)."""
    ix = np.rint((x - x.min()) / dx).astype(int)
    iy = np.rint((y - y.min()) / dx).astype(int)
    grid = np.zeros((iy.max() + 1, ix.max() + 1))
    grid[iy, ix] = d
    kx = 2.0 * np.pi * np.fft.rfftfreq(grid.shape[1])
    ky = 2.0 * np.pi * np.fft.fftfreq(grid.shape[0])
    low = np.fft.irfft2(
        np.fft.rfft2(grid) * np.exp(-(kx[None, :] ** 2 + ky[:, None] ** 2) * SMOOTH_DX**2 / 2.0), s=grid.shape
    )
    return d - low[iy, ix]


def probe_points(scene) -> dict:
    """{name: (x, y)} of the workshop's observation points about the body's axis, m."""
    x0, y0, _a = scene.body
    return {
        name: (x0 + r * math.cos(math.radians(deg)), y0 + r * math.sin(math.radians(deg)))
        for name, (r, deg) in PROBES.items()
    }


class Cylinder(SceneKind):
    name = "cylinder"
    summary = (
        "the CAA workshop's pulse scattered by a rigid cylinder (radius 0.5 m at the origin) in the open plane; "
        "--boundary-method models its wall"
    )
    periodic = ("x", "y")
    images = ("x", "y")  # open: the square's edges are the open plane's (always open here)
    domain = {"x_min": -6.0, "x_max": 6.0, "y_min": -6.0, "y_max": 6.0}
    defaults = {"pulse_width": 0.2, "pulse_center": 4.0, "cylinder_radius": 0.5, "open": "xy"}
    fields = ("drho",)
    primary = "drho"
    body = True
    window = WINDOW  # s: where the probes are scored
    # a rigid cylinder with its ghost particles (solvers/boundaries/bodies/: the default boundary method), the pulse's
    # flank at its wall from the first step (a solver that skips the ghosts' values, Solver.prepare_boundaries, fails
    # agreement):
    # the body and the pulse with 3 widths about it (1,376 particles with the layer)
    smallest = {
        "dx": 0.125,
        "x_min": -1.375,
        "x_max": 2.75,
        "y_min": -1.375,
        "y_max": 1.375,
        "pulse_width": 0.3,
        "pulse_center": 1.85,
    }
    card = {"dx": 0.04}  # the workshop's cylinder at 5 particles a pulse width (102,400 particles)

    def body_of(self, scene) -> tuple:
        return 0.0, 0.0, float(scene.cylinder_radius)

    def headline(self, t_end: float) -> str:
        start, end = self.window
        if t_end < start:  # no reading in the window: the field's at the end (errors)
            return super().headline(t_end)
        return f"relative RMS error of p at the probes over {start:g} <= t <= {min(t_end, end):g} s"

    def measure(self, scene, t: float) -> str:
        """The workshop's measure, p at the probes over the window (``probes_p``), once the run reaches it."""
        return "probes_p" if t >= self.window[0] else super().measure(scene, t)

    def probe_points(self, scene) -> dict:
        return probe_points(scene)

    def probe_errors(self, scene, probes) -> dict:
        """The probes' errors over the workshop's window 6 <= t <= 10 s (:func:`window_probe_errors`) against the
        series solution."""
        points = scene.probe_points()

        def exact(names, times):
            ref = self.reference(scene, float(times.max()))
            return [ref.drho(np.array([points[k][0]]), np.array([points[k][1]]), times)[:, 0] for k in names]

        return window_probe_errors(scene, probes, WINDOW, exact)

    def check(self, scene) -> list[str]:
        out = super().check(scene)
        a, b = scene.cylinder_radius, scene.pulse_width
        if scene.open != "xy":
            out.append(
                f"--open: the cylinder scene is sound in the open plane, its four edges are always open "
                f"(--open xy; got {scene.open!r})"
            )
        if not (isinstance(a, (int, float)) and math.isfinite(a) and a > 0):
            out.append(f"--cylinder-radius must be > 0 m (got {a!r})")
            return out
        room = min(-scene.x_min, scene.x_max, -scene.y_min, scene.y_max)  # from the axis to the nearest edge, m
        domain = f"[{scene.x_min:g}, {scene.x_max:g}] x [{scene.y_min:g}, {scene.y_max:g}] m"
        if a >= room:
            out.append(f"--cylinder-radius {a:g}: the cylinder (at the origin) must lie inside the domain {domain}")
        elif a + scene.cutoff > room:  # the body fits; the kernel's cutoff about it, set by --dx, does not
            per_dx = scene.cutoff / scene.dx
            out.append(
                f"--dx {scene.dx:g} with --cylinder-radius {a:g}: the cutoff ({scene.cutoff:.3g} m = {per_dx:.3g} dx: "
                f"--h-factor, --cutoff) about the cylinder reaches past the domain {domain}: --dx at most "
                f"{(room - a) / per_dx:.3g} m here, or a smaller radius"
            )
        gap = abs(scene.pulse_center) - a
        if gap < CLEAR_WIDTHS * b:
            out.append(
                f"--pulse-center: the pulse overlaps the cylinder: its centre must be at least "
                f"{CLEAR_WIDTHS:g} pulse widths ({CLEAR_WIDTHS * b:.3g} m) from the surface, |x| >= "
                f"{a + CLEAR_WIDTHS * b:.4g} m (got {scene.pulse_center:g})"
            )
        if not scene.x_min + EDGE_WIDTHS * b <= scene.pulse_center <= scene.x_max - EDGE_WIDTHS * b:
            out.append(
                f"--pulse-center: the pulse must be inside the domain, {EDGE_WIDTHS:g} pulse widths from its "
                f"edges: in [{scene.x_min + EDGE_WIDTHS * b:.4g}, {scene.x_max - EDGE_WIDTHS * b:.4g}] m "
                f"(got {scene.pulse_center:g})"
            )
        if scene.dx > 0.25 * a:
            out.append(
                f"--dx must be at most a quarter of the cylinder's radius, {0.25 * a:g} m, for its wall to hold "
                f"particles (got {scene.dx:g})"
            )
        return out

    def initial_fields(self, scene, x, y, xp):
        r2 = (x - scene.pulse_center) ** 2 + y**2
        drho = scene.rho0 * scene.mach * xp.exp(-LN2 * r2 / scene.pulse_width**2)
        zero = xp.zeros_like(drho)
        return zero, zero.copy(), drho

    def reference(self, scene, t_max: float | None = None, factor=None):
        """The exact linear solution (solvers/reference/cylinder.CylinderPulse) for this scene, up to ``t_max``;
        with ``factor``, each wavenumber's evolution from rest in place of cos(c0 k t) (the prediction's)."""
        from solvers.reference.cylinder import CylinderPulse

        x0, y0, a = scene.body
        corner = max(math.hypot(x - x0, y - y0) for x in (scene.x_min, scene.x_max) for y in (scene.y_min, scene.y_max))
        return CylinderPulse(
            a,
            scene.pulse_width,
            scene.pulse_center,
            0.0,
            scene.rho0 * scene.mach,
            scene.c0,
            x0,
            y0,
            t_max=max(t_max if t_max is not None else scene.t_final, 1e-9),
            r_max=corner + 2 * scene.cutoff,
            factor=factor,
        )

    def fluid(self, scene, fields):
        """Which of a run's output points are fluid: outside the body."""
        x0, y0, a = scene.body
        return np.hypot(np.asarray(fields.x) - x0, np.asarray(fields.y) - y0) >= a

    def errors(self, scene, fields) -> dict:
        """The workshop's measure as the headline (``mse``, ``me``): p at the probes over the window against the
        exact solution (``probe_rms``; ``me`` the largest error of drho there), where the run recorded readings in
        it; else (a run that ends before t = 6 s) the field's at its end. The field's relative RMS at the end
        (``field_rms``), near the body and away from it, apart, always."""
        x0, y0, a = scene.body
        keep = self.fluid(scene, fields)
        x, y = np.asarray(fields.x)[keep], np.asarray(fields.y)[keep]
        drho = np.asarray(fields.drho, float)[keep]
        ref = self.reference(scene).field(x, y, fields.t)
        d = drho - ref
        nan = float("nan")
        if not np.all(np.isfinite(d)):
            return {"mse": nan, "me": nan, "field_rms": nan, "near_rms": nan, "near_grid_rms": nan, "far_rms": nan}
        scale = float(np.mean(ref**2))
        near = np.hypot(x - x0, y - y0) < a + NEAR_CUTOFFS * scene.cutoff
        n = d.size
        out = {
            "field_rms": float(np.sqrt(np.mean(d**2) / scale)),
            "near_rms": float(np.sqrt(np.sum(d[near] ** 2) / max(near.sum(), 1) / scale)),
            "near_grid_rms": float(
                np.sqrt(np.sum(grid_scale_part(x, y, d, scene.dx)[near] ** 2) / max(near.sum(), 1) / scale)
            ),
            "far_rms": float(np.sqrt(np.sum(d[~near] ** 2) / max(n - near.sum(), 1) / scale)),
        }
        probes = self.probe_errors(scene, fields.probes) if fields.probes else {}
        worst = probes.pop("probe_max", nan)
        out.update(probes)
        if np.isfinite(probes.get("probe_rms", nan)):  # the workshop's measure: the headline
            out["mse"], out["me"] = probes["probe_rms"], worst
        else:
            out["mse"], out["me"] = out["field_rms"], float(np.max(np.abs(d)))
        return out

    def lattice_sites(self, scene) -> tuple[np.ndarray, np.ndarray]:
        """(x, y) of the scored domain's lattice sites, row by row, m (the body's inside included)."""
        nx, ny = scene.nx - 2 * scene.layer_columns, scene.ny - 2 * scene.layer_rows
        x = scene.x_min + (np.arange(nx) + 0.5) * scene.dx
        y = scene.y_min + (np.arange(ny) + 0.5) * scene.dx
        gx, gy = np.meshgrid(x, y)
        return gx.ravel(), gy.ravel()

    def exact_fields(self, scene, t: float):

        gx, gy = self.lattice_sites(scene)
        drho = self.reference(scene, t).field(gx, gy, t)
        zero = np.zeros_like(drho)
        return Fields(x=gx, y=gy, u=zero, v=zero.copy(), drho=np.nan_to_num(drho), t=t)

    def predict(self, scene):
        """The errors the bulk's dispersion alone would give, the wall exact
        (solvers/reference/dispersive_cylinder.py)."""
        from solvers.reference.dispersive_cylinder import predict_cylinder

        return predict_cylinder(scene)

    def predict_headline(self, scene):
        """The probes' predicted error alone (seconds at any dx: no field of the lattice)."""
        from solvers.reference.dispersive_cylinder import predict_cylinder

        return predict_cylinder(scene, field=False)

    def tiny(self, scene):
        """A small square with the body, for the warm-up: a few thousand particles."""
        a = scene.cylinder_radius
        width = max(PULSE_WIDTH_RANGE[0], 0.4 * a)
        centre = a + CLEAR_WIDTHS * width + 0.2 * a
        half = centre + CLEAR_WIDTHS * width + 0.2 * a
        return scene.replace(
            dx=0.25 * a,
            x_min=-half,
            x_max=half,
            y_min=-half,
            y_max=half,
            pulse_center=centre,
            pulse_width=width,
            layer_width=None,
            steps=2,
            t_end=None,
            mach=scene.default("mach"),
            h_factor=scene.default("h_factor"),
            cutoff_factor=min(scene.cutoff_factor, 3.0),
        )
