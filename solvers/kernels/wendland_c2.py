"""Wendland's C2 kernel in 2D, compact support 2h (q = r/h <= 2).

W(r) = 7 / (4 pi h^2) (1 - q/2)^4 (2q + 1) (1/m^2);
G(r) = W'(r) / r = -35 / (4 pi h^4) (1 - q/2)^3 (1/m^4), G(0) = -35 / (4 pi h^4).
Nothing is truncated and no exp is needed, only q. In 3D the same shape with sigma = 21 / (16 pi):
W = 21 / (16 pi h^3) (1 - q/2)^4 (2q + 1), G = -105 / (16 pi h^5) (1 - q/2)^3.
"""

from __future__ import annotations

import math

import numpy as np

from solvers.kernels.base import Kernel
from solvers.kernels.constants import GRAD0, INV_H2


class WendlandC2(Kernel):
    """7 / (4 pi h^2) (1 - q/2)^4 (2q + 1), q = r/h <= 2."""

    name = "wendland-c2"
    summary = "Wendland C2, compact support 2h"
    support = 2.0
    norm = 7.0 / (4.0 * math.pi)
    dimensions = (2, 3)
    norms = {2: 7.0 / (4.0 * math.pi), 3: 21.0 / (16.0 * math.pi)}

    def value(self, r, h: float, dims: int = 2):
        q = np.minimum(np.asarray(r, dtype=np.float64) / h, 2.0)
        s = 1.0 - 0.5 * q
        if dims == 3:
            return 21.0 / (16.0 * math.pi * h**3) * s**4 * (2.0 * q + 1.0)
        return 7.0 / (4.0 * math.pi * h * h) * s**4 * (2.0 * q + 1.0)

    def gradient(self, r, h: float, dims: int = 2):
        q = np.minimum(np.asarray(r, dtype=np.float64) / h, 2.0)
        s = 1.0 - 0.5 * q
        if dims == 3:
            return -105.0 / (16.0 * math.pi * h**5) * s**3
        return -35.0 / (4.0 * math.pi * h**4) * s**3

    def compiled_gradient(self, dtype, exp_neg, dims: int = 2):
        """G(0) (1 - q/2)^3, q = sqrt(r^2/h^2)."""
        t = np.dtype(dtype).type
        one, half = t(1.0), t(0.5)

        def gradient(r2, k):
            s = one - half * math.sqrt(r2 * k[INV_H2])
            return k[GRAD0] * (s * s * s)

        return gradient
