"""The CPU pair list: each neighbour pair found once per search, its kernel factors kept, both sides updated.

The gather loop (solvers/pairs.py) visits the 3x3 cell stencil of every
particle in every sweep: each pair is found twice per sweep (once from each
side), and the Gaussian is evaluated four times per pair per Verlet step.
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
after the counting sort): a stencil row is then sorted by x, so its scan
starts by binary search a cutoff to the left of i and stops a cutoff to the
right, about 120 candidates per particle instead of 183.

Rows of the list are padded to a capacity (``capacity``): every particle
writes its own row, so the build is parallel without a prefix sum. On
several threads each thread accumulates its particles' pairs into its own
buffer, and the buffers are summed per particle: no races, no atomics.
"""
from __future__ import annotations

import math
from functools import lru_cache

import numba
import numpy as np

from .kernel import GRAD0, INV_H2, NONLIN, NY, RC2, RHO0, SPACING, make_exp_neg_table

INDEX_BYTES = 4  # int32 neighbour index per pair
COUNT_BYTES = 4  # int32 pair count per particle
# A row holds i's pairs with the rest of its cell row and the row above: on average half the
# neighbours in the cutoff disc, but up to three quarters for a particle at the top of its cell
# row (the whole upper half disc and a quarter of the lower one). Rows are sized for that
# worst case plus disorder, so that the first search never has to grow them.
WORST_SHARE = 0.78
CAPACITY_MARGIN = 1.1  # growth when a row overflows all the same


def neighbours_per_particle(scene) -> float:
    """Neighbours within the cutoff of a particle of the lattice (the disc's area over dx^2)."""
    return math.pi * (scene.cutoff / scene.dx) ** 2


def capacity(scene) -> int:
    """Padded row length of the list, pairs: the worst row of the lattice with room for disorder."""
    return int(math.ceil(WORST_SHARE * neighbours_per_particle(scene))) + 8


def list_bytes(scene, row_capacity: int | None = None) -> int:
    """Memory the pair list takes at ``scene``, bytes: per pair an index and two kernel factors."""
    item = np.dtype(scene.precision).itemsize
    cap = capacity(scene) if row_capacity is None else row_capacity
    return scene.n_particles * (cap * (INDEX_BYTES + 2 * item) + COUNT_BYTES)


