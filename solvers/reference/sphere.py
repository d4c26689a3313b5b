"""Exact linear reference of a Gaussian pulse scattered by a rigid sphere: the 3D analogue of the CAA workshop's
cylinder (solvers/reference/cylinder.py, whose method this follows order by order).

The linear acoustic equations in a medium at rest (rho0, c0), p = c0^2 drho:

    d(drho)/dt = -rho0 div u,   du/dt = -(c0^2 / rho0) grad drho,   u . n = 0 on r = a,

from u = 0 and, in the fluid (r > a), drho = A exp(-ln2 |x - x_s|^2 / b^2) (A = rho0 Ma), x_s = (d, 0, 0): a
Gaussian pulse centred at distance ``d`` from the centre of a sphere of radius ``a``; inside the body there is no
fluid, so the data is the Gaussian cut at r = a (at the sphere's default, b = 0.4 m at d = 1.5 m, a = 0.5 m, the
cut is 1.3 % of the amplitude).

**Method.** In spherical coordinates about the sphere's centre, theta from the pulse's direction (+x), the
Gaussian is a Legendre series, exp(beta cos theta) = sum_n (2n + 1) i_n(beta) P_n(cos theta) (i_n the modified
spherical Bessel function), so that

    drho_0 = sum_n (2n + 1) f_n(r) P_n(cos theta),
    f_n(r) = A exp(-ln2 (r - d)^2 / b^2) [exp(-beta) i_n(beta)],  beta = 2 ln2 r d / b^2.

Each order evolves by the spherical Weber transform of the exterior Neumann problem, whose radial eigenfunctions
are C_n(k r) = j_n(k r) y_n'(k a) - y_n(k r) j_n'(k a) (spherical Bessel functions; int j_n(k r) j_n(k' r) r^2 dr
= pi / (2 k^2) delta(k - k')):

    drho_n(r, t) = (2 / pi) int_0^inf F_n(k) C_n(k r) cos(c0 k t) k^2 dk / (j_n'(k a)^2 + y_n'(k a)^2),
    F_n(k) = int_a^inf f_n(r) C_n(k r) r^2 dr.

As for the cylinder, the field is the free evolution of the data plus a scattered part that needs only the orders
where j_n'(k a) is not negligible (n up to k_max a and a margin):

* the free evolution of the whole Gaussian is the closed form (solvers/reference/pulse3d.py, ``open_pulse``:
  r p = [(r - c0 t) g(r - c0 t) + (r + c0 t) g(r + c0 t)] / 2 about x_s), less that of the part cut away inside
  the body, sum_n (2n + 1) P_n (2 / pi) int G_n^in(k) j_n(k r) cos(c0 k t) k^2 dk, G_n^in = int_0^a f_n j_n r^2 dr
  (beta <= 2 ln2 a d / b^2 there: a few tens of orders);
* the scattered part of each order, with G_n, H_n = int_a^inf f_n (j_n, y_n)(k r) r^2 dr,

      s_n(r, t) = -(2 / pi) int j_n'(k a) [G_n (j_n j_n'(k a) + y_n y_n'(k a)) + H_n (j_n y_n'(k a) - y_n j_n'(k a))]
                  cos(c0 k t) k^2 dk / (j_n'(k a)^2 + y_n'(k a)^2),

  written in the ratio of the smaller derivative at k a to the larger, so that nothing overflows (the terms where
  y_n(k r) overflows, k r << n, vanish).

The k integrals are Gauss-Legendre on [0, k_max] with exp(-k_max^2 b^2 / (4 ln2)) = 1e-16 (the pulse's
spectrum), the r integrals on the pulse's support (8 widths either side of d) cut at a. Needs scipy.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from solvers.reference.pulse2d import gauss_legendre
from solvers.reference.pulse3d import open_pulse

LN2 = math.log(2.0)
SPECTRUM_FLOOR = 1e-16  # exp(-k_max^2 b^2 / (4 ln2)): where the pulse's spectrum ends
SUPPORT_WIDTHS = 8.0  # the pulse's radial support either side of d, in widths (exp(-ln2 64) = 5e-20)
ORDER_MARGIN = 24  # orders past k_max a (where j_n'(k a) has fallen below 1e-16 of its peak)
K_NODES = 640  # Gauss-Legendre nodes in k (the integrand's phase c0 k t + k r + k d: under 100 half-turns here)
R_NODES = 480  # and in r, on each of the two radial pieces


def _special():
    try:
        from scipy import special
    except ImportError as exc:  # pragma: no cover - scipy is a dependency
        raise ImportError("the sphere's exact reference needs scipy (pip install scipy)") from exc
    return special


def k_max(width: float) -> float:
    """The pulse's largest wavenumber, 1/m: where its spectrum exp(-k^2 b^2 / (4 ln2)) falls to 1e-16."""
    return math.sqrt(-math.log(SPECTRUM_FLOOR) * 4.0 * LN2) / width


