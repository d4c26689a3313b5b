"""The paper's analytic pulse (eq. 10) and error measures (eq. 11).

u(t, x) = c0 Ma exp(-((x - x_c - c0 t) / w)^2), v = 0, drho = rho0 u / c0:
a right-travelling solution of the linear wave equation.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


def pulse_velocity(scene, x, t):
    """Analytic x-velocity at positions ``x`` (m) and time ``t`` (s), m/s."""
    x = np.asarray(x, dtype=np.float64)
    xi = (x - scene.pulse_center - scene.c0 * t) / scene.pulse_width
    return scene.c0 * scene.mach * np.exp(-xi * xi)


@dataclass(frozen=True)
class Errors:
    """Relative RMS error (the paper's "MSE") and max error ME (m/s) of u."""

    mse: float
    me: float


QUIET = 1e-6  # a reference whose RMS is below this fraction of its pulse's amplitude holds no pulse


def errors(scene, x, u, t) -> Errors:
    """Paper eq. 11 over all particles: sqrt(mean((u-u_the)^2)/mean(u_the^2)), max|u-u_the|."""
    return relative_errors(u, pulse_velocity(scene, x, t), amplitude=scene.mach * scene.c0)


def relative_errors(u, u_the, amplitude: float = 0.0) -> Errors:
    """Eq. 11 of ``u`` against any reference ``u_the`` at the same points. The relative error is NaN (undefined,
    stored as null) where the reference holds no pulse: its RMS below :data:`QUIET` of ``amplitude`` (the
    pulse's peak in the same unit), as once a pulse has left the domain by a free end, where dividing by its
    tail's 1e-60 made errors of 1e26."""
    diff = np.asarray(u, dtype=np.float64) - u_the
    if not np.all(np.isfinite(diff)):
        return Errors(float("nan"), float("nan"))
    scale = float(np.mean(np.square(u_the)))
    mse = float(np.sqrt(np.mean(diff**2) / scale)) if scale > (QUIET * amplitude) ** 2 else float("nan")
    return Errors(mse, float(np.max(np.abs(diff))))
