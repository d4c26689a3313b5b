"""Reference solution of what the `lagrangian` model converges to.

The paper's scheme with moving particles and rho = rho0 + drho in the
coefficients solves the 1D isothermal Euler equations
    d(rho)/dt + d(rho u)/dx = 0,  d(rho u)/dt + d(rho u^2 + c0^2 rho)/dx = 0,
not the linear wave equation. This solves them on a fine grid with the
two-step Lax-Wendroff (Richtmyer) scheme, second order, which is accurate for
the smooth pulse (a Mach 0.05 pulse of width 3 m steepens into a shock only
after about 70 s).
"""

from __future__ import annotations

import numpy as np


def isothermal_pulse(scene, t_end: float, cells_per_m: int = 200, cfl: float = 0.5):
    """(x, u) of the isothermal solution at ``t_end`` for ``scene``'s pulse, on a uniform grid."""
    n = int(round((scene.x_max - scene.x_min) * cells_per_m))
    dx = (scene.x_max - scene.x_min) / n
    x = scene.x_min + (np.arange(n) + 0.5) * dx
    xi = (x - scene.pulse_center) / scene.pulse_width
    u = scene.c0 * scene.mach * np.exp(-xi * xi)
    rho = scene.rho0 + scene.rho0 * u / scene.c0
    q = np.stack([rho, rho * u])
    c2 = scene.c0**2

    def flux(q):
        return np.stack([q[1], q[1] ** 2 / q[0] + c2 * q[0]])

    steps = int(np.ceil(t_end / (cfl * dx / scene.c0)))
    dt = t_end / steps
    for _ in range(steps):
        f = flux(q)
        half = 0.5 * (q[:, 1:] + q[:, :-1]) - 0.5 * dt / dx * (f[:, 1:] - f[:, :-1])
        fh = flux(half)
        q[:, 1:-1] -= dt / dx * (fh[:, 1:] - fh[:, :-1])  # edge cells stay at rest
    return x, q[1] / q[0]


def isothermal_errors(scene, x, u, t, cells_per_m: int = 100):
    """Eq. 11 of ``u`` (at positions ``x``) against the isothermal solution at ``t``: what the `lagrangian`
    model's error is measured against, its own limit (100 cells per m: the reference's own error is far
    below the runs')."""
    from solvers.reference.analytic import relative_errors

    x_ref, u_ref = isothermal_pulse(scene, t, cells_per_m=cells_per_m)
    return relative_errors(u, np.interp(x, x_ref, u_ref))