@lru_cache(maxsize=None)
def kernels(precision: str, parallel: bool) -> dict:
    """The list build and the two sweeps for ``precision``, serial or on numba's threads."""
    exp_neg = numba.njit(inline="always")(make_exp_neg_table(precision))
    prange = numba.prange
    jit = numba.njit(nogil=True, parallel=parallel, error_model="numpy")

    @numba.njit(inline="always")
    def scan(j0, j1, lxi, lyi, sxi, syi, lx, ly, sx, sy, js, rxs, rys, r2s, m, k):
        """Append the candidates j0 <= j < j1 within the cutoff to the scratch rows from slot m; the new m.

        The range is sorted by x, so the scan stops at the first j a cutoff to
        the right of i. Branch-free inside: every candidate is written at slot
        m and m advances only for those in range.
        """
        for j in range(j0, j1):
            rx = (lxi - lx[j]) * k[SPACING] + (sxi - sx[j])
            if rx * rx >= k[RC2] and rx < 0:
                break
            ry = (lyi - ly[j]) * k[SPACING] + (syi - sy[j])
            r2 = rx * rx + ry * ry
            js[m] = j
            rxs[m] = rx
            rys[m] = ry
            r2s[m] = r2
            m += r2 < k[RC2]
        return m

    @numba.njit(inline="always")
    def first_within(j0, j1, lxi, sxi, lx, sx, k):
        """The first j in the x-sorted range [j0, j1) less than a cutoff to the left of i (binary search)."""
        j0, j1 = np.int64(j0), np.int64(j1)  # cell bounds are unsigned: keep the arithmetic signed
        while j0 < j1:
            mid = (j0 + j1) // 2
            rx = (lxi - lx[mid]) * k[SPACING] + (sxi - sx[mid])
            if rx > 0 and rx * rx >= k[RC2]:
                j0 = mid + 1
            else:
                j1 = mid
        return j0

    def build(cell, begin, ncx, ncy, lx, ly, sx, sy, nbr, fx, fy, count, js, rxs, rys, r2s, k):
        """Fill the list for cell-ordered particles, x-sorted within each cell; the largest row length
        needed (more than the capacity: rebuild). ``js, rxs, rys, r2s`` are scratch rows, one per thread,
        as long as the most candidates of a particle.
        """
        n, nt, cap = lx.shape[0], js.shape[0], nbr.shape[1]
        most = np.zeros(nt, np.int64)
        for t in prange(nt):
            jt, rxt, ryt, r2t = js[t], rxs[t], rys[t], r2s[t]
            for i in range(t * n // nt, (t + 1) * n // nt):
                c = cell[i]
                cx = c % ncx
                cy = c // ncx
                x0 = cx - 1 if cx > 0 else 0
                x1 = cx + 1 if cx < ncx - 1 else ncx - 1
                lxi, lyi, sxi, syi = lx[i], ly[i], sx[i], sy[i]
                # the rest of this cell row: i's own cell after i, and the cell to the right
                m = scan(i + 1, begin[cy * ncx + x1 + 1], lxi, lyi, sxi, syi, lx, ly, sx, sy, jt, rxt, ryt, r2t,
                         0, k)
                # the three cells of the row above (across the periodic seam: i shifted down by ny rows)
                up = cy + 1
                if up >= ncy:
                    up -= ncy
                    lyi = lyi - k[NY]
                j1 = begin[up * ncx + x1 + 1]
                j0 = first_within(begin[up * ncx + x0], j1, lxi, sxi, lx, sx, k)
                m = scan(j0, j1, lxi, lyi, sxi, syi, lx, ly, sx, sy, jt, rxt, ryt, r2t, m, k)
                count[i] = m
                most[t] = max(most[t], m)
                for q in range(min(m, cap)):  # the kernel factors of the pairs in range, no branch
                    g = k[GRAD0] * exp_neg(r2t[q] * k[INV_H2])
                    nbr[i, q] = jt[q]
                    fx[i, q] = g * rxt[q]
                    fy[i, q] = g * ryt[q]
        return most.max()

    def continuity(nbr, fx, fy, count, u, v, vol, drho, out, buf, k):
        """out = d(drho)/dt from the list; ``buf`` holds one accumulator row per thread."""
        n, nt = u.shape[0], buf.shape[0]
        for t in prange(nt):
            acc = buf[t]
            acc[:] = 0
            for i in range(t * n // nt, (t + 1) * n // nt):
                ui, vi, voli = u[i], v[i], vol[i]
                a = acc[i]
                for m in range(count[i]):
                    j = nbr[i, m]
                    s = (ui - u[j]) * fx[i, m] + (vi - v[j]) * fy[i, m]
                    a += vol[j] * s
                    acc[j] += voli * s
                acc[i] = a
        for i in prange(n):
            total = buf[0, i]
            for t in range(1, nt):
                total += buf[t, i]
            out[i] = (k[RHO0] + k[NONLIN] * drho[i]) * total

    def momentum(nbr, fx, fy, count, mass, pr, ax, ay, bufx, bufy):
        """ax, ay = du/dt from the list; ``bufx``, ``bufy`` hold one accumulator row per thread."""
        n, nt = mass.shape[0], bufx.shape[0]
        for t in prange(nt):
            accx, accy = bufx[t], bufy[t]
            accx[:] = 0
            accy[:] = 0
            for i in range(t * n // nt, (t + 1) * n // nt):
                pri, mi = pr[i], mass[i]
                bx, by = accx[i], accy[i]
                for m in range(count[i]):
                    j = nbr[i, m]
                    p = pri + pr[j]
                    wx = p * fx[i, m]
                    wy = p * fy[i, m]
                    bx -= mass[j] * wx
                    by -= mass[j] * wy
                    accx[j] += mi * wx
                    accy[j] += mi * wy
                accx[i] = bx
                accy[i] = by
        for i in prange(n):
            sx_, sy_ = bufx[0, i], bufy[0, i]
            for t in range(1, nt):
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
    """The pair list of one solver: padded rows, kernel factors, per-thread accumulators."""

    def __init__(self, scene, threads: int):
        dt = np.dtype(scene.precision)
        n = scene.n_particles
        self.kernels = kernels(scene.precision, threads > 1)
        self.threads = threads
        self._allocate(n, capacity(scene), dt)
        self.buf = np.zeros((threads, n), dt)
        self.bufy = np.zeros((threads, n), dt)
        self.scratch = None

    def _allocate(self, n, cap, dt):
        """The padded rows, touched at once: the first-touch page faults of a list of hundreds of MB
        (measured 2.5 s at 400K here) belong to the allocation (init), not to the first search."""
        self.nbr = np.zeros((n, cap), np.int32)
        self.fx = np.zeros((n, cap), dt)
        self.fy = np.zeros((n, cap), dt)
        self.count = np.zeros(n, np.int32)
        for arr in (self.nbr, self.fx, self.fy):
            arr.fill(0)

    def _scratch(self, begin, ncx) -> tuple:
        """Per-thread scratch rows long enough for any particle's candidates (two stencil rows of 3 cells)."""
        per_cell = np.diff(begin.astype(np.int64))
        rows = np.convolve(per_cell, np.ones(3, np.int64), mode="same")  # 3 consecutive cells (upper bound)
        need = 2 * int(rows.max(initial=0)) + 1
        if self.scratch is None or self.scratch[0].shape[1] < need:
            dt = self.fx.dtype
            self.scratch = (np.empty((self.threads, need), np.int32), np.empty((self.threads, need), dt),
                            np.empty((self.threads, need), dt), np.empty((self.threads, need), dt))
        return self.scratch

    def build(self, cell, begin, ncx, ncy, lx, ly, sx, sy, k) -> None:
        """List the pairs of the current (cell-ordered) positions; grow the rows if one overflowed."""
        scratch = self._scratch(begin, ncx)
        most = self.kernels["build"](cell, begin, ncx, ncy, lx, ly, sx, sy, self.nbr, self.fx, self.fy,
                                     self.count, *scratch, k)
        if most > self.nbr.shape[1]:
            self._allocate(lx.shape[0], int(most * CAPACITY_MARGIN) + 8, self.fx.dtype)
            self.kernels["build"](cell, begin, ncx, ncy, lx, ly, sx, sy, self.nbr, self.fx, self.fy,
                                  self.count, *scratch, k)

    def continuity(self, u, v, vol, drho, out, k) -> None:
        self.kernels["continuity"](self.nbr, self.fx, self.fy, self.count, u, v, vol, drho, out, self.buf, k)

    def momentum(self, mass, pr, ax, ay) -> None:
        self.kernels["momentum"](self.nbr, self.fx, self.fy, self.count, mass, pr, ax, ay, self.buf, self.bufy)

    @property
    def pairs(self) -> int:
        """Pairs listed, each once."""
        return int(self.count.sum())
