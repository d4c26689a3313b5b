"""The 3D acoustic pulse: a Gaussian pressure pulse at rest that spreads as a spherical wave.

drho = rho0 Ma exp(-ln2 r^2 / b^2), u = 0 at t = 0, r the distance to the cube's centre, b = ``pulse_width`` (3 m),
in a triply periodic cube (16 m by default, ``--domain-size``), with its periodic images summed (the 27 nearest
copies: the next are below 1e-17 of the peak in a cube of 5 widths), so that the initial field is smooth across
the faces (cut at the faces instead, the 16 m cube's pulse has a kink of 0.7 % of its peak there, which a
fourth-order method cannot resolve: its order fell from 4.5 to 2.5, predicted). Its exact linear reference on
the periodic cube evolves every Fourier mode of the sampled initial field with the exact dispersion w = c0 |k|
(solvers/reference/pulse3d.py: exact to round-off, the waves that wrap included; checked against the open-space
closed form r p = [(r - c0 t) g(r - c0 t) + (r + c0 t) g(r + c0 t)] / 2 while the images are below round-off).

Error measures (the primary field is drho): relative RMS and max error of drho and of the velocity vector over the
cube, and the relative RMS of drho along the lattice's axes through the centre and along its body diagonals,
apart (the lattice's phase error depends on the direction of travel).

With ``--open xyz`` its six faces open onto a sponge layer (solvers/boundaries/absorbers/sponge.py; ``--absorber pml``
the split-field PML, which sends back a quarter of the sponge's energy at the same width): the pulse is alone in open
space (no images), scored against the closed form at the scored sites while it is inside the cube (``rms_drho``),
then by what the faces left behind (``left_energy``, the error's acoustic energy over the initial pulse's, and
``left_amplitude``).
"""

from __future__ import annotations

import math

import numpy as np

from solvers.fields import Fields
from solvers.scenes.base import PULSE_REACH, SceneKind

LN2 = math.log(2.0)
FIT_WIDTHS = 5.0  # the cube's side in pulse widths, at least: the initial pulse below 1.3 % of its peak at a face


def centre(scene) -> tuple[float, float, float]:
    """The pulse's centre (x, y, z), m: ``pulse_center`` in x, the middle of the y and z ranges."""
    return scene.pulse_center, 0.5 * (scene.y_min + scene.y_max), 0.5 * (scene.z_min + scene.z_max)


def _relative(diff, ref) -> float:
    den = float(np.mean(ref**2))
    return float(np.sqrt(np.mean(diff**2) / den)) if den > 0 else float("nan")


def periodic_pulse(scene, x, y, z, xp=np):
    """drho of the pulse centred at :func:`centre` and its 26 nearest periodic images at ``x, y, z`` (m), kg/m^3."""
    sides = (scene.x_max - scene.x_min, scene.y_max - scene.y_min, scene.z_max - scene.z_min)
    out = xp.zeros_like(xp.asarray(x, dtype=float) + 0.0 * y + 0.0 * z)
    for ix in (-1, 0, 1):
        for iy in (-1, 0, 1):
            for iz in (-1, 0, 1):
                c = [c0 + i * side for c0, i, side in zip(centre(scene), (ix, iy, iz), sides)]
                out += xp.exp(-LN2 * ((x - c[0]) ** 2 + (y - c[1]) ** 2 + (z - c[2]) ** 2) / scene.pulse_width**2)
    return scene.rho0 * scene.mach * out


