"""A Gaussian pulse scattered by a rigid sphere: the 3D analogue of the CAA workshop's cylinder.

A sphere of radius a = ``sphere_radius`` (0.5 m) at the origin, the Gaussian pulse
drho = rho0 Ma exp(-ln2 ((x - xp)^2 + y^2 + z^2) / b^2) at rest at (xp, 0, 0) = (``pulse_center``, 0, 0) =
(1.5, 0, 0) m with b = ``pulse_width`` = 0.4 m, c0 = 1 m/s, in open space: the cube [-2.25, 2.25]^3 m with its six
faces open (the split-field PML beyond each, solvers/boundaries/absorbers/pml.py, by default, as every 3D scene's since
2026-12-07: its parts of the continuity rate summed in the rate's own pass; ``--absorber sponge`` sends back from
the +x and +y faces into A's window, docs/accuracy.md). The sphere's
wall is the weak one (solvers/boundaries/bodies/weak.py: the body's sites carry no volume, the gradient-corrected
operators make the wall), which needs ``--correction gradient``. The pulse's flank reaches the sphere at t = 0 (1.3 %
of its peak at the surface): the fluid's data is the Gaussian cut at the wall, as the exact reference's
(solvers/reference/sphere.py: the exterior Neumann series in spherical Bessel functions and Legendre polynomials
for the scattered part and the part cut away, the closed form for the free pulse).

Observed as the cylinder's: p = c0^2 drho at A (0, 1.5, 0), B (-1.0607, 1.0607, 0) and C (-1.5, 0, 0) over
1.5 <= t <= 4 s (``--probe x,y,z`` adds points), their relative RMS over the window the headline (``probes_p``).
The field's own error is not scored (its series at every particle would take minutes): before the window the run
has no headline error. Predicted (``accuracy``, ``advise``) by the series with the method's dispersion, the wall
exact (solvers/reference/dispersive_sphere.py): the bulk's share of a run's error.
"""

from __future__ import annotations

import math

import numpy as np

from solvers.scenes.base import PULSE_WIDTH_RANGE, SceneKind, window_probe_errors

LN2 = math.log(2.0)
PROBES = {"A": (0.0, 1.5, 0.0), "B": (-1.0607, 1.0607, 0.0), "C": (-1.5, 0.0, 0.0)}  # m
WINDOW = (1.5, 4.0)  # the probes' window, s
EDGE_WIDTHS = 1.5  # the pulse's centre keeps 1.5 widths from the cube's faces (the layer beyond takes the rest)


