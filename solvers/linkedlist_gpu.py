"""Linked-list GPU solver: every stage on the device, float32 or float64 from one source.

Device arrays are CuPy's; the kernels are numba-cuda, built from the same
pair physics as the CPU solvers (solvers/pairs.py). One thread per particle.

SNP on the device, every step for moving particles and once otherwise:
a kernel computes each particle's cell (particleIndex); CuPy's radix argsort
orders particles by cell (cellParticleOrder); a binary search of the sorted
cells gives cellBegin (cellBegin[c+1] is cell c's end); every per-particle
array is gathered into cell order, so the three cells of a stencil row are
one contiguous, coalesced range of memory.

The system update (kick, advance) and the sweeps' coefficients are one
fused kernel each, so a Verlet step is a handful of launches besides SNP.

Without a GPU, ``NUMBA_ENABLE_CUDASIM=1`` runs the same kernels in numba's
CUDA simulator with NumPy in place of CuPy (small scenes only): that is how
CI checks the GPU code. Without either, the solver says there is no GPU.
"""
from __future__ import annotations

import os
from functools import lru_cache

import numpy as np

from .celllist import CellListSolver
from .interface import SolverUnavailable
from .scene import SceneError

THREADS_PER_BLOCK = 256


def simulated() -> bool:
    """True when numba's CUDA simulator is switched on (NUMBA_ENABLE_CUDASIM=1)."""
    return os.environ.get("NUMBA_ENABLE_CUDASIM", "0") == "1"


def _compat_numba_cuda() -> None:
    """Let numba-cuda <= 0.30 run on NumPy 2.5: it registers an overload for ``np.row_stack``, which
    NumPy 2.5 removed, and its first kernel compilation fails without this alias."""
    if not hasattr(np, "row_stack"):
        np.row_stack = np.vstack


@lru_cache(maxsize=None)
def device_backend():
    """(cuda, cupy or None): numba-cuda and, on a real GPU, CuPy. Raises SolverUnavailable."""
    _compat_numba_cuda()
    try:
        from numba import cuda
    except ImportError as exc:  # pragma: no cover - numba without CUDA support
        raise SolverUnavailable("linkedlist-gpu needs numba-cuda: pip install 'pcabench[gpu]'") from exc
    if simulated():
        return cuda, None
    try:
        import cupy
    except ImportError as exc:
        raise SolverUnavailable(
            "linkedlist-gpu needs CuPy and a CUDA GPU: pip install 'pcabench[gpu]' on a machine "
            "with an NVIDIA GPU (or set NUMBA_ENABLE_CUDASIM=1 to run its kernels in the simulator)"
        ) from exc
    try:
        if cupy.cuda.runtime.getDeviceCount() < 1 or not cuda.is_available():
            raise RuntimeError("no CUDA device")
    except Exception as exc:  # noqa: BLE001 - any driver/runtime failure means no usable GPU
        raise SolverUnavailable(
            f"linkedlist-gpu: no CUDA GPU on this machine ({exc}); use linkedlist-cpu, or set "
            "NUMBA_ENABLE_CUDASIM=1 to run its kernels in the simulator") from exc
    _one_stream()
    return cuda, cupy


def _one_stream() -> None:
    """All work goes to one stream, so numba need not synchronise on every CuPy array it is handed
    (the CUDA Array Interface's default)."""
    from numba import config

    config.CUDA_ARRAY_INTERFACE_SYNC = False