def orders_needed(a: float, d: float, width: float) -> int:
    """Orders the scattered part and the cut-away part need: past k_max a, and past where f_n inside the body
    (beta <= 2 ln2 a d / b^2) has fallen below 1e-16 of the amplitude."""
    beta_in = 2.0 * LN2 * a * d / width**2
    return int(math.ceil(max(k_max(width) * a, beta_in) + ORDER_MARGIN))


def _f_scaled(n: int, r, d: float, width: float) -> np.ndarray:
    """f_n(r) / A: exp(-ln2 (r - d)^2 / b^2) exp(-beta) i_n(beta), beta = 2 ln2 r d / b^2 (by ive: no overflow)."""
    sp = _special()
    beta = 2.0 * LN2 * np.asarray(r, float) * d / width**2
    scaled = np.sqrt(np.pi / (2.0 * np.maximum(beta, 1e-300))) * sp.ive(n + 0.5, beta)
    return np.exp(-LN2 * (r - d) ** 2 / width**2) * scaled


def _nodes(lo: float, hi: float, count: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes on [lo, hi] and their weights times r^2."""
    z, w = gauss_legendre(count)
    r = 0.5 * (hi - lo) * (z + 1.0) + lo
    return r, 0.5 * (hi - lo) * w * r * r


@lru_cache(maxsize=8)
def _spectrum(a: float, d: float, width: float, orders: int, k_nodes: int, r_nodes: int):
    """The k nodes and weights (with (2 / pi) k^2), and per order n < ``orders`` the coefficients, arrays
    (orders, k_nodes) for a unit amplitude, of j_n(k r) and y_n(k r) in the field less the free Gaussian's: the
    scattered part's, less the free evolution of the part cut away inside the body (of j_n)."""
    sp = _special()
    z, w = gauss_legendre(k_nodes)
    top = k_max(width)
    k = 0.5 * top * (z + 1.0)
    wk = 0.5 * top * w * k * k * (2.0 / math.pi)
    r_out, w_out = _nodes(max(d - SUPPORT_WIDTHS * width, a), d + SUPPORT_WIDTHS * width, r_nodes)
    inside = d - SUPPORT_WIDTHS * width < a
    r_in, w_in = _nodes(max(d - SUPPORT_WIDTHS * width, 0.0), a, r_nodes) if inside else (np.zeros(0), np.zeros(0))
    kr_out, kr_in = k[:, None] * r_out[None, :], k[:, None] * r_in[None, :]
    coef_j = np.empty((orders, k_nodes))
    coef_y = np.empty((orders, k_nodes))
    for n in range(orders):
        f_out = _f_scaled(n, r_out, d, width) * w_out
        f_in = _f_scaled(n, r_in, d, width) * w_in
        with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
            g = sp.spherical_jn(n, kr_out) @ f_out  # G_n(k)
            h = sp.spherical_yn(n, kr_out) @ f_out  # H_n(k): -inf where y_n(k r) overflows (k r << n)
            g_in = sp.spherical_jn(n, kr_in) @ f_in if inside else np.zeros_like(k)
            jp, yp = sp.spherical_jn(n, k * a, derivative=True), sp.spherical_yn(n, k * a, derivative=True)
            big_y = np.abs(yp) >= np.abs(jp)
            q = np.where(big_y, jp / np.where(big_y, yp, 1.0), 0.0)
            p = np.where(big_y, 0.0, yp / np.where(big_y, 1.0, jp))
            cj = np.where(big_y, q * (g * q + h) / (1 + q * q), (g + h * p) / (1 + p * p))
            cy = np.where(big_y, q * (g - h * q) / (1 + q * q), (g * p - h) / (1 + p * p))
        # where y_n(k r) overflows the true terms vanish (q ~ (k a)^(2n+1) against y_n ~ (k r)^(-n-1), a < r): 0
        coef_j[n] = -np.nan_to_num(cj, nan=0.0, posinf=0.0, neginf=0.0) - g_in
        coef_y[n] = -np.nan_to_num(cy, nan=0.0, posinf=0.0, neginf=0.0)
    return k, wk, coef_j, coef_y


def drho(
    points,
    times,
    radius: float,
    distance: float,
    width: float,
    amplitude: float,
    c0: float = 1.0,
    orders: int | None = None,
    k_nodes: int = K_NODES,
    r_nodes: int = R_NODES,
    factor=None,
) -> np.ndarray:
    """drho (kg/m^3) at ``points`` ((m, 3), m, the sphere's centre at the origin, outside it) and ``times`` (s):
    an (m, len(times)) array, for the pulse of ``width`` b and ``amplitude`` A centred at (``distance``, 0, 0)
    about a rigid sphere of ``radius`` a. ``factor(k, t)`` (an array (len(t), len(k))) replaces each wavenumber's
    cos(c0 k t), the free pulse's included (then by its k integral, :func:`free_pulse`): a method's own evolution
    (solvers/reference/dispersive_sphere.py)."""
    sp = _special()
    pts = np.atleast_2d(np.asarray(points, dtype=np.float64))
    ts = np.atleast_1d(np.asarray(times, dtype=np.float64))
    r = np.linalg.norm(pts, axis=1)
    if np.any(r < radius * (1 - 1e-12)):
        raise ValueError("sphere reference: a point inside the body")
    cos_theta = np.clip(pts[:, 0] / np.maximum(r, 1e-300), -1.0, 1.0)
    orders = orders_needed(radius, distance, width) if orders is None else orders
    k, wk, coef_j, coef_y = _spectrum(radius, distance, width, orders, k_nodes, r_nodes)
    evolution = np.cos(c0 * k[:, None] * ts[None, :]) if factor is None else np.asarray(factor(k, ts)).T
    waves = evolution * wk[:, None]  # (k, t)
    kr = r[:, None] * k[None, :]
    out = np.zeros((len(r), len(ts)))
    for n in range(orders):
        with np.errstate(over="ignore", invalid="ignore"):
            y = sp.spherical_yn(n, kr)
            term = sp.spherical_jn(n, kr) * coef_j[n] + np.where(coef_y[n] != 0.0, y * coef_y[n], 0.0)
        term = np.nan_to_num(term, nan=0.0, posinf=0.0, neginf=0.0)
        out += ((2 * n + 1) * sp.eval_legendre(n, cos_theta))[:, None] * (term @ waves)
    from_source = np.linalg.norm(pts - [distance, 0.0, 0.0], axis=1)
    if factor is None:
        free = np.array([open_pulse(from_source, t, width, 1.0, 1.0, c0)[0] for t in ts]).T
    else:
        free = free_pulse(from_source, width, k, wk, evolution)
    return amplitude * (free + out)


def free_pulse(distance, width: float, k, wk, evolution) -> np.ndarray:
    """The free unit Gaussian exp(-ln2 R^2 / b^2) (b = ``width``, m) at ``distance`` R (m) from its centre, evolved
    by ``evolution``
    (an array (len(k), len(t)), cos(c0 k t) for the exact pulse): (1 / 2 pi^2) int g(k) j_0(k R) evolution k^2 dk,
    g(k) = (pi / alpha)^1.5 exp(-k^2 / 4 alpha), alpha = ln2 / b^2, on the series' k nodes (``wk``: the weights
    times (2 / pi) k^2). An (len(R), len(t)) array."""
    sp = _special()
    alpha = LN2 / width**2
    spectrum = (math.pi / alpha) ** 1.5 * np.exp(-(k**2) / (4.0 * alpha)) * wk / (4.0 * math.pi)
    return sp.spherical_jn(0, np.multiply.outer(np.asarray(distance, float), k)) @ (spectrum[:, None] * evolution)


def scene_drho(scene, points, times, factor=None) -> np.ndarray:
    """:func:`drho` of a sphere scene's pulse and body (its radius, the pulse's centre, width and amplitude
    rho0 Ma, c0) at ``points`` ((m, 3), m) and ``times`` (s): an (m, len(times)) array, kg/m^3."""
    return drho(
        np.atleast_2d(np.asarray(points, dtype=np.float64)), times, scene.sphere_radius, scene.pulse_center,
        scene.pulse_width, scene.rho0 * scene.mach, scene.c0, factor=factor,
    )  # fmt: skip
