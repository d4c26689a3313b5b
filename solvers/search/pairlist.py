"""The CPU pair list: each neighbour pair found once per search, its kernel factors kept, both sides updated.

The gather loop (solvers/physics/pairs.py) visits the 3x3 cell stencil of every
particle in every sweep: each pair is found twice per sweep (once from each
side), and the kernel is evaluated four times per pair per Verlet step.
Here SNP, after the cell sort, lists each pair once (j after i in the half
stencil: the rest of i's cell row from i + 1, and the three cells of the row
above) with its kernel factors f = G(r^2) r_ij; the sweeps then stream over
the list and update both particles (Newton's third law):

    d(drho)/dt:  s = (u_i - u_j) . f,            acc_i += vol_j s,  acc_j += vol_i s
    du/dt:       w = (pr_i + pr_j) f,            a_i -= m_j w,      a_j += m_i w

In Stormer-Verlet the continuity sweep of step n + 1 runs at the positions of
the momentum sweep of step n, so one list serves both; particles that never
move (the fixed and linear models) build it once per run.
Where moving particles are corrected (solvers/corrections/gradient.py), the
moment matrix M_i = -sum_j vol_j r_ij (x) f_ij and Gamma_i = sum_j vol_j f_ij
come from the list too, both sides of each pair, r_ij from the positions: no
kernel evaluation at every search (the gather loop's moments cost 2.5 steps).

The list needs each cell's particles sorted by x (``sort_cells_by_x`` in solvers/loops/sorting.py,
after the counting sort): a stencil row is then sorted by x, so binary
searches bound each row to a cutoff either side of i, about 120 candidates
per particle instead of 183. Their separations are computed in one
branch-free pass the compiler vectorises, then compressed to the pairs in
range (solvers/search/compress.py: the vcompress instruction on cores with
AVX-512), whose kernel factors are computed in a second vectorisable pass.

Each thread lists its particles' pairs one after another in its own stretch
of the list (a budget of pairs per particle, :func:`capacity`), so the
build is parallel without a prefix sum and the sweeps stream through
contiguous memory (padded rows per particle, measured here, made the
float64 sweeps three times slower: the prefetcher restarts at every row).
On several threads each thread accumulates its particles' pairs into its
own buffer, and the buffers are summed per particle: no races, no atomics.
In float32 the loops flush subnormals to zero (solvers/physics/denormals.py).
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from solvers.corrections import correction_named
from solvers.physics.backend import COMPILED, cpu_loops
from solvers.search.compress import PAD

INDEX_BYTES = 4  # uint32 neighbour index per pair
ROW_BYTES = 4 + 8  # per particle: its pair count (uint32) and where its pairs start (uint64)
# A particle lists its pairs with the rest of its cell row and the row above: half the neighbours
# in the cutoff disc on average (up to three quarters for one at the top of its cell row). Each
# thread's particles share one stretch of the list, so the budget is an average with a margin for
# compressed regions; a stretch that overflows all the same is grown and the search redone.
MEAN_SHARE = 0.55
MOMENT_SUMS = 5  # the gradient correction's sums a particle (M_xx, M_xy, M_yy, Gamma_x, Gamma_y)
CAPACITY_MARGIN = 1.1  # growth when a stretch overflows all the same


def neighbours_per_particle(scene) -> float:
    """Neighbours within the cutoff of a particle of the lattice (the disc's area over dx^2)."""
    return math.pi * (scene.cutoff / scene.dx) ** 2


def capacity(scene) -> int:
    """Pairs budgeted per particle in the list: half the lattice's neighbours with a margin."""
    return int(math.ceil(MEAN_SHARE * neighbours_per_particle(scene))) + 8


def list_bytes(scene, budget: int | None = None) -> int:
    """Memory the pair list takes at ``scene``, bytes: per pair an index and two kernel factors (and the
    correction's moment sums, per particle, where they are summed from the list at every search)."""
    item = np.dtype(scene.precision).itemsize
    per_particle = capacity(scene) if budget is None else budget
    # a correction's moments summed from the list at every search where particles move: their accumulators
    summed = correction_named(scene.correction).moments and scene.model == "lagrangian"
    moments = MOMENT_SUMS * item if summed else 0
    return scene.n_particles * (per_particle * (INDEX_BYTES + 2 * item) + ROW_BYTES + moments)


@lru_cache(maxsize=None)
def kernels(precision: str, kernel: str, parallel: bool) -> dict:
    """The list build (with ``kernel``'s G), the two sweeps and the correction's moments for ``precision``,
    serial or on numba's threads (solvers/loops/pairlist.py, compiled once per machine)."""
    loops = cpu_loops("pairlist", precision, kernel, parallel, flush=precision == "float32")
    return {name: getattr(loops, name) for name in COMPILED["pairlist"]}


class PairList:
    """The pair list of one solver: one stretch of pairs per thread, kernel factors, per-thread accumulators."""

    def __init__(self, scene, threads: int):
        dt = np.dtype(scene.precision)
        n = scene.n_particles
        self.kernels = kernels(scene.precision, scene.kernel, threads > 1)
        self.threads = threads
        self._allocate(n, capacity(scene), dt)
        self.start = np.zeros(n, np.uint64)
        self.count = np.zeros(n, np.uint32)
        self.buf = np.zeros((threads, n), dt)
        self.bufy = np.zeros((threads, n), dt)
        self.bufm = None  # the correction's moments' accumulators, made at the first use
        self.scratch = None

    def _allocate(self, n, budget, dt):
        """The list for ``budget`` pairs per particle, touched at once: the first-touch page faults of a
        list of hundreds of MB (measured 2.5 s at 400K here) belong to the allocation (init), not to the
        first search."""
        self.budget = budget
        self.nbr = np.zeros(n * budget, np.uint32)
        self.fx = np.zeros(n * budget, dt)
        self.fy = np.zeros(n * budget, dt)
        for arr in (self.nbr, self.fx, self.fy):
            arr.fill(0)

    def _scratch(self, begin, ncx) -> tuple:
        """Per-thread scratch rows long enough for any particle's candidates (two stencil rows of 3 cells)."""
        per_cell = np.diff(begin.astype(np.int64))
        rows = np.convolve(per_cell, np.ones(3, np.int64), mode="same")  # 3 consecutive cells (upper bound)
        need = 2 * int(rows.max(initial=0)) + 2 * int(per_cell.max(initial=0)) + 1 + PAD  # + cells across a seam
        if self.scratch is None or self.scratch[0].shape[2] < need:
            self.scratch = (
                np.empty((self.threads, 2, need), np.uint32),
                np.empty((self.threads, 6, need), self.fx.dtype),
            )
        return self.scratch

    def build(self, cell, begin, ncx, ncy, lx, ly, sx, sy, k) -> None:
        """List the pairs of the current (cell-ordered) positions; grow the list if a stretch overflowed."""
        scratch = self._scratch(begin, ncx)
        args = (cell, begin, ncx, ncy, lx, ly, sx, sy)
        most = self.kernels["build"](*args, self.nbr, self.fx, self.fy, self.start, self.count, *scratch, k)
        if most > self.budget:
            self._allocate(lx.shape[0], int(most * CAPACITY_MARGIN) + 8, self.fx.dtype)
            self.kernels["build"](*args, self.nbr, self.fx, self.fy, self.start, self.count, *scratch, k)

    def continuity(self, u, v, vol, drho, out, k) -> None:
        self.kernels["continuity"](
            self.nbr, self.fx, self.fy, self.start, self.count, u, v, vol, drho, out, self.buf, k
        )

    def continuity_split(self, u, v, vol, drho, out, outx, k) -> None:
        """d(drho)/dt into ``out`` and its x part (v's terms left out) into ``outx``, in one pass."""
        self.kernels["continuity_split"](
            self.nbr, self.fx, self.fy, self.start, self.count, u, v, vol, drho, out, outx, self.buf, self.bufy, k
        )

    def momentum(self, mass, pr, ax, ay) -> None:
        self.kernels["momentum"](
            self.nbr, self.fx, self.fy, self.start, self.count, mass, pr, ax, ay, self.buf, self.bufy
        )

    def moments(self, lx, ly, sx, sy, vol, k) -> tuple:
        """(M_xx, M_xy, M_yy, Gamma_x, Gamma_y) of every particle from the listed pairs (the gradient correction's
        sums: solvers/corrections/gradient.py), as rows of one new (5, n) array; the accumulators (five a
        particle a thread) kept for the next search."""
        n = lx.shape[0]
        if self.bufm is None or self.bufm.shape[1] != n:
            self.bufm = np.zeros((self.threads, n, MOMENT_SUMS), self.fx.dtype)
        out = np.empty((MOMENT_SUMS, n), self.fx.dtype)
        self.kernels["moments"](
            self.nbr, self.fx, self.fy, self.start, self.count, lx, ly, sx, sy, vol, out, self.bufm, k
        )
        return tuple(out)

    def row(self, i: int) -> tuple:
        """Particle ``i``'s pairs: (neighbour indices, x and y kernel factors)."""
        s = slice(int(self.start[i]), int(self.start[i]) + int(self.count[i]))
        return self.nbr[s], self.fx[s], self.fy[s]

    @property
    def pairs(self) -> int:
        """Pairs listed, each once."""
        return int(self.count.sum())
