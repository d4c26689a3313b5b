"""The CPU pair list's build (with the kernel's G) and its two sweeps, serial or on numba's threads (see
solvers/search/pairlist.py for the method). A template of solvers.jitcache, specialised by
solvers.search.pairlist.kernels."""

import numba
import numpy as np
from numba import prange

from solvers.kernels.constants import NONLIN, NX, NY, RC2, RHO0, SPACING
from solvers.physics.denormals import flush_off, flush_on
from solvers.search.compress import compress_within

# Loop indices are unsigned (U): numba then drops its negative-index wraparound, which otherwise
# turns every contiguous load into a gather and keeps the distance pass from vectorising
# (measured here: 163 -> 27 ns for 120 candidates in float64, 17 ns in float32).
U = np.uint64
P = None  # the pair functions for numba's CPU target (solvers.physics.backend.cpu_pairs), bound by solvers.jitcache
flush = (
    None  # True in float32: subnormals flushed to zero in the loops (solvers/physics/denormals.py), bound by jitcache
)


@numba.njit(inline="always")
def thread_sum(buf, i):
    """Particle i's sum over the threads' accumulator rows ``buf`` (threads, n), in thread order."""
    total = buf[0, i]
    for t in range(U(1), U(buf.shape[0])):
        total += buf[t, i]
    return total


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
            # the three cells of the row above (across the periodic seam: i shifted down by ny rows; none past a
            # free y edge)
            up = cy + U(1)
            above = True
            if up >= ncy:
                if k[NY] == 0:
                    above = False
                else:
                    up -= ncy
                    lyi = lyi - k[NY]
            if above:
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
                g = P.gradient(cr2[q], k)
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
        out[i] = (k[RHO0] + k[NONLIN] * drho[i]) * thread_sum(buf, i)


def continuity_split(nbr, fx, fy, start, count, u, v, vol, drho, out, outx, buf, bufx, k):
    """out = d(drho)/dt and outx its x part (the terms in u: a split absorber's ``ddx``) in one pass over the
    list; ``buf``, ``bufx`` hold one accumulator row per thread. The x part is what :func:`continuity` gives
    with v = 0, to round-off, for a sixth of the work of that second sweep."""
    n, nt = U(u.shape[0]), U(buf.shape[0])
    for tt in prange(nt):
        t = U(tt)
        saved = flush_on(flush)
        acc, accx = buf[t], bufx[t]
        acc[:] = 0
        accx[:] = 0
        for i in range(t * n // nt, (t + U(1)) * n // nt):
            ui, vi, voli = u[i], v[i], vol[i]
            a, ax = acc[i], accx[i]
            for m in range(U(start[i]), U(start[i]) + U(count[i])):
                j = U(nbr[m])
                sx = (ui - u[j]) * fx[m]
                s = sx + (vi - v[j]) * fy[m]
                a += vol[j] * s
                ax += vol[j] * sx
                acc[j] += voli * s
                accx[j] += voli * sx
            acc[i] = a
            accx[i] = ax
        flush_off(flush, saved)
    for i in prange(n):
        rho = k[RHO0] + k[NONLIN] * drho[i]
        out[i] = rho * thread_sum(buf, i)
        outx[i] = rho * thread_sum(bufx, i)


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
        ax[i] = thread_sum(bufx, i)
        ay[i] = thread_sum(bufy, i)


@numba.njit(inline="always")
def nearest(d, period):
    """A lattice offset ``d`` across a periodic seam of ``period`` columns (0: none) as its nearest image."""
    if period > 0:
        if d > 0.5 * period:
            return d - period
        if d < -0.5 * period:
            return d + period
    return d


def moments(nbr, fx, fy, start, count, lx, ly, sx, sy, vol, out, buf, k):
    """The kernel gradient correction's sums from the list (solvers/corrections/gradient.py), both sides of
    each pair: out = (M_xx, M_xy, M_yy, Gamma_x, Gamma_y) with M_i = -sum_j vol_j r_ij (x) f_ij and
    Gamma_i = sum_j vol_j f_ij (f = G r_ij, the list's factors; r_ij from the positions, across a periodic
    seam its nearest image). No kernel evaluation: a stream over the list like the sweeps. ``buf`` (threads,
    n, 5) holds each thread's accumulators, a particle's five side by side (one cache line for the scattered
    j side: five rows of n took twice the time, measured here)."""
    n, nt = U(lx.shape[0]), U(buf.shape[0])
    spacing, periods = k[SPACING], (k[NX], k[NY])  # locals: the accumulators' stores could alias k
    for tt in prange(nt):
        t = U(tt)
        saved = flush_on(flush)
        b = buf[t]
        b[:, :] = 0
        for i in range(t * n // nt, (t + U(1)) * n // nt):
            lxi, lyi, sxi, syi, voli = lx[i], ly[i], sx[i], sy[i], vol[i]
            bi = b[i]
            mxx, mxy, myy, gx, gy = bi[0], bi[1], bi[2], bi[3], bi[4]
            for m in range(U(start[i]), U(start[i]) + U(count[i])):
                j = U(nbr[m])
                rx = nearest(lxi - lx[j], periods[0]) * spacing + (sxi - sx[j])
                ry = nearest(lyi - ly[j], periods[1]) * spacing + (syi - sy[j])
                f1, f2 = fx[m], fy[m]
                pxx, pxy, pyy = rx * f1, rx * f2, ry * f2
                vj = vol[j]
                mxx -= vj * pxx
                mxy -= vj * pxy
                myy -= vj * pyy
                gx += vj * f1
                gy += vj * f2
                bj = b[j]
                bj[0] -= voli * pxx
                bj[1] -= voli * pxy
                bj[2] -= voli * pyy
                bj[3] -= voli * f1
                bj[4] -= voli * f2
            bi[0], bi[1], bi[2], bi[3], bi[4] = mxx, mxy, myy, gx, gy
        flush_off(flush, saved)
    for i in prange(n):
        for q in range(5):
            total = buf[0, i, q]
            for t in range(U(1), nt):
                total += buf[t, i, q]
            out[q, i] = total
