"""The exact linear solution of the 3D acoustic pulse: a Gaussian pressure pulse at rest that spreads as a spherical
wave.

drho(r, 0) = A exp(-ln2 r^2 / b^2) (A = rho0 Ma, b the half-width, m), u = 0. In open space the radial wave
equation's solution is d'Alembert's for r p (p = c0^2 drho):

    r p(r, t) = [F(r - c0 t) + F(r + c0 t)] / 2,   F(s) = s p0(s)   (odd, p0 even),

and the radial velocity follows from the potential phi (p = -rho0 phi_t, u = grad phi) with
r phi = [H(r - c0 t) - H(r + c0 t)] / (2 rho0 c0), H' = F:

    u_r = [F(r - c0 t) - F(r + c0 t)] / (2 rho0 c0 r) - [H(r - c0 t) - H(r + c0 t)] / (2 rho0 c0 r^2),

both finite at r = 0 (their limits: p(0, t) = F'(c0 t), u_r = 0). On a triply periodic cube the solution is the
sum over the periodic images; :func:`periodic_linear` gives it on the lattice by evolving every Fourier mode of the
sampled initial field with the exact dispersion w = c0 |k| (exact to round-off, wrapped waves included; checked
against :func:`open_pulse` while the images are below round-off, tests/test_pulse3d.py).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

LN2 = math.log(2.0)
NEAR_CENTRE = 1e-4  # r / b below which p and u_r take their limits at r = 0 (the closed form cancels there)


def _F(s, amplitude: float, width: float):
    """F(s) = s p0(s) / c0^2 (in drho units, kg/m^2)."""
    return s * amplitude * np.exp(-LN2 * s * s / width**2)


def _H(s, amplitude: float, width: float):
    """H(s) = int F ds (in drho units, kg/m)."""
    return -amplitude * width**2 / (2.0 * LN2) * np.exp(-LN2 * s * s / width**2)


def open_pulse(r, t: float, width: float, mach: float, rho0: float = 1.0, c0: float = 1.0) -> tuple:
    """(drho, u_r): the open-space pulse at distances ``r`` (m) from its centre at ``t`` (s): kg/m^3 and m/s."""
    r = np.abs(np.asarray(r, dtype=np.float64))
    a, ct = rho0 * mach, c0 * t
    near = r < NEAR_CENTRE * width
    rs = np.where(near, 1.0, r)  # the closed form away from the centre, its limit at it
    lo, hi = rs - ct, rs + ct
    drho = (_F(lo, a, width) + _F(hi, a, width)) / (2.0 * rs)
    u = (
        c0
        / rho0
        * ((_F(lo, a, width) - _F(hi, a, width)) / (2.0 * rs) - (_H(lo, a, width) - _H(hi, a, width)) / (2.0 * rs * rs))
    )
    centre = a * np.exp(-LN2 * ct * ct / width**2) * (1.0 - 2.0 * LN2 * ct * ct / width**2)  # F'(c0 t)
    return np.where(near, centre, drho), np.where(near, 0.0, u)


@dataclass
class Lattice3D:
    """A field on the lattice x_lo + (i + 1/2) dx (and y, z likewise): drho (kg/m^3) and the velocity (u, v, w)
    (m/s) as (nz, ny, nx) arrays, with the axes' coordinates (m)."""

    x: np.ndarray
    y: np.ndarray
    z: np.ndarray
    drho: np.ndarray
    u: np.ndarray
    v: np.ndarray
    w: np.ndarray


def periodic_linear(
    n: tuple,
    dx: float,
    lo: tuple,
    centre: tuple,
    width: float,
    mach: float,
    rho0: float,
    c0: float,
    t: float,
    initial=None,
) -> Lattice3D:
    """The exact linear solution on the triply periodic lattice of ``n`` = (nx, ny, nz) sites from corner ``lo``
    (m) at ``t`` (s): the sampled initial drho (``initial(x, y, z)``, kg/m^3; by default the pulse centred at
    ``centre``, m, by its nearest image) with every Fourier mode advanced by w = c0 |k|."""
    axes = [lo[d] + (np.arange(n[d]) + 0.5) * dx for d in range(3)]
    periods = [n[d] * dx for d in range(3)]
    if initial is not None:
        z, y, x = np.meshgrid(axes[2], axes[1], axes[0], indexing="ij")
        drho0 = initial(x, y, z)
    else:
        offsets = []
        for d in range(3):
            o = axes[d] - centre[d]
            offsets.append(o - periods[d] * np.round(o / periods[d]))
        oz, oy, ox = np.meshgrid(offsets[2], offsets[1], offsets[0], indexing="ij")
        drho0 = rho0 * mach * np.exp(-LN2 * (ox**2 + oy**2 + oz**2) / width**2)
    spectrum = np.fft.rfftn(drho0)
    kz = 2 * np.pi * np.fft.fftfreq(n[2], dx)[:, None, None]
    ky = 2 * np.pi * np.fft.fftfreq(n[1], dx)[None, :, None]
    kx = 2 * np.pi * np.fft.rfftfreq(n[0], dx)[None, None, :]
    k = np.sqrt(kx**2 + ky**2 + kz**2)
    w = c0 * k * t
    drho = np.fft.irfftn(spectrum * np.cos(w), s=drho0.shape, axes=(0, 1, 2))
    with np.errstate(invalid="ignore", divide="ignore"):
        scale = np.where(k > 0, -1j * c0 / rho0 * np.sin(w) / np.where(k > 0, k, 1.0), 0.0) * spectrum
    u, v, wz = (np.fft.irfftn(scale * kk, s=drho0.shape, axes=(0, 1, 2)) for kk in (kx, ky, kz))
    return Lattice3D(*axes, drho, u, v, wz)
