"""The CPU pair list: each neighbour pair found once per search, its kernel factors kept, both sides updated.

The gather loop (solvers/pairs.py) visits the 3x3 cell stencil of every
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

The list needs each cell's particles sorted by x (:func:`sort_cells_by_x`,
after the counting sort): a stencil row is then sorted by x, so binary
searches bound each row to a cutoff either side of i, about 120 candidates
per particle instead of 183. Their separations are computed in one
branch-free pass the compiler vectorises, then compressed to the pairs in
range (solvers/compress.py: the vcompress instruction on cores with
AVX-512), whose kernel factors are computed in a second vectorisable pass.

Each thread lists its particles' pairs one after another in its own stretch
of the list (a budget of pairs per particle, :func:`capacity`), so the
build is parallel without a prefix sum and the sweeps stream through
contiguous memory (padded rows per particle, measured here, made the
float64 sweeps three times slower: the prefetcher restarts at every row).
On several threads each thread accumulates its particles' pairs into its
own buffer, and the buffers are summed per particle: no races, no atomics.
In float32 the loops flush subnormals to zero (solvers/denormals.py).
"""

from __future__ import annotations

import math
from functools import lru_cache

import numba
import numpy as np

from .backend import cpu_pairs
from .compress import PAD, compress_within
from .denormals import flush_off, flush_on
from .kernel import NONLIN, NX, NY, RC2, RHO0, SPACING

INDEX_BYTES = 4  # uint32 neighbour index per pair
ROW_BYTES = 4 + 8  # per particle: its pair count (uint32) and where its pairs start (uint64)
# Loop indices are unsigned (U): numba then drops its negative-index wraparound, which otherwise
# turns every contiguous load into a gather and keeps the distance pass from vectorising
# (measured here: 163 -> 27 ns for 120 candidates in float64, 17 ns in float32).
U = np.uint64
# A particle lists its pairs with the rest of its cell row and the row above: half the neighbours
# in the cutoff disc on average (up to three quarters for one at the top of its cell row). Each
# thread's particles share one stretch of the list, so the budget is an average with a margin for
# compressed regions; a stretch that overflows all the same is grown and the search redone.
MEAN_SHARE = 0.55
CAPACITY_MARGIN = 1.1  # growth when a stretch overflows all the same


def neighbours_per_particle(scene) -> float:
    """Neighbours within the cutoff of a particle of the lattice (the disc's area over dx^2)."""
    return math.pi * (scene.cutoff / scene.dx) ** 2


def capacity(scene) -> int:
    """Pairs budgeted per particle in the list: half the lattice's neighbours with a margin."""
    return int(math.ceil(MEAN_SHARE * neighbours_per_particle(scene))) + 8


def list_bytes(scene, budget: int | None = None) -> int:
    """Memory the pair list takes at ``scene``, bytes: per pair an index and two kernel factors."""
    item = np.dtype(scene.precision).itemsize
    per_particle = capacity(scene) if budget is None else budget
    return scene.n_particles * (per_particle * (INDEX_BYTES + 2 * item) + ROW_BYTES)