class Sphere(SceneKind):
    name = "sphere"
    summary = (
        "a Gaussian pulse scattered by a rigid sphere (radius 0.5 m at the origin) in open space, 3D; its wall the "
        "weak one (--correction gradient)"
    )
    dims = 3
    periodic = ("x", "y", "z")
    images = ("x", "y", "z")  # open: the cube's faces are open space's (always open here)
    domain = {"x_min": -2.25, "x_max": 2.25, "y_min": -2.25, "y_max": 2.25, "z_min": -2.25, "z_max": 2.25}
    defaults = {"pulse_width": 0.4, "pulse_center": 1.5, "sphere_radius": 0.5, "open": "xyz"}
    fields = ("drho",)
    primary = "drho"
    body = True
    window = WINDOW
    t_end = WINDOW[1]  # the probes' window's end
    # the sphere and the pulse in a small box, a corrected Wendland C2 (the conformance suite's 3D body: 13,068
    # particles with the layer, the pulse's flank at the wall from the first step; room for the Gaussian's 3 h)
    smallest = {
        "dx": 0.125, "sphere_radius": 0.5, "pulse_width": 0.4, "pulse_center": 1.0,
        "x_min": -1.0, "x_max": 1.625, "y_min": -1.0, "y_max": 1.0, "z_min": -1.0, "z_max": 1.0,
        "kernel": "wendland-c2", "h_factor": 1.3, "correction": "gradient", "layer_width": 0.375,
    }  # fmt: skip
    card = {"dx": 0.1}

    def body_of(self, scene) -> tuple:
        return 0.0, 0.0, float(scene.sphere_radius)

    def sized_domain(self, size: float) -> dict:
        """A cube of side ``size`` m centred on the sphere (``--domain-size``; the layer beyond its faces)."""
        half = 0.5 * size
        return {"x_min": -half, "x_max": half, "y_min": -half, "y_max": half, "z_min": -half, "z_max": half}

    def headline(self, t_end: float) -> str:
        start, end = self.window
        if t_end < start:
            return super().headline(t_end)
        return f"relative RMS error of p at the probes over {start:g} <= t <= {min(t_end, end):g} s"

    def measure(self, scene, t: float) -> str:
        return "probes_p" if t >= self.window[0] else super().measure(scene, t)

    def probe_points(self, scene) -> dict:
        return dict(PROBES)

    def probe_errors(self, scene, probes) -> dict:
        """The probes' errors over the window 1.5 <= t <= 4 s (:func:`window_probe_errors`) against the exact
        series (solvers/reference/sphere.py)."""
        from solvers.reference.sphere import scene_drho

        points = scene.probe_points()

        def exact(names, times):
            return scene_drho(scene, [points[k] for k in names], times)

        return window_probe_errors(scene, probes, WINDOW, exact)

    def check(self, scene) -> list[str]:
        out = super().check(scene)
        a, b = scene.sphere_radius, scene.pulse_width
        if scene.open != "xyz":
            out.append(
                f"--open: the sphere scene is sound in open space, its six faces are always open (--open xyz; got "
                f"{scene.open!r})"
            )
        if not (isinstance(a, (int, float)) and math.isfinite(a) and a > 0):
            out.append(f"--sphere-radius must be > 0 m (got {a!r})")
            return out
        room = min(-scene.x_min, scene.x_max, -scene.y_min, scene.y_max, -scene.z_min, scene.z_max)
        if a + scene.cutoff > room:
            out.append(
                f"--sphere-radius {a:g}: the sphere (at the origin) and a cutoff about it ({scene.cutoff:.3g} m) must "
                f"lie inside the cube (its nearest face {room:g} m from the centre)"
            )
        if scene.pulse_center - a < b:
            out.append(
                f"--pulse-center: the pulse's centre must be at least a pulse width ({b:g} m) outside the sphere, "
                f"x >= {a + b:.4g} m (got {scene.pulse_center:g})"
            )
        if scene.pulse_center > scene.x_max - EDGE_WIDTHS * b:
            out.append(
                f"--pulse-center: the pulse must be inside the cube, {EDGE_WIDTHS:g} pulse widths from its faces: "
                f"at most {scene.x_max - EDGE_WIDTHS * b:.4g} m (got {scene.pulse_center:g})"
            )
        if scene.dx > 0.25 * a:
            out.append(f"--dx must be at most a quarter of the sphere's radius, {0.25 * a:g} m (got {scene.dx:g})")
        return out

    def initial_fields(self, scene, x, y, xp, z=None):
        """(u, v, w, drho) at t = 0: the pulse at rest (the body's sites zeroed by the body, solvers/boundaries/)."""
        r2 = (x - scene.pulse_center) ** 2 + y**2 + z**2
        drho = scene.rho0 * scene.mach * xp.exp(-LN2 * r2 / scene.pulse_width**2)
        zero = xp.zeros_like(drho)
        return zero, zero.copy(), zero.copy(), drho

    def errors(self, scene, fields) -> dict:
        """The probes' relative RMS over the window as the headline (``mse``; ``me`` the largest error of drho
        there), where the run recorded readings in it; before the window none (NaN) and ``me`` the fluid's largest
        |drho| (kg/m^3, finite: a run that went wrong is not ok)."""
        probes = self.probe_errors(scene, fields.probes) if fields.probes else {}
        worst = probes.pop("probe_max", float("nan"))
        out = dict(probes)
        if math.isfinite(probes.get("probe_rms", float("nan"))):
            out["mse"], out["me"] = probes["probe_rms"], worst
        else:
            drho = np.asarray(fields.drho, dtype=np.float64)
            out["mse"], out["me"] = float("nan"), float(np.max(np.abs(drho), initial=0.0))
        return out

    def predicted_stable_cfl(self, scene) -> float:
        """The cubic lattice's stable CFL of the scene's method (solvers/reference/dispersion3d.py)."""
        from solvers.reference.dispersion3d import predicted_stable_cfl

        return predicted_stable_cfl(scene)

    def predict(self, scene):
        """The probes' errors the bulk's dispersion alone would give, the wall exact
        (solvers/reference/dispersive_sphere.py)."""
        from solvers.reference.dispersive_sphere import predict_sphere

        return predict_sphere(scene)

    def tiny(self, scene):
        """A small cube with the body, for the warm-up: a few thousand particles."""
        a = scene.sphere_radius
        width = max(PULSE_WIDTH_RANGE[0], 0.8 * a)
        half = a + 3.0 * width
        return scene.replace(
            dx=0.25 * a,
            x_min=-half,
            x_max=half,
            y_min=-half,
            y_max=half,
            z_min=-half,
            z_max=half,
            pulse_center=a + width,
            pulse_width=width,
            layer_width=None,
            steps=2,
            t_end=None,
            mach=scene.default("mach"),
            h_factor=min(scene.h_factor, 1.3),
            cutoff_factor=min(scene.cutoff_factor, 3.0),
        )
