"""The sixth-order Laguerre-Gauss kernel in 2D and 3D, truncated at the scene's cutoff (5 h for its order).

W(r) = L_2^(d/2)(q^2) exp(-q^2) / (pi^(d/2) h^d), q = r/h, for r < cutoff = cutoff_factor h, 0 beyond, with the
generalised Laguerre polynomial L_2^(a)(x) = (a + 1)(a + 2) / 2 - (a + 2) x + x^2 / 2 (Monaghan 1985's family; the
fourth-order member is solvers/kernels/laguerre_gauss.py):

* 2D: (3 - 3 q^2 + q^4 / 2) exp(-q^2) / (pi h^2) (1/m^2); G = W'(r) / r = -(12 - 8 q^2 + q^4) exp(-q^2) / (pi h^4),
  G(0) = -12 / (pi h^4);
* 3D: (35/8 - 7 q^2 / 2 + q^4 / 2) exp(-q^2) / (pi^1.5 h^3) (1/m^3); G = -(63/4 - 9 q^2 + q^4) exp(-q^2) /
  (pi^1.5 h^5), G(0) = -63 / (4 pi^1.5 h^5).

Its second and fourth moments vanish, so its Fourier transform is 1 + O(k^6 h^6) (the fourth-order kernel's
1 - k^4 h^4 / 32 ...): with the gradient correction, h = 1.5 dx and a 5 h cutoff (exp(-25): 1e-11) the bulk's
phase error at 10 particles per pulse half-width is a fifth of the fourth-order kernel's (issue 67; docs/accuracy.md
"A sixth-order kernel"). A 5 h cutoff holds 1.95 times the neighbours of 4 h in 3D (1.56 in 2D). It is
negative between q = 1.13 and 2.18 in 2D (its polynomial's zeros, q^2 = 3 -+ sqrt 3), so it has the tensile
instability's source of the fourth-order one once particles move.
"""

from __future__ import annotations

import math

import numpy as np

from solvers.kernels.base import Kernel
from solvers.kernels.constants import GRAD0, INV_H2

# L_2^(d/2)(x) = P0 - P1 x + x^2 / 2 and G's polynomial -(2 P0 + 2 P1) + (2 P1 + 2) x - x^2, by dimension
POLYNOMIAL = {2: (3.0, 3.0), 3: (35.0 / 8.0, 3.5)}  # (P0, P1)


def _g_polynomial(dims: int) -> tuple:
    """(g0, g1): G = -(g0 - g1 q^2 + q^4) exp(-q^2) / (pi^(d/2) h^(d+2)) (from W' = 2 r / h^2 (P' - P) e^-x)."""
    p0, p1 = POLYNOMIAL[dims]
    return 2.0 * (p0 + p1), 2.0 * (p1 + 1.0)


class LaguerreGauss6(Kernel):
    """L_2^(d/2)(q^2) exp(-q^2) / (pi^(d/2) h^d), q = r/h, cut at the scene's ``cutoff_factor`` h (5 for sixth
    order)."""

    name = "laguerre-gauss-6"
    summary = "sixth-order Laguerre-Gauss (3 - 3 q^2 + q^4 / 2) exp(-q^2), truncated at --cutoff (5 for sixth order)"
    support = None
    norm = 3.0 / math.pi  # W = norm / h^2 (1 - q^2 + q^4 / 6) exp(-q^2)
    negative_lobe = True
    order_cutoff = 5.0  # W(5 h) is 1e-9 of W(0); at 4 h the cut's error (3e-6 of W(0)) leads
    dimensions = (2, 3)
    norms = {2: 3.0 / math.pi, 3: 35.0 / 8.0 * math.pi**-1.5}  # W(0) h^d

    def value(self, r, h: float, dims: int = 2):
        q2 = (np.asarray(r, dtype=np.float64) / h) ** 2
        p0, p1 = POLYNOMIAL[dims]
        return (p0 - p1 * q2 + 0.5 * q2 * q2) * np.exp(-q2) / (math.pi ** (0.5 * dims) * h**dims)

    def gradient(self, r, h: float, dims: int = 2):
        q2 = (np.asarray(r, dtype=np.float64) / h) ** 2
        g0, g1 = _g_polynomial(dims)
        return -(g0 - g1 * q2 + q2 * q2) * np.exp(-q2) / (math.pi ** (0.5 * dims) * h ** (dims + 2))

    def compiled_gradient(self, dtype, exp_neg, dims: int = 2):
        """G(0) (1 - (g1 / g0) q^2 + q^4 / g0) exp(-q^2) through the caller's ``exp_neg``."""
        g0, g1 = _g_polynomial(dims)
        one = np.dtype(dtype).type(1.0)
        a, b = np.dtype(dtype).type(g1 / g0), np.dtype(dtype).type(1.0 / g0)

        def gradient(r2, k):
            q2 = r2 * k[INV_H2]
            return k[GRAD0] * (one - q2 * (a - b * q2)) * exp_neg(q2)

        return gradient
