"""Radially symmetric isothermal (nonlinear) Euler solution of the 2D acoustic pulse.

With rho = rho0 + drho and p = c0^2 rho, a radially symmetric flow in the plane obeys

    d(rho)/dt   + (1/r) d(r rho u)/dr                    = 0,
    d(rho u)/dt + (1/r) d(r rho u^2)/dr + c0^2 d(rho)/dr = 0,

here from the CAA pulse at rest: drho = rho0 Ma exp(-ln2 r^2/b^2), u = 0. It is what a Lagrangian
scheme with rho = rho0 + drho in its coefficients converges to in 2D (the 2D analogue of
`solvers.reference.isothermal1d`), and at small Ma it tends to the linear `solvers.reference.pulse2d.open_domain`.

Scheme: two-step Lax-Wendroff (Richtmyer), second order, no artificial viscosity (the pulse stays smooth:
a Mach 0.05, b = 3 m pulse steepens into a shock far later than the times used here). Cell centres
r_i = (i + 0.5) dr on (0, r_max]; the mass equation is in conservative, r-weighted form (cell area
2 pi r_i dr), so the discrete mass 2 pi sum r_i drho_i dr is conserved to rounding; at r = 0 the flux
vanishes (symmetry: drho even, u odd); the last cell is held at rest (r_max must exceed the reach
c0 t + ~4 b of the pulse).
"""

from __future__ import annotations

import functools

import numpy as np

LN2 = float(np.log(2.0))


def isothermal_pulse_radial(
    t: float, b: float, mach: float, rho0: float, c0: float, r_max: float, cells_per_m: float = 100.0, cfl: float = 0.8
):
    """(r, drho, u_r) at time ``t`` (s): cell centres r_i = (i + 0.5) dr of (0, r_max], m; kg/m^3; m/s.

    ``b``: pulse half-width, m; ``mach``: Ma; ``rho0``: kg/m^3; ``c0``: m/s; ``cells_per_m``: 1/dr, 1/m;
    ``cfl``: dt (c0 (1 + 2 Ma)) / dr (<= 1 for stability; steps are rounded up to land on ``t``).
    """
    n = int(round(r_max * cells_per_m))
    dr = r_max / n
    r = (np.arange(n) + 0.5) * dr
    rf = np.arange(1, n) * dr  # interior faces r_(i+1/2), i = 0 .. n-2
    d = rho0 * mach * np.exp(-LN2 * r**2 / b**2)  # drho, point values at the centres
    m = np.zeros(n)  # rho u
    c2 = c0 * c0
    steps = max(1, int(np.ceil(t * c0 * (1.0 + 2.0 * mach) / (cfl * dr))))
    dt = t / steps
    inv_rf = 1.0 / (rf * dr)
    inv_rc = 1.0 / (r[:-1] * dr)  # updated cells 0 .. n-2 (the last stays at rest)
    fd = np.zeros(n)  # face values: index k is face r = k dr, k = 0 .. n-1
    fm = np.zeros(n)
    for _ in range(steps):
        rm = r * m
        rg = rm * m / (rho0 + d)  # r rho u^2
        # predictor: faces at t + dt/2
        fd[1:] = 0.5 * (d[1:] + d[:-1]) - 0.5 * dt * inv_rf * (rm[1:] - rm[:-1])
        fm[1:] = 0.5 * (m[1:] + m[:-1]) - 0.5 * dt * (inv_rf * (rg[1:] - rg[:-1]) + c2 * (d[1:] - d[:-1]) / dr)
        fd[0] = d[0] - 0.5 * dt * 4.0 * m[0] / dr  # axis: (1/r) d(r m)/dr -> 2 dm/dr, m odd; u = 0 there
        # corrector with the face fluxes
        frm = np.arange(n) * dr * fm  # r m at the faces (0 at the axis)
        frg = frm * fm / (rho0 + fd)
        d[:-1] -= dt * inv_rc * (frm[1:] - frm[:-1])
        m[:-1] -= dt * (inv_rc * (frg[1:] - frg[:-1]) + c2 * (fd[1:] - fd[:-1]) / dr)
    return r, d, m / (rho0 + d)


@functools.lru_cache(maxsize=16)
def isothermal_pulse_radial_cached(
    t: float, b: float, mach: float, rho0: float, c0: float, r_max: float, cells_per_m: float = 100.0, cfl: float = 0.8
):
    """`isothermal_pulse_radial`, memoised on its scalar arguments; the arrays returned are read-only."""
    out = isothermal_pulse_radial(t, b, mach, rho0, c0, r_max, cells_per_m=cells_per_m, cfl=cfl)
    for a in out:
        a.flags.writeable = False
    return out