@lru_cache(maxsize=None)
def kernels(precision: str, kernel: str, parallel: bool) -> dict:
    """The list build (with ``kernel``'s G) and the two sweeps for ``precision``, serial or on numba's threads."""
    gradient = cpu_pairs(precision, kernel).gradient  # the pair code's G (solvers/pairs.py)
    prange = numba.prange
    jit = numba.njit(nogil=True, parallel=parallel, error_model="numpy")
    flush = precision == "float32"  # subnormals to zero in float32 (solvers/denormals.py)

    @numba.njit(inline="always")
    def first_within(j0, j1, lxi, sxi, lx, sx, k):
        """The first j in the x-sorted range [j0, j1) less than a cutoff to the left of i (binary search)."""
        while j0 < j1:
            mid = (j0 + j1) >> U(1)
            rx = (lxi - lx[mid]) * k[SPACING] + (sxi - sx[mid])
            if rx > 0 and rx * rx >= k[RC2]:
                j0 = mid + U(1)
            else:
                j1 = mid
        return j0

    @numba.njit(inline="always")
    def first_beyond(j0, j1, lxi, sxi, lx, sx, k):
        """The first j in the x-sorted range [j0, j1) a cutoff or more to the right of i (binary search)."""
        while j0 < j1:
            mid = (j0 + j1) >> U(1)
            rx = (lxi - lx[mid]) * k[SPACING] + (sxi - sx[mid])
            if rx < 0 and rx * rx >= k[RC2]:
                j1 = mid
            else:
                j0 = mid + U(1)
        return j0

    @numba.njit(inline="always")
    def distances(j0, j1, lxi, lyi, sxi, syi, lx, ly, sx, sy, js, rxs, rys, r2s, q0, k):
        """Separations of the candidates j0 <= j < j1 into the scratch rows from slot q0; the next free slot.
        No branch and contiguous loads: the compiler vectorises it."""
        for q in range(j1 - j0):
            j = j0 + q
            rx = (lxi - lx[j]) * k[SPACING] + (sxi - sx[j])
            ry = (lyi - ly[j]) * k[SPACING] + (syi - sy[j])
            js[q0 + q] = j
            rxs[q0 + q] = rx
            rys[q0 + q] = ry
            r2s[q0 + q] = rx * rx + ry * ry
        return q0 + (j1 - j0)

    def build(cell, begin, ncx, ncy, lx, ly, sx, sy, nbr, fx, fy, start, count, scratch, fscratch, k):
        """Fill the list for cell-ordered particles, x-sorted within each cell; the most pairs per particle
        one thread's stretch needed (more than the budget: grow and search again). Thread t lists its
        particles' pairs one after another in its own stretch of ``nbr, fx, fy`` (from t n / nt particles
        times the budget on), so the sweeps stream through memory. ``scratch`` (threads, 2, L) indices and
        ``fscratch`` (threads, 6, L) separations are per-thread rows as long as the most candidates.
        """
        n, nt = U(lx.shape[0]), U(scratch.shape[0])
        budget = U(nbr.shape[0]) // n
        ncx, ncy = U(ncx), U(ncy)
        periodic = k[NX] > 0  # x periodic: the stencil wraps across the x seam
        need = np.zeros(nt, np.uint64)
        for tt in prange(nt):
            t = U(tt)
            saved = flush_on(flush)
            js, cj = scratch[t, 0], scratch[t, 1]
            rxs, rys, r2s, crx, cry, cr2 = (
                fscratch[t, 0],
                fscratch[t, 1],
                fscratch[t, 2],
                fscratch[t, 3],
                fscratch[t, 4],
                fscratch[t, 5],
            )
            lo, hi = t * n // nt, (t + U(1)) * n // nt
            at, end = lo * budget, hi * budget
            listed = U(0)  # this thread's pairs (a local: a shared array written per particle is false sharing)
            for i in range(lo, hi):
                c = U(cell[i])
                cx = c % ncx
                cy = c // ncx
                x0 = cx - U(1) if cx > U(0) else U(0)
                x1 = cx + U(1) if cx < ncx - U(1) else ncx - U(1)
                lxi, lyi, sxi, syi = lx[i], ly[i], sx[i], sy[i]
                # the rest of this cell row (i's own cell after i, and the cell to the right), sorted by x
                a0 = i + U(1)
                a1 = first_beyond(a0, U(begin[cy * ncx + x1 + U(1)]), lxi, sxi, lx, sx, k)
                nq = distances(a0, a1, lxi, lyi, sxi, syi, lx, ly, sx, sy, js, rxs, rys, r2s, U(0), k)
                if periodic and cx == ncx - U(1):  # the cell to the right is the row's first, across the x seam
                    lxs = lxi - k[NX]
                    e1 = U(begin[cy * ncx + U(1)])
                    b1 = first_beyond(U(begin[cy * ncx]), e1, lxs, sxi, lx, sx, k)
                    nq = distances(U(begin[cy * ncx]), b1, lxs, lyi, sxi, syi, lx, ly, sx, sy, js, rxs, rys, r2s, nq, k)
                # the three cells of the row above (across the periodic seam: i shifted down by ny rows)
                up = cy + U(1)
                if up >= ncy:
                    up -= ncy
                    lyi = lyi - k[NY]
                e1 = U(begin[up * ncx + x1 + U(1)])
                b0 = first_within(U(begin[up * ncx + x0]), e1, lxi, sxi, lx, sx, k)
                b1 = first_beyond(b0, e1, lxi, sxi, lx, sx, k)
                nq = distances(b0, b1, lxi, lyi, sxi, syi, lx, ly, sx, sy, js, rxs, rys, r2s, nq, k)
                if periodic and (cx == U(0) or cx == ncx - U(1)):  # the cell of the row above across the x seam
                    other = ncx - U(1) if cx == U(0) else U(0)
                    lxs = lxi + k[NX] if cx == U(0) else lxi - k[NX]
                    e1 = U(begin[up * ncx + other + U(1)])
                    b0 = first_within(U(begin[up * ncx + other]), e1, lxs, sxi, lx, sx, k)
                    b1 = first_beyond(b0, e1, lxs, sxi, lx, sx, k)
                    nq = distances(b0, b1, lxs, lyi, sxi, syi, lx, ly, sx, sy, js, rxs, rys, r2s, nq, k)
                m = compress_within(js, rxs, rys, r2s, cj, crx, cry, cr2, nq, k[RC2])  # those within the cutoff
                start[i] = at
                count[i] = m
                for q in range(min(m, end - at)):  # the kernel factors of the pairs in range
                    g = gradient(cr2[q], k)
                    nbr[at + q] = cj[q]
                    fx[at + q] = g * crx[q]
                    fy[at + q] = g * cry[q]
                at = min(at + m, end)
                listed += m
            need[t] = (listed + hi - lo - U(1)) // max(hi - lo, U(1))
            flush_off(flush, saved)
        return need.max()

    def continuity(nbr, fx, fy, start, count, u, v, vol, drho, out, buf, k):
        """out = d(drho)/dt from the list; ``buf`` holds one accumulator row per thread."""
        n, nt = U(u.shape[0]), U(buf.shape[0])
        for tt in prange(nt):
            t = U(tt)
            saved = flush_on(flush)
            acc = buf[t]
            acc[:] = 0
            for i in range(t * n // nt, (t + U(1)) * n // nt):
                ui, vi, voli = u[i], v[i], vol[i]
                a = acc[i]
                for m in range(U(start[i]), U(start[i]) + U(count[i])):
                    j = U(nbr[m])
                    s = (ui - u[j]) * fx[m] + (vi - v[j]) * fy[m]
                    a += vol[j] * s
                    acc[j] += voli * s
                acc[i] = a
            flush_off(flush, saved)
        for i in prange(n):
            total = buf[0, i]
            for t in range(U(1), nt):
                total += buf[t, i]
            out[i] = (k[RHO0] + k[NONLIN] * drho[i]) * total

    def momentum(nbr, fx, fy, start, count, mass, pr, ax, ay, bufx, bufy):
        """ax, ay = du/dt from the list; ``bufx``, ``bufy`` hold one accumulator row per thread."""
        n, nt = U(mass.shape[0]), U(bufx.shape[0])
        for tt in prange(nt):
            t = U(tt)
            saved = flush_on(flush)
            accx, accy = bufx[t], bufy[t]
            accx[:] = 0
            accy[:] = 0
            for i in range(t * n // nt, (t + U(1)) * n // nt):
                pri, mi = pr[i], mass[i]
                bx, by = accx[i], accy[i]
                for m in range(U(start[i]), U(start[i]) + U(count[i])):
                    j = U(nbr[m])
                    p = pri + pr[j]
                    wx = p * fx[m]
                    wy = p * fy[m]
                    bx -= mass[j] * wx
                    by -= mass[j] * wy
                    accx[j] += mi * wx
                    accy[j] += mi * wy
                accx[i] = bx
                accy[i] = by
            flush_off(flush, saved)
        for i in prange(n):
            sx_, sy_ = bufx[0, i], bufy[0, i]
            for t in range(U(1), nt):
                sx_ += bufx[t, i]
                sy_ += bufy[t, i]
            ax[i] = sx_
            ay[i] = sy_

    return {"build": jit(build), "continuity": jit(continuity), "momentum": jit(momentum)}


@numba.njit(nogil=True, cache=True)
def sort_cells_by_x(order, begin, lx, sx, dx):
    """Sort each cell's stretch of ``order`` by x = (lx + 1/2) dx + sx (insertion sort: the stable
    counting sort keeps last step's order, which is almost sorted, so this is close to linear)."""
    for c in range(begin.shape[0] - 1):
        for a in range(begin[c] + 1, begin[c + 1]):
            p = order[a]
            xp = (lx[p] + 0.5) * dx + sx[p]
            b = a - 1
            while b >= begin[c] and (lx[order[b]] + 0.5) * dx + sx[order[b]] > xp:
                order[b + 1] = order[b]
                b -= 1
            order[b + 1] = p


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

    def momentum(self, mass, pr, ax, ay) -> None:
        self.kernels["momentum"](
            self.nbr, self.fx, self.fy, self.start, self.count, mass, pr, ax, ay, self.buf, self.bufy
        )

    def row(self, i: int) -> tuple:
        """Particle ``i``'s pairs: (neighbour indices, x and y kernel factors)."""
        s = slice(int(self.start[i]), int(self.start[i]) + int(self.count[i]))
        return self.nbr[s], self.fx[s], self.fy[s]

    @property
    def pairs(self) -> int:
        """Pairs listed, each once."""
        return int(self.count.sum())
