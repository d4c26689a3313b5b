"""Linked-list GPU solver: every stage on the device, float32 or float64 from one source.

Device arrays are CuPy's; the kernels are numba-cuda, built from the same
pair physics as the CPU solvers (solvers/pairs.py). One thread per particle.

SNP on the device, every step for moving particles and once otherwise:
a kernel computes each particle's cell (particleIndex); CuPy's radix argsort
orders particles by cell (cellParticleOrder); a binary search of the sorted
cells gives cellBegin (cellBegin[c+1] is cell c's end); every per-particle
array is gathered into cell order, so the three cells of a stencil row are
one contiguous, coalesced range of memory.

Without a GPU, ``NUMBA_ENABLE_CUDASIM=1`` runs the same kernels in numba's
CUDA simulator with NumPy in place of CuPy (small scenes only): that is how
CI checks the GPU code. Without either, the solver says there is no GPU.
"""
from __future__ import annotations

import os
import time
from functools import lru_cache

import numpy as np

from .interface import Solver, SolverUnavailable, cell_grid, tiny_scene
from .scene import SceneError

THREADS_PER_BLOCK = 256
cuda = None  # numba.cuda, bound on first use; a module global so that the simulator can swap it


def simulated() -> bool:
    """True when numba's CUDA simulator is switched on (NUMBA_ENABLE_CUDASIM=1)."""
    return os.environ.get("NUMBA_ENABLE_CUDASIM", "0") == "1"


@lru_cache(maxsize=None)
def device_backend():
    """(cuda, cupy or None): numba-cuda and, on a real GPU, CuPy. Raises SolverUnavailable."""
    if not hasattr(np, "row_stack"):
        # numba-cuda <= 0.30 registers an overload for np.row_stack, which NumPy 2.5
        # removed; without this alias its first kernel compilation fails.
        np.row_stack = np.vstack
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
    # All work goes to one stream, so numba need not synchronise on every CuPy
    # array it is handed (the CUDA Array Interface's default).
    from numba import config

    config.CUDA_ARRAY_INTERFACE_SYNC = False
    return cuda, cupy


@lru_cache(maxsize=None)
def kernels(precision: str):
    """The device kernels for ``precision`` (compiled by numba-cuda on first launch).

    float32 kernels use fastmath (the hardware's approximate expf, ~2 ulp);
    float64 kernels use the accurate libdevice exp.
    """
    from .backend import compile_pairs
    from .kernel import exp_neg_math

    global cuda
    cuda, _ = device_backend()
    fast = precision == "float32"
    P = compile_pairs(cuda.jit(device=True, fastmath=fast), exp_neg_math, f"cuda_{precision}")
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

    return {"cell_ids": cell_ids, "continuity": continuity, "momentum": momentum,
            "neighbours": neighbours}


class LinkedListGPU(Solver):
    """Uniform cell list on a CUDA GPU (or numba's CUDA simulator)."""

    name = "linkedlist-gpu"
    device = "gpu"

    def __init__(self, threads: int | None = None):
        super().__init__(threads=None)
        if threads not in (None, 1):
            raise SceneError(f"threads: linkedlist-gpu runs one GPU thread per particle (got --threads {threads})")
        self.cuda, self.cupy = device_backend()
        self.xp = self.cupy if self.cupy is not None else np

    # ------------------------------------------------------------ stages
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

    def after_init(self) -> None:
        s, xp = self.scene, self.xp
        self.cw, self.ch, self.ncx, self.ncy = cell_grid(s)
        self.ncells = self.ncx * self.ncy
        self.cell = xp.empty(s.n_particles, xp.int32)
        self.cell_range = xp.arange(self.ncells + 1, dtype=xp.int32)
        self.begin = None
        # the simulator runs every thread of a block as a Python thread: keep blocks small there
        self.threads_per_block = 32 if self.cupy is None else THREADS_PER_BLOCK
        self.blocks = (s.n_particles + self.threads_per_block - 1) // self.threads_per_block
        self.cells_valid = False

    def launch(self, name, *args):
        kernels(self.scene.precision)[name][self.blocks, self.threads_per_block](*args)

    def snp(self) -> None:
        if self.cells_valid and not self.moving:
            return
        s, a, xp = self.scene, self.arrays, self.xp
        self.launch("cell_ids", a["lx"], a["ly"], a["sx"], a["sy"], self.cell, s.dx, -self.cw,
                    s.height, self.cw, self.ch, self.ncx, self.ncy)
        if self.cupy is not None:
            order = xp.argsort(self.cell)  # CUB radix sort: stable
        else:
            order = np.argsort(self.cell, kind="stable")
        self.cell = xp.take(self.cell, order)
        # unsigned cell bounds: no negative-index wraparound on each neighbour load
        self.begin = xp.searchsorted(self.cell, self.cell_range).astype(xp.uint32)
        self.permute(order)
        self.cells_valid = True

    def _sweep(self, continuity: bool, momentum: bool) -> None:
        a = self.arrays
        geo = (self.cell, self.begin, self.ncx, self.ncy, a["lx"], a["ly"], a["sx"], a["sy"])
        if continuity:
            self.launch("continuity", *geo, a["u"], a["v"], a["vol"], a["drho"], a["dd"], self.k)
        if momentum:
            self.launch("momentum", *geo, a["mass"], a["pr"], a["ax"], a["ay"], self.k)

    def mean_neighbours(self) -> float:
        self.cells_valid = False
        self.snp()
        a = self.arrays
        counts = self.xp.zeros(self.scene.n_particles, self.xp.int32)
        self.launch("neighbours", self.cell, self.begin, self.ncx, self.ncy, a["lx"], a["ly"],
                    a["sx"], a["sy"], counts, self.k)
        return float(counts.astype(self.xp.float64).mean())

    def to_host(self, arr) -> np.ndarray:
        return self.cupy.asnumpy(arr) if self.cupy is not None else np.asarray(arr)

    def synchronize(self) -> None:
        if self.cupy is not None:
            self.cupy.cuda.runtime.deviceSynchronize()

    def warmup(self) -> float:
        """Compile the kernels and make the first launches on a tiny scene, outside the timing."""
        t0 = time.perf_counter()
        probe = type(self)()
        probe.input(tiny_scene(self.scene))
        probe.init()
        probe.snp()
        probe.rates(True, True)
        probe.kick(0.5)
        probe.advance(1.0)
        probe.amplitude()
        probe.output()
        probe.mean_neighbours()
        probe.synchronize()
        return time.perf_counter() - t0
