"""Linked-list GPU solver: every stage on the device, float32 or float64 from one source.

Device arrays are CuPy's; the kernels are numba-cuda, built from the same
pair physics as the CPU solvers (solvers/physics/pairs.py; in 3D pairs3d.py
and the kernels of solvers/loops/gpu3d.py). One thread per particle, every
launch on the solver's own stream.

The per-particle arrays are the rows of one 2D block (and a spare block of
the same shape), so that SNP moves all of them in one launch. SNP, every step
for moving particles and once otherwise, is three launches with no host round
trip, a counting sort by cell: the search's two (solvers/gpu/cells.py:
particleIndex and ranks by atomics, cellBegin by a one-block scan), then
``scatter`` (the whole block into cell order in the spare block, which then
becomes the current one). The system update writes the sweeps' coefficients as it updates drho,
so a lagrangian Verlet step is 8 launches: kick, continuity, advance, the
three of SNP, momentum, kick. Nothing is allocated inside a step, so a step
can be captured once as a CUDA graph and replayed (solvers/gpu/graph.py).

Without a GPU, ``NUMBA_ENABLE_CUDASIM=1`` runs the same kernels in numba's
CUDA simulator with NumPy in place of CuPy (small scenes only): that is how
CI checks the GPU code. Without either, the solver says there is no GPU.
"""

from __future__ import annotations

import numpy as np

from solvers.gpu.cells import DeviceCellList
from solvers.gpu.device import device_backend, simulated
from solvers.scene import SceneError
from solvers.search.celllist import CellListSolver

THREADS_PER_BLOCK = 256

__all__ = ["LinkedListGPU", "device_backend", "simulated"]  # the backend checks, re-exported for callers


class LinkedListGPU(CellListSolver):
    """Uniform cell list on a CUDA GPU (or numba's CUDA simulator), one thread per particle."""

    name = "linkedlist-gpu"
    summary = 'the cell list on a CUDA GPU, CuPy + numba-cuda (pip install -e ".[gpu]")'
    device = "gpu"
    serial_why = "one GPU thread per particle"
    resources = {"timing": 1, "GPU": 1}
    boundaries = ("free-x", "periodic-x", "wall-x", "free-y", "periodic-y", "periodic-z", "free-z", "body")
    neighbour_search = DeviceCellList

    @classmethod
    def available(cls) -> None:
        device_backend()  # SolverUnavailable: what to install, or that this machine has no GPU

    def __init__(self, threads: int = 1, pair_loop: str = "auto"):
        if threads not in (None, 1):
            raise SceneError(f"threads: linkedlist-gpu runs one GPU thread per particle (got --threads {threads})")
        super().__init__(threads=1, pair_loop=pair_loop)
        self.cuda, self.cupy = device_backend()
        self.xp = self.cupy if self.cupy is not None else np
        self.stream = None

    def check_scene(self, scene) -> None:
        if self.cupy is None:
            return
        free, _total = self.cupy.cuda.runtime.memGetInfo()
        need = self.memory_bytes(scene)
        if need > free:
            raise SceneError(
                f"dx = {scene.dx} m needs {scene.n_particles:,} particles and about {need / 2**30:.3g} GiB "
                f"on the GPU, more than its {free / 2**30:.3g} GiB free; the smallest dx that fits is "
                f"about {scene.smallest_dx_fitting(free):.3g} m"
            )

    def input(self, scene) -> None:
        super().input(scene)
        if self.cupy is not None:
            self.stream = self.cupy.cuda.Stream()  # blocking: ordered with CuPy's work on the legacy stream
            self.stream.use()  # CuPy's operations (init, output, checks) go to the same stream
            self.launch_stream = self.cuda.external_stream(self.stream.ptr)
        else:
            self.stream = None
            self.launch_stream = self.cuda.default_stream()

    def warmup(self) -> float:
        seconds = super().warmup()
        if self.stream is not None:
            self.stream.use()  # the probe made its own stream CuPy's current one
        return seconds

    def allocate_cells(self) -> None:
        """Both particle blocks and the launch shapes (the search has its cell arrays): everything a step needs."""
        xp, n, a = self.xp, self.scene.n_particles, self.arrays
        self.names = tuple(a)
        block = xp.empty((len(self.names), n), self.dtype)
        for row, name in enumerate(self.names):
            block[row] = a[name]
        self.blocks_of = [block, xp.empty_like(block)]
        self.views = [{name: blk[row] for row, name in enumerate(self.names)} for blk in self.blocks_of]
        self.set_state(0)
        self.coefficients_fresh = False
        # the simulator runs every thread of a block as a Python thread: keep blocks small there
        self.threads_per_block = 32 if self.cupy is None else THREADS_PER_BLOCK
        self.blocks = (n + self.threads_per_block - 1) // self.threads_per_block

    def launch(self, name, *args, grid=None):
        """Kernel ``name`` on the solver's stream: one thread per particle, or ``grid`` = (blocks, threads)."""
        from solvers.gpu.cuda_kernels import kernels  # numba.cuda only once a device (or the simulator) is known

        blocks, threads = grid or (self.blocks, self.threads_per_block)
        s = self.scene
        kernels(s.precision, s.kernel, s.dims)[name][blocks, threads, self.launch_stream](*args)

    def sort_cells(self) -> None:
        """Counting sort by cell in three launches (the search's two, then the scatter); the spare block
        becomes the current one."""
        a, now = self.arrays, self.current
        self.nnps.bin(*(a[name] for name in self.nnps.positions))
        self.launch("scatter", *self.nnps.scatter_arguments(self.blocks_of[now], self.blocks_of[1 - now], now))
        self.set_state(1 - now)
        self.reordered += 1
        for name, arr in self.saved.items():  # two-stage integrators' copies (not in a Verlet step)
            self.saved[name] = self.gathered(arr, self.nnps.order)

    def state(self) -> int:
        """Which particle block is current (a step that searches flips it)."""
        return self.current

    def set_state(self, current: int) -> None:
        self.current = current
        self.arrays = self.views[current]
        self.nnps.use(current)

    def rates(self, continuity: bool, momentum: bool) -> None:
        """PI; the coefficients only when drho changed since the system update last wrote them (a body's
        ghosts take new values first: then always)."""
        if self.prepare_boundaries():  # a body's ghosts took new values
            self.coefficients_fresh = False
        if not self.coefficients_fresh:
            self.coefficients(True, True)
            self.coefficients_fresh = True
        self.correction.sweep(self, continuity, momentum)

    def advance_launch(self, f: float) -> None:
        """drho (and x) += f dt (D, u), with the coefficients of the new drho in the same launch."""
        a = self.arrays
        self.launch("advance", *self.advance_arguments(f), a["mass"], a["vol"], a["pr"], self.k)
        self.coefficients_fresh = True

    def absorb(self, f: float, fields: str) -> None:
        """An open edge's layer damps drho too: its coefficients are then recomputed at the next PI."""
        super().absorb(f, fields)
        if self.absorber is not None and fields == "density":
            self.coefficients_fresh = False

    def restore(self, names) -> None:
        super().restore(names)
        self.coefficients_fresh = self.coefficients_fresh and "drho" not in names

    def to_host(self, arr) -> np.ndarray:
        return self.cupy.asnumpy(arr) if self.cupy is not None else np.asarray(arr)

    def synchronize(self) -> None:
        if self.stream is not None:
            self.stream.synchronize()
