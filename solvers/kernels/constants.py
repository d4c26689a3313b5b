"""What the pair loops need of any kernel: the constant tuple and the compiled exp(-x).

The kernels themselves are classes, one file each in solvers/kernels/ (W, G =
W'(r) / r, their reach and the compiled G), found by its registry. Here is
only what is not per-kernel: the layout of the constant tuple ``k`` every
pair loop reads (the compiled G takes G(0) and 1/h^2 from it), built in the
solver's precision so that float32 loops never promote to float64, and the
two exp(-x) a kernel such as the Gaussian is given (libm/CUDA, or a table for
CPU loops).
"""

from __future__ import annotations

import math

import numpy as np

# Layout of the constant tuple passed to every pair loop: numba folds a module-level
# integer index into a compile-time constant, so a named slot costs nothing.
SPACING = 0  # dx, m
NY = 1  # lattice rows in the periodic height, 0 where the y edges are free
INV_H2 = 2  # 1 / h^2, 1/m^2
GRAD0 = 3  # G(0) of the scene's kernel, 1/m^4 (the Gaussian's -2 / (pi h^4))
RC2 = 4  # cutoff^2, m^2
RHO0 = 5  # rho0, kg/m^3
C0SQ = 6  # c0^2, m^2/s^2
NONLIN = 7  # 1 where rho = rho0 + drho in the coefficients, 0 in the linear model
ZERO = 8  # 0 in the solver's float type (accumulators start from it)
NX = 9  # lattice columns in the periodic width, 0 where the x edges are free
WALL_LO = 10  # 1 where a rigid wall is the lattice's left edge (mirror particles across it), else 0
WALL_HI = 11  # 1 where a rigid wall is the lattice's right edge, else 0
MIRROR_HI = 12  # 2 nx - 1: the right wall mirrors lattice column lx onto column MIRROR_HI - lx (the left: -1 - lx)
ONE = 13  # 1 in the solver's float type
SLOTS = 14
NZ = 14  # a 3D scene's lattice layers in the periodic depth, 0 where the z faces are free (2D tuples stop at SLOTS)
SLOTS_3D = 15


def constants(scene, dtype) -> tuple:
    """Pair-loop constants for ``scene`` as a tuple of ``dtype`` scalars."""
    h = scene.h
    nonlin = 0.0 if scene.model == "linear" else 1.0
    values = {
        SPACING: scene.dx,
        NY: float(scene.ny) if scene.periodic_y else 0.0,
        INV_H2: 1.0 / (h * h),
        GRAD0: scene.sph_kernel.grad0(h, **scene.sph_kernel.in_dims(scene.dims)),
        RC2: scene.cutoff**2,
        RHO0: scene.rho0,
        C0SQ: scene.c0**2,
        NONLIN: nonlin,
        ZERO: 0.0,
        NX: float(scene.nx) if scene.periodic_x else 0.0,
        WALL_LO: 1.0 if "x_min" in scene.kind.walls else 0.0,
        WALL_HI: 1.0 if "x_max" in scene.kind.walls else 0.0,
        MIRROR_HI: float(2 * scene.nx - 1),
        ONE: 1.0,
    }
    slots = SLOTS
    if scene.dims == 3:
        values[NZ], slots = (float(scene.nz) if scene.periodic_z else 0.0), SLOTS_3D
    t = np.dtype(dtype).type
    return tuple(t(values[i]) for i in range(slots))


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