@lru_cache(maxsize=None)
def kernels(precision: str):
    """The device kernels for ``precision`` (compiled by numba-cuda on first launch).

    float32 kernels use fastmath (the hardware's approximate expf, ~2 ulp);
    float64 kernels use the accurate libdevice exp.
    """
    from .kernel import C0SQ, NONLIN, RHO0, exp_neg_math
    from .pairs import make_pairs

    cuda, _ = device_backend()
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
            rho = k[RHO0] + k[NONLIN] * drho[i]
            if continuity:
                vol[i] = mass[i] / rho
            if momentum:
                pr[i] = k[C0SQ] * drho[i] / (rho * rho)

    @jit
    def kick(u, v, ax, ay, c):
        i = cuda.grid(1)
        if i < u.shape[0]:
            u[i] += c * ax[i]
            v[i] += c * ay[i]

    @jit
    def advance(drho, dd, sx, sy, u, v, c, moving):
        i = cuda.grid(1)
        if i < drho.shape[0]:
            drho[i] += c * dd[i]
            if moving:
                sx[i] += c * u[i]
                sy[i] += c * v[i]

    return {"cell_ids": cell_ids, "continuity": continuity, "momentum": momentum,
            "neighbours": neighbours, "coefficients": coefficients, "kick": kick, "advance": advance}


class LinkedListGPU(CellListSolver):
    """Uniform cell list on a CUDA GPU (or numba's CUDA simulator), one thread per particle."""

    name = "linkedlist-gpu"
    device = "gpu"

    def __init__(self, threads: int = 1):
        if threads not in (None, 1):
            raise SceneError(f"threads: linkedlist-gpu runs one GPU thread per particle (got --threads {threads})")
        super().__init__(threads=1)
        self.cuda, self.cupy = device_backend()
        self.xp = self.cupy if self.cupy is not None else np

    def check_scene(self, scene) -> None:
        if self.cupy is None:
            return
        free, _total = self.cupy.cuda.runtime.memGetInfo()
        need = scene.memory_bytes()
        if need > free:
            raise SceneError(
                f"dx = {scene.dx} m needs {scene.n_particles:,} particles and about {need / 2**30:.3g} GiB "
                f"on the GPU, more than its {free / 2**30:.3g} GiB free; the smallest dx that fits is "
                f"about {scene.smallest_dx_fitting(free):.3g} m")

    def allocate_cells(self) -> None:
        xp, n = self.xp, self.scene.n_particles
        self.cell = xp.empty(n, xp.int32)
        self.cell_range = xp.arange(self.ncells + 1, dtype=xp.int32)
        self.begin = None
        # the simulator runs every thread of a block as a Python thread: keep blocks small there
        self.threads_per_block = 32 if self.cupy is None else THREADS_PER_BLOCK
        self.blocks = (n + self.threads_per_block - 1) // self.threads_per_block

    def launch(self, name, *args):
        kernels(self.scene.precision)[name][self.blocks, self.threads_per_block](*args)

    def sort_cells(self) -> None:
        """Cell ids on the device, CuPy's radix argsort (stable), cellBegin by binary search, then the gather."""
        xp = self.xp
        self.cell_ids()
        order = xp.argsort(self.cell) if self.cupy is not None else np.argsort(self.cell, kind="stable")
        self.cell = xp.take(self.cell, order)
        # unsigned cell bounds: no negative-index wraparound on each neighbour load
        self.begin = xp.searchsorted(self.cell, self.cell_range).astype(xp.uint32)
        self.permute(order)

    def coefficients(self, continuity: bool, momentum: bool) -> None:
        a = self.arrays
        self.launch("coefficients", a["drho"], a["mass"], a["vol"], a["pr"], continuity, momentum, self.k)

    def kick(self, f: float) -> None:
        a = self.arrays
        self.launch("kick", a["u"], a["v"], a["ax"], a["ay"], self.dtype.type(f * self.scene.dt))

    def advance(self, f: float) -> None:
        a = self.arrays
        self.launch("advance", a["drho"], a["dd"], a["sx"], a["sy"], a["u"], a["v"], self.dtype.type(f * self.scene.dt),
                    self.moving)
        self.t += f * self.scene.dt

    def count_neighbours(self) -> int:
        counts = self.xp.zeros(self.scene.n_particles, self.xp.int32)
        self.launch("neighbours", *self.geometry(), counts, self.k)
        return int(counts.astype(self.xp.int64).sum())

    def to_host(self, arr) -> np.ndarray:
        return self.cupy.asnumpy(arr) if self.cupy is not None else np.asarray(arr)

    def synchronize(self) -> None:
        if self.cupy is not None:
            self.cupy.cuda.runtime.deviceSynchronize()
