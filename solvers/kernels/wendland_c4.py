"""Wendland's C4 kernel in 2D, compact support 2h (q = r/h <= 2).

W(r) = 9 / (4 pi h^2) (1 - q/2)^6 (35/12 q^2 + 3q + 1) (1/m^2);
G(r) = W'(r) / r = -21 / (4 pi h^4) (1 - q/2)^5 (5q + 2) (1/m^4), G(0) = -21 / (2 pi h^4).
In 3D the same shape with sigma = 495 / (256 pi) over h^3: G = -(7/3) sigma / h^5 (1 - q/2)^5 (5q + 2).
"""

from __future__ import annotations

import math

import numpy as np

from solvers.kernels.base import Kernel
from solvers.kernels.constants import GRAD0, INV_H2


class WendlandC4(Kernel):
    """9 / (4 pi h^2) (1 - q/2)^6 (35/12 q^2 + 3q + 1), q = r/h <= 2."""

    name = "wendland-c4"
    summary = "Wendland C4, compact support 2h"
    support = 2.0
    norm = 9.0 / (4.0 * math.pi)
    dimensions = (2, 3)
    norms = {2: 9.0 / (4.0 * math.pi), 3: 495.0 / (256.0 * math.pi)}

    def value(self, r, h: float, dims: int = 2):
        q = np.minimum(np.asarray(r, dtype=np.float64) / h, 2.0)
        s = 1.0 - 0.5 * q
        if dims == 3:
            return 495.0 / (256.0 * math.pi * h**3) * s**6 * (35.0 / 12.0 * q * q + 3.0 * q + 1.0)
        return 9.0 / (4.0 * math.pi * h * h) * s**6 * (35.0 / 12.0 * q * q + 3.0 * q + 1.0)

    def gradient(self, r, h: float, dims: int = 2):
        q = np.minimum(np.asarray(r, dtype=np.float64) / h, 2.0)
        s = 1.0 - 0.5 * q
        if dims == 3:
            return -1155.0 / (256.0 * math.pi * h**5) * s**5 * (5.0 * q + 2.0)  # (7/3) 495 / 256
        return -21.0 / (4.0 * math.pi * h**4) * s**5 * (5.0 * q + 2.0)

    def compiled_gradient(self, dtype, exp_neg, dims: int = 2):
        """G(0) (1 - q/2)^5 (1 + 5q/2): (5q + 2) / 2 = 1 + 2.5 q, with G(0) = -21 / (2 pi h^4)."""
        t = np.dtype(dtype).type
        one, half, c4_slope = t(1.0), t(0.5), t(2.5)

        def gradient(r2, k):
            q = math.sqrt(r2 * k[INV_H2])
            s = one - half * q
            s2 = s * s
            return k[GRAD0] * (s2 * s2 * s) * (one + c4_slope * q)

        return gradient