class AcousticPulse3D(SceneKind):
    name = "acoustic-pulse-3d"
    summary = "the 3D acoustic pulse: a Gaussian pressure pulse at rest in a triply periodic cube (--domain-size)"
    dims = 3
    periodic = ("x", "y", "z")
    images = ("x", "y", "z")  # the cube's seams are the open pulse's images: --open xyz opens them
    domain = {"x_min": -8.0, "x_max": 8.0, "y_min": -8.0, "y_max": 8.0, "z_min": -8.0, "z_max": 8.0}
    fields = ("drho", "velocity")
    primary = "drho"
    # a few hundred particles with every seam acting from the first step (the conformance suite, the rehearsal)
    smallest = {
        "dx": 1.0, "pulse_width": 1.5, "pulse_center": 1.0, "h_factor": 1.0,
        "x_min": -4.5, "x_max": 4.5, "y_min": -4.5, "y_max": 4.5, "z_min": -4.5, "z_max": 4.5,
    }  # fmt: skip
    smallest_open = {**smallest, "open": "xyz", "layer_width": 2.0}  # the six faces open onto a sponge
    card = {"dx": 0.25}

    def initial_fields(self, scene, x, y, xp, z=None):
        """(u, v, w, drho) at the lattice positions ``x``, ``y``, ``z`` (m) at t = 0: the pulse and its periodic
        images (:func:`periodic_pulse`), or with open faces the pulse alone."""
        if scene.open:
            xc, yc, zc = centre(scene)
            r2 = (x - xc) ** 2 + (y - yc) ** 2 + (z - zc) ** 2
            drho = scene.rho0 * scene.mach * xp.exp(-LN2 * r2 / scene.pulse_width**2)
        else:
            drho = periodic_pulse(scene, x, y, z, xp)
        zero = xp.zeros_like(drho)
        return zero, zero.copy(), zero.copy(), drho

    def reference(self, scene, t: float):
        """The exact linear solution on the scene's periodic lattice at ``t`` (solvers/reference/pulse3d.py)."""
        from solvers.reference.pulse3d import periodic_linear

        return periodic_linear(
            (scene.nx, scene.ny, scene.nz),
            scene.dx,
            (scene.x_lo, scene.y_lo, scene.z_lo),
            centre(scene),
            scene.pulse_width,
            scene.mach,
            scene.rho0,
            scene.c0,
            t,
            initial=lambda x, y, z: periodic_pulse(scene, x, y, z),
        )

    def exact_fields(self, scene, t: float):

        if scene.open:
            return self.open_fields(scene, t)
        ref = self.reference(scene, t)
        z, y, x = np.meshgrid(ref.z, ref.y, ref.x, indexing="ij")
        return Fields(
            x=x.ravel(), y=y.ravel(), z=z.ravel(), u=ref.u.ravel(), v=ref.v.ravel(), w=ref.w.ravel(),
            drho=ref.drho.ravel(), t=t,
        )  # fmt: skip

    def open_fields(self, scene, t: float):
        """The open-space pulse (the closed form, solvers/reference/pulse3d.py) at the scored domain's sites at
        ``t``, in a run's output order, as Fields."""
        from solvers.reference.pulse3d import open_pulse

        axes = [
            lo + (np.arange(d, n - d) + 0.5) * scene.dx
            for lo, n, d in (
                (scene.x_lo, scene.nx, scene.layer_columns),
                (scene.y_lo, scene.ny, scene.layer_rows),
                (scene.z_lo, scene.nz, scene.layer_depth),
            )
        ]
        z, y, x = (a.ravel() for a in np.meshgrid(axes[2], axes[1], axes[0], indexing="ij"))
        xc, yc, zc = centre(scene)
        p = np.stack([x - xc, y - yc, z - zc])
        r = np.sqrt(np.sum(p**2, axis=0))
        drho, ur = open_pulse(r, t, scene.pulse_width, scene.mach, scene.rho0, scene.c0)
        radial = np.where(r > 0, ur / np.where(r > 0, r, 1.0), 0.0) * p
        return Fields(x=x, y=y, z=z, u=radial[0], v=radial[1], w=radial[2], drho=drho, t=t)

    def pulse_inside(self, scene, t: float) -> bool:
        """The spherical shell (radius c0 t and PULSE_REACH half-widths) has not reached an open face."""
        if not scene.open:
            return True
        xc, yc, zc = centre(scene)
        gaps = (xc - scene.x_min, scene.x_max - xc, yc - scene.y_min, scene.y_max - yc, zc - scene.z_min)
        return scene.c0 * t + PULSE_REACH * scene.pulse_width <= min(*gaps, scene.z_max - zc)

    def left_behind(self, scene, fields, ref) -> dict:
        """What the open faces left: the largest error of drho over the initial peak (``left_amplitude``) and the
        error's acoustic energy over the initial pulse's (``left_energy``), at the scored sites."""
        d = {c: np.asarray(getattr(fields, c), float) - getattr(ref, c) for c in ("drho", "u", "v", "w")}
        start = self.open_fields(scene, 0.0)

        def energy(f):
            kinetic = sum(np.asarray(f[c], float) ** 2 for c in ("u", "v", "w"))
            return float(
                np.mean(0.5 * scene.rho0 * kinetic + 0.5 * scene.c0**2 * np.asarray(f["drho"]) ** 2 / scene.rho0)
            )

        initial = {c: getattr(start, c) for c in ("drho", "u", "v", "w")}
        return {
            "left_amplitude": float(np.max(np.abs(d["drho"])) / (scene.rho0 * scene.mach)),
            "left_energy": energy(d) / energy(initial),
        }

    def errors(self, scene, fields) -> dict:
        """Relative RMS (``mse``) and max error (``me``) of drho, the velocity's, and drho's along the axes and
        the body diagonals through the centre, against the exact solution at the lattice sites (a lagrangian
        run's particles have moved by a Mach number's fraction of dx: scored at their sites too)."""
        ref = self.exact_fields(scene, fields.t)
        d = np.asarray(fields.drho, float) - ref.drho
        du = np.stack([np.asarray(getattr(fields, c), float) - getattr(ref, c) for c in ("u", "v", "w")])
        left = self.left_behind(scene, fields, ref) if scene.open else {}
        if not (np.all(np.isfinite(d)) and np.all(np.isfinite(du))):
            nan = float("nan")
            return {
                **dict.fromkeys(left, nan),
                "mse": nan,
                "me": nan,
                "velocity_rms": nan,
                "velocity_max": nan,
                "axis_rms": nan,
                "diagonal_rms": nan,
            }
        xc, yc, zc = centre(scene)
        p = [ref.x - xc, ref.y - yc, ref.z - zc]
        near = [np.abs(q) < scene.dx for q in p]
        axis = (near[0] & near[1]) | (near[1] & near[2]) | (near[0] & near[2])
        a = [np.abs(q) for q in p]
        diagonal = (np.abs(a[0] - a[1]) < scene.dx) & (np.abs(a[1] - a[2]) < scene.dx)
        speed = np.sqrt(np.sum(du**2, axis=0))
        ref_speed = np.sqrt(ref.u**2 + ref.v**2 + ref.w**2)
        return {
            **left,
            "mse": _relative(d, ref.drho),
            "me": float(np.max(np.abs(d))),
            "velocity_rms": _relative(speed, ref_speed),
            "velocity_max": float(speed.max()),
            "axis_rms": _relative(d[axis], ref.drho[axis]),
            "diagonal_rms": _relative(d[diagonal], ref.drho[diagonal]),
        }

    def predict(self, scene):
        """The `linear` run's exact discrete solution on the cubic lattice (solvers/reference/dispersion3d.py)."""
        from solvers.reference.dispersion3d import predict

        return predict(scene, self)

    def predicted_stable_cfl(self, scene) -> float:
        """The cubic lattice's stable CFL of the scene's method (solvers/reference/dispersion3d.py)."""
        from solvers.reference.dispersion3d import predicted_stable_cfl

        return predicted_stable_cfl(scene)

    def sized_domain(self, size: float) -> dict:
        """A cube of side ``size`` m centred on the origin."""
        half = 0.5 * size
        return {"x_min": -half, "x_max": half, "y_min": -half, "y_max": half, "z_min": -half, "z_max": half}

    def tiny(self, scene):
        """A cube of three cutoffs at dx 1 and h = dx (a few thousand particles at most) with the scene's kernel,
        integrator, model and precision, for the JIT warm-up."""
        side = max(6.0, math.ceil(3.0 * scene.cutoff_ratio(scene.kernel, scene.cutoff_factor)))
        return scene.replace(
            dx=1.0, **self.sized_domain(side), pulse_center=0.0, pulse_width=1.0, steps=2, t_end=None, h_factor=1.0
        )

    def check(self, scene) -> list[str]:
        out = super().check(scene)
        side = min(scene.x_max - scene.x_min, scene.y_max - scene.y_min, scene.z_max - scene.z_min)
        if not side >= FIT_WIDTHS * scene.pulse_width:
            out.append(
                f"--domain-size must be at least {FIT_WIDTHS:g} pulse widths ({FIT_WIDTHS * scene.pulse_width:g} m) "
                f"so that the pulse fits in the cube (got {side:g} m)"
            )
        return out
