"""The SPH kernels and the constants the pair loops need.

Three kernels (``KERNELS``), each as W(r) and G(r) = W'(r) / r, so that
grad_i W_ij = G(r_ij) (x_i - x_j):

- ``gaussian`` (the paper's): W = exp(-r^2/h^2) / (pi h^2) for r < cutoff,
  0 beyond, G = -2 exp(-r^2/h^2) / (pi h^4). The truncation is not
  renormalised: at a 3h cutoff it biases the sound speed by about 0.12 %
  (9 % at 2h), an error floor the reports state.
- ``wendland-c2``, ``wendland-c4``: Wendland's kernels in their 2D
  normalisation, compact support 2h (``SUPPORT``): nothing is truncated and
  no exp is needed, only q = r/h.

The reference forms (:func:`value`, :func:`gradient_factor`, NumPy) are the
truth; :func:`make_gradient` is the one compiled G every solver's pair code
evaluates (solvers/pairs.py, solvers/pairlist.py).

The constant tuple ``k`` is built in the solver's precision so that float32
loops never promote to float64. Its layout is indexed by the names below.
"""
from __future__ import annotations

import math

import numpy as np

# Layout of the constant tuple passed to every pair loop: numba folds a module-level
# integer index into a compile-time constant, so a named slot costs nothing.
SPACING = 0  # dx, m
NY = 1  # lattice rows in the periodic height
INV_H2 = 2  # 1 / h^2, 1/m^2
GRAD0 = 3  # G(0), 1/m^4: -2 / (pi h^4) for the Gaussian, -35 / (4 pi h^4) C2, -21 / (2 pi h^4) C4
RC2 = 4  # cutoff^2, m^2
RHO0 = 5  # rho0, kg/m^3
C0SQ = 6  # c0^2, m^2/s^2
NONLIN = 7  # 1 where rho = rho0 + drho in the coefficients, 0 in the linear model
ZERO = 8  # 0 in the solver's float type (accumulators start from it)
NX = 9  # lattice columns in the periodic width, 0 where the x edges are free
SLOTS = 10


def constants(scene, dtype) -> tuple:
    """Pair-loop constants for ``scene`` as a tuple of ``dtype`` scalars."""
    h = scene.h
    nonlin = 0.0 if scene.model == "linear" else 1.0
    values = {
        SPACING: scene.dx,
        NY: float(scene.ny),
        INV_H2: 1.0 / (h * h),
        GRAD0: float(gradient_factor(scene.kernel, 0.0, h)),
        RC2: scene.cutoff**2,
        RHO0: scene.rho0,
        C0SQ: scene.c0**2,
        NONLIN: nonlin,
        ZERO: 0.0,
        NX: float(scene.nx) if scene.periodic_x else 0.0,
    }
    t = np.dtype(dtype).type
    return tuple(t(values[i]) for i in range(SLOTS))


# ---------------------------------------------------------------- reference forms (NumPy), for every kernel
KERNELS = ("gaussian", "wendland-c2", "wendland-c4")
SUPPORT = {"wendland-c2": 2.0, "wendland-c4": 2.0}  # compact support / h; the Gaussian is truncated instead
WENDLAND_NORM = {"wendland-c2": 7.0, "wendland-c4": 9.0}  # W = NORM / (4 pi h^2) f(q) in 2D


def value(kernel: str, r, h: float):
    """W(r) in 2D, 1/m^2 (NumPy; the Gaussian untruncated: the caller applies its cutoff)."""
    r = np.asarray(r, dtype=np.float64)
    if kernel == "gaussian":
        return np.exp(-(r / h) ** 2) / (math.pi * h * h)
    q = np.minimum(r / h, 2.0)
    s = 1.0 - 0.5 * q
    norm = WENDLAND_NORM[kernel] / (4.0 * math.pi * h * h)
    if kernel == "wendland-c2":
        return norm * s**4 * (2.0 * q + 1.0)
    if kernel == "wendland-c4":
        return norm * s**6 * (35.0 / 12.0 * q * q + 3.0 * q + 1.0)
    raise ValueError(f"kernel must be one of {', '.join(KERNELS)} (got {kernel!r})")


