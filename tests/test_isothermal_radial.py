"""The radial isothermal Euler reference of the 2D pulse (solvers.reference.isothermal_radial): its own convergence,
its small-Mach limit (the linear open-domain solution), its nonlinearity at Ma = 0.05, and mass."""

from __future__ import annotations

import functools
import time

import numpy as np

from solvers.reference.isothermal_radial import isothermal_pulse_radial, isothermal_pulse_radial_cached
from solvers.reference.pulse2d import open_domain

T, B, RHO0, C0, R_MAX = 10.0, 3.0, 1.0, 1.0, 40.0


def rel_rms(a, b):
    return float(np.sqrt(np.mean((a - b) ** 2) / np.mean(b**2)))


@functools.lru_cache(maxsize=None)
def linear_per_mach(cells_per_m=100, r_lim=20.0):
    """open_domain (drho, u_r) / Ma at t = T on the cell centres below ``r_lim``: the linear solution is
    proportional to Ma."""
    n = int(round(r_lim * cells_per_m))
    r = (np.arange(n) + 0.5) / cells_per_m
    return open_domain(r, T, B, 1.0, RHO0, C0)


def to_coarse(fine, ratio, parity):
    """Cubic interpolation of a cell-centred field to the centres of a grid ``ratio`` (even) times coarser,
    each of which lies midway between two fine centres; ``parity`` +1 (drho) or -1 (u_r) across r = 0."""
    pad = np.concatenate([parity * fine[1::-1], fine, fine[-1:], fine[-1:]])  # pad[p] = fine[p - 2]
    p = ratio * np.arange(len(fine) // ratio) + ratio // 2 + 1  # left neighbour of each coarse centre
    return (-pad[p - 1] + 9.0 * pad[p] + 9.0 * pad[p + 1] - pad[p + 2]) / 16.0


def test_default_call_runtime():
    start = time.perf_counter()
    r, drho, u_r = isothermal_pulse_radial(T, B, 0.05, RHO0, C0, R_MAX)
    elapsed = time.perf_counter() - start
    print(f"isothermal_pulse_radial(t=10, b=3, Ma=0.05, R=40, 100 cells/m): {elapsed:.2f} s")  # 0.4 s here
    assert r.shape == drho.shape == u_r.shape == (4000,)
    assert np.allclose(r[:2], [0.005, 0.015])


def test_second_order_convergence():
    # max errors against 200 cells/m (measured, drho): 1.25e-6, 3.0e-7, 5.9e-8 at 25, 50, 100 cells/m,
    # orders 2.07 and 2.32 (a pure dr^2 error against a 200 cells/m reference gives log2(63/15) = 2.07 and
    # log2(15/3) = 2.32); the same for u_r.
    sols = {c: isothermal_pulse_radial(T, B, 0.05, RHO0, C0, 30.0, cells_per_m=c) for c in (25, 50, 100, 200)}
    _, d_ref, u_ref = sols[200]
    errs = []
    for c in (25, 50, 100):
        _, d, u = sols[c]
        errs.append(
            [np.max(np.abs(d - to_coarse(d_ref, 200 // c, 1.0))), np.max(np.abs(u - to_coarse(u_ref, 200 // c, -1.0)))]
        )
    orders = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    assert np.all(orders >= 1.8), orders
    assert errs[-1][0] < 1e-5 * RHO0 * 0.05  # measured 1.2e-6 rho0 Ma at 100 cells/m


def test_small_mach_is_linear():
    # Ma = 1e-4: relative RMS of drho against open_domain over r < 20 m measured 4.4e-5 (u_r: 5.0e-5),
    # almost all of it the (Ma-proportional) nonlinearity, see the next test
    r, drho, u_r = isothermal_pulse_radial_cached(T, B, 1e-4, RHO0, C0, R_MAX)
    d_lin, u_lin = (1e-4 * f for f in linear_per_mach())
    near = r < 20.0
    assert np.allclose(r[near], (np.arange(2000) + 0.5) / 100.0, rtol=0, atol=1e-12)
    assert rel_rms(drho[near], d_lin) < 1e-3
    assert rel_rms(u_r[near], u_lin) < 1e-3


def test_mach_005_is_nonlinear():
    # Ma = 0.05: relative RMS of drho - drho_linear over r < 20 m measured 2.3e-2 (u_r: 2.6e-2);
    # divided by Ma it is 0.47, against 0.44 at Ma = 1e-4: the difference is the nonlinearity (steepening)
    rel = {}
    for mach in (0.05, 1e-4):
        r, drho, _ = isothermal_pulse_radial_cached(T, B, mach, RHO0, C0, R_MAX)
        rel[mach] = rel_rms(drho[r < 20.0], mach * linear_per_mach()[0])
    assert rel[0.05] > 1e-3
    assert 0.8 < (rel[0.05] / 0.05) / (rel[1e-4] / 1e-4) < 1.25


def test_mass_is_conserved():
    # 2 pi sum r drho dr: measured 4e-16 relative change from t = 0 to 10 s; against the exact
    # rho0 Ma pi b^2/ln2, 6.4e-7 (the midpoint-rule sampling of the initial Gaussian, ~dr^2 ln2/(12 b^2))
    mach = 0.05
    r, drho, _ = isothermal_pulse_radial_cached(T, B, mach, RHO0, C0, R_MAX)
    r0, drho0, u0 = isothermal_pulse_radial(1e-9, B, mach, RHO0, C0, R_MAX)
    dr = r[1] - r[0]
    mass = 2.0 * np.pi * np.sum(r * drho) * dr
    mass0 = 2.0 * np.pi * np.sum(r0 * drho0) * dr
    assert abs(mass / mass0 - 1.0) < 1e-12
    assert abs(mass / (RHO0 * mach * np.pi * B**2 / np.log(2.0)) - 1.0) < 1e-6
    assert np.max(np.abs(u0)) < 1e-9 * mach * C0


def test_cached_call_is_memoised_and_read_only():
    a = isothermal_pulse_radial_cached(T, B, 0.05, RHO0, C0, R_MAX)
    assert isothermal_pulse_radial_cached(T, B, 0.05, RHO0, C0, R_MAX) is a
    assert not any(x.flags.writeable for x in a)
