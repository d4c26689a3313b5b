"""The GPU solver's device kernels (numba-cuda), from the shared pair physics.

Imported only once the GPU solver has a device (or numba's simulator), so
that nothing touches CUDA at the import of ``solvers``. ``cuda`` is this
module's global on purpose: numba's CUDA simulator (NUMBA_ENABLE_CUDASIM=1)
runs the kernels as Python and swaps the module global named ``cuda`` for its
own, which a closure variable would hide from it.
"""
from __future__ import annotations

from functools import lru_cache

from numba import cuda

from .kernel import exp_neg_math
from .gpu_device import device_backend
from .pairs import make_pairs


@lru_cache(maxsize=None)
def kernels(precision: str):
    """The device kernels for ``precision`` (compiled by numba-cuda on first launch).

    float32 kernels use fastmath (the hardware's approximate expf, ~2 ulp);
    float64 kernels use the accurate libdevice exp.
    """
    device_backend()  # the device is usable (or simulated), numba-cuda patched for this NumPy
    fast = precision == "float32"
    P = make_pairs(cuda.jit(device=True, fastmath=fast), exp_neg_math)
    jit = cuda.jit(fastmath=fast)

    @jit
    def cell_ids(lx, ly, sx, sy, cell, dx, x_grid, height, cw, ch, ncx, ncy):
        i = cuda.grid(1)
        if i < lx.shape[0]:
            cell[i] = P.cell_index(lx[i], ly[i], sx[i], sy[i], dx, x_grid, height, cw, ch, ncx, ncy)

    @jit
    def continuity(cell, begin, ncx, ncy, lx, ly, sx, sy, u, v, vol, drho, out, k):
        i = cuda.grid(1)
        if i < lx.shape[0]:
            out[i] = P.continuity_cells(i, cell, begin, ncx, ncy, lx, ly, sx, sy, u, v, vol, drho, k)

    @jit
    def momentum(cell, begin, ncx, ncy, lx, ly, sx, sy, mass, pr, ax, ay, k):
        i = cuda.grid(1)
        if i < lx.shape[0]:
            bx, by = P.momentum_cells(i, cell, begin, ncx, ncy, lx, ly, sx, sy, mass, pr, k)
            ax[i] = bx
            ay[i] = by

    @jit
    def neighbours(cell, begin, ncx, ncy, lx, ly, sx, sy, counts, k):
        i = cuda.grid(1)
        if i < lx.shape[0]:
            counts[i] = P.neighbours_cells(i, cell, begin, ncx, ncy, lx, ly, sx, sy, k)

    # the system update and the coefficients, each one launch instead of a chain of array operations
    @jit
    def coefficients(drho, mass, vol, pr, continuity, momentum, k):
        i = cuda.grid(1)
        if i < drho.shape[0]:
            P.coefficients_at(i, drho, mass, vol, pr, continuity, momentum, k)

    @jit
    def kick(u, v, ax, ay, c):
        i = cuda.grid(1)
        if i < u.shape[0]:
            P.kick_at(i, u, v, ax, ay, c)

    @jit
    def advance(drho, dd, sx, sy, u, v, c, moving):
        i = cuda.grid(1)
        if i < drho.shape[0]:
            P.advance_at(i, drho, dd, sx, sy, u, v, c, moving)

    return {"cell_ids": cell_ids, "continuity": continuity, "momentum": momentum,
            "neighbours": neighbours, "coefficients": coefficients, "kick": kick, "advance": advance}
