"""The Laguerre-Gauss (super-Gaussian) kernel in 2D: fourth order, truncated at the scene's cutoff.

W(r) = (2 - q^2) exp(-q^2) / (pi h^2) (1/m^2), q = r/h, for r < cutoff = cutoff_factor h, 0 beyond
(Gingold & Monaghan 1982; Wang, Zhang, Haidn & Hu, arXiv 2309.01581). Its second moment vanishes, so its
Fourier transform is 1 + O(k^4 h^4) (the Gaussian's exp(-k^2 h^2 / 4) is second order): with the kernel
gradient correction (solvers/corrections/), h >= 1.5 dx and a 4 h cutoff the lattice operator is fourth
order. It is negative beyond q = sqrt(2), a known source of the tensile instability once particles move.
G(r) = W'(r) / r = -2 (3 - q^2) exp(-q^2) / (pi h^4) (1/m^4), G(0) = -6 / (pi h^4).
In d dimensions W = (d/2 + 1 - q^2) exp(-q^2) / (pi^(d/2) h^d), G = -2 (d/2 + 2 - q^2) exp(-q^2) /
(pi^(d/2) h^(d+2)): in 3D (5/2 - q^2) exp(-q^2) / (pi^1.5 h^3), G(0) = -7 / (pi^1.5 h^5).
"""

from __future__ import annotations

import math

import numpy as np

from solvers.kernels.base import Kernel
from solvers.kernels.constants import GRAD0, INV_H2


class LaguerreGauss(Kernel):
    """(2 - q^2) exp(-q^2) / (pi h^2), q = r/h, cut at the scene's ``cutoff_factor`` h (4 for fourth order)."""

    name = "laguerre-gauss"
    summary = "fourth-order Laguerre-Gauss (2 - q^2) exp(-q^2), truncated at --cutoff (in h; 4 for fourth order)"
    support = None
    norm = 2.0 / math.pi  # W = norm / h^2 (1 - q^2 / 2) exp(-q^2)
    negative_lobe = True  # beyond q = sqrt(2) (2D), sqrt(5/2) (3D)
    order_cutoff = 4.0  # its fourth order needs the cut at 4 h (exp(-16): 1e-7); at 2 h it is second order
    dimensions = (2, 3)
    norms = {2: 2.0 / math.pi, 3: 2.5 * math.pi**-1.5}  # W(0) h^d

    def value(self, r, h: float, dims: int = 2):
        q2 = (np.asarray(r, dtype=np.float64) / h) ** 2
        if dims == 3:
            return (2.5 - q2) * np.exp(-q2) / (math.pi**1.5 * h**3)
        return (2.0 - q2) * np.exp(-q2) / (math.pi * h * h)

    def gradient(self, r, h: float, dims: int = 2):
        q2 = (np.asarray(r, dtype=np.float64) / h) ** 2
        if dims == 3:
            return -2.0 * (3.5 - q2) * np.exp(-q2) / (math.pi**1.5 * h**5)
        return -2.0 * (3.0 - q2) * np.exp(-q2) / (math.pi * h**4)

    def compiled_gradient(self, dtype, exp_neg, dims: int = 2):
        """G(0) (1 - q^2 / (d/2 + 2)) exp(-q^2) through the caller's ``exp_neg`` (1/3 in 2D, 2/7 in 3D)."""
        one, third = np.dtype(dtype).type(1.0), np.dtype(dtype).type(1.0 / 3.0 if dims == 2 else 2.0 / 7.0)

        def gradient(r2, k):
            q2 = r2 * k[INV_H2]
            return k[GRAD0] * (one - third * q2) * exp_neg(q2)

        return gradient