def gradient_factor(kernel: str, r, h: float):
    """G(r) = W'(r) / r, so that grad_i W_ij = G(r_ij) (x_i - x_j), 1/m^4 (NumPy).

    Wendland C2: G = -35/(4 pi h^4) (1 - q/2)^3; C4: G = -21/(4 pi h^4) (1 - q/2)^5 (5q + 2), q = r/h <= 2:
    no exp and no division by r.
    """
    r = np.asarray(r, dtype=np.float64)
    if kernel == "gaussian":
        return -2.0 * np.exp(-(r / h) ** 2) / (math.pi * h**4)
    q = np.minimum(r / h, 2.0)
    s = 1.0 - 0.5 * q
    if kernel == "wendland-c2":
        return -35.0 / (4.0 * math.pi * h**4) * s**3
    if kernel == "wendland-c4":
        return -21.0 / (4.0 * math.pi * h**4) * s**5 * (5.0 * q + 2.0)
    raise ValueError(f"kernel must be one of {', '.join(KERNELS)} (got {kernel!r})")


def make_gradient(kernel: str, dtype, exp_neg):
    """G(r^2, k) = W'(r) / r of ``kernel`` for the pair loops, 1/m^4, in ``dtype`` throughout (to be compiled).

    ``exp_neg(x) = exp(-x)`` (compiled by the caller) serves the Gaussian; the
    Wendland kernels take q = sqrt(r^2 / h^2) once and no exp. ``r2`` must be
    within the cutoff (the loops test it first). Each kernel is its own
    function, so a solver compiles only its kernel's arithmetic.
    """
    if kernel == "gaussian":
        def gradient(r2, k):
            return k[GRAD0] * exp_neg(r2 * k[INV_H2])
        return gradient
    t = np.dtype(dtype).type
    one, half = t(1.0), t(0.5)
    if kernel == "wendland-c2":
        def gradient(r2, k):  # G(0) (1 - q/2)^3
            s = one - half * math.sqrt(r2 * k[INV_H2])
            return k[GRAD0] * (s * s * s)
        return gradient
    if kernel == "wendland-c4":
        c4_slope = t(2.5)  # (5q + 2) / 2 = 1 + 2.5 q, with G(0) = -21 / (2 pi h^4)

        def gradient(r2, k):  # G(0) (1 - q/2)^5 (1 + 5q/2)
            q = math.sqrt(r2 * k[INV_H2])
            s = one - half * q
            s2 = s * s
            return k[GRAD0] * (s2 * s2 * s) * (one + c4_slope * q)
        return gradient
    raise ValueError(f"kernel must be one of {', '.join(KERNELS)} (got {kernel!r})")


def exp_neg_math(x):
    """exp(-x) through the math library (the GPU's fast hardware path)."""
    return math.exp(-x)


def make_exp_neg_table(dtype):
    """An inlinable exp(-x), x >= 0, for CPU loops, in ``dtype`` throughout.

    exp(-x) = 2^(-n/32) * exp(-f ln2/32) with n = floor(32 x / ln 2): a table of
    2^(-n/32) and a Taylor polynomial on [0, ln2/32) (degree 7 in float64,
    relative error ~3e-15 up to x = 36; degree 3 in float32). libm's exp is a
    call the compiler cannot schedule into the pair loop; this is about 20 %
    faster there. Arguments beyond the table give 0.
    """
    t = np.dtype(dtype).type
    size = 32 * 52 + 1  # x up to 36 (cutoff 6h); the cutoff test removes larger x anyway
    table = (2.0 ** (-np.arange(size) / 32.0)).astype(dtype)
    table[-1] = 0
    scale, inv_scale, last = t(32.0 / math.log(2.0)), t(math.log(2.0) / 32.0), t(size - 1)
    c0, c1, c2, c3, c4, c5, c6, c7 = (t(1.0 / math.factorial(m)) for m in range(8))
    if t is np.float64:
        def exp_neg(x):
            s = min(x * scale, last)
            n = int(s)
            f = (s - n) * inv_scale
            return table[n] * (c0 - f * (c1 - f * (c2 - f * (c3 - f * (c4 - f * (c5 - f * (c6 - f * c7)))))))
    else:
        def exp_neg(x):
            s = min(x * scale, last)
            n = int(s)
            f = (s - n) * inv_scale
            return table[n] * (c0 - f * (c1 - f * (c2 - f * c3)))
    return exp_neg
