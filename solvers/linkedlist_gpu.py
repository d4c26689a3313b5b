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

import numpy as np

from .celllist import CellListSolver
from .gpu_device import device_backend, simulated
from .scene import SceneError

THREADS_PER_BLOCK = 256

__all__ = ["LinkedListGPU", "device_backend", "simulated"]  # the backend checks, re-exported for callers


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
        from .gpu_kernels import kernels  # numba.cuda only once a device (or the simulator) is known

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

    def count_neighbours(self) -> int:
        counts = self.xp.zeros(self.scene.n_particles, self.xp.int32)
        self.launch("neighbours", *self.geometry(), counts, self.k)
        return int(counts.astype(self.xp.int64).sum())

    def to_host(self, arr) -> np.ndarray:
        return self.cupy.asnumpy(arr) if self.cupy is not None else np.asarray(arr)

    def synchronize(self) -> None:
        if self.cupy is not None:
            self.cupy.cuda.runtime.deviceSynchronize()
