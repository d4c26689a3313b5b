"""The linked-list CPU solver's interaction loops over the 3x3 cell stencil, serial or on numba's thread
pool. A template of solvers.jitcache, specialised by solvers.linkedlist_cpu.sweeps."""

from numba import prange

from solvers.kernels.constants import NONLIN, RHO0

P = None  # the pair functions for numba's CPU target (solvers.physics.backend.cpu_pairs), bound by solvers.jitcache


def continuity(cell, begin, ncx, ncy, lx, ly, sx, sy, u, v, vol, drho, out, k):
    for i in prange(lx.shape[0]):
        out[i] = P.continuity_cells(i, cell, begin, ncx, ncy, lx, ly, sx, sy, u, v, vol, drho, k)


def momentum(cell, begin, ncx, ncy, lx, ly, sx, sy, mass, pr, ax, ay, k):
    for i in prange(lx.shape[0]):
        ax[i], ay[i] = P.momentum_cells(i, cell, begin, ncx, ncy, lx, ly, sx, sy, mass, pr, k)


def wall_continuity(cell, begin, ncx, ncy, lx, ly, sx, sy, u, v, vol, drho, out, k):
    """out += the mirror particles' part of d(drho)/dt, over the particles of the grid's edge columns only
    (the pair list holds the real pairs; at a wall the mirrors are the pairs across it)."""
    for cy in prange(ncy):
        for c in (cy * ncx, cy * ncx + ncx - 1):
            for i in range(begin[c], begin[c + 1]):
                rho = k[RHO0] + k[NONLIN] * drho[i]
                out[i] += rho * P.continuity_across(i, cell, begin, ncx, ncy, lx, ly, sx, sy, u, v, vol, k)


def wall_momentum(cell, begin, ncx, ncy, lx, ly, sx, sy, mass, pr, ax, ay, k):
    """ax, ay -= the mirror particles' part of the momentum sums, over the grid's edge columns only."""
    for cy in prange(ncy):
        for c in (cy * ncx, cy * ncx + ncx - 1):
            for i in range(begin[c], begin[c + 1]):
                bx, by = P.momentum_across(i, cell, begin, ncx, ncy, lx, ly, sx, sy, mass, pr, k)
                ax[i] -= bx
                ay[i] -= by


def wall_moments(cell, begin, ncx, ncy, lx, ly, sx, sy, vol, mxx, mxy, myy, gx, gy, k):
    """The mirror particles' part of the moment sums added, over the grid's edge columns only (with the pair
    list's :func:`moments`, which holds the real pairs)."""
    for cy in prange(ncy):
        for c in (cy * ncx, cy * ncx + ncx - 1):
            for i in range(begin[c], begin[c + 1]):
                a, b, d, e, f = P.moments_across(i, cell, begin, ncx, ncy, lx, ly, sx, sy, vol, k)
                mxx[i] += a
                mxy[i] += b
                myy[i] += d
                gx[i] += e
                gy[i] += f


def moments(cell, begin, ncx, ncy, lx, ly, sx, sy, vol, mxx, mxy, myy, gx, gy, k):
    """The kernel gradient correction's moment matrix and Gamma of every particle (solvers/corrections/)."""
    for i in prange(lx.shape[0]):
        mxx[i], mxy[i], myy[i], gx[i], gy[i] = P.moments_cells(i, cell, begin, ncx, ncy, lx, ly, sx, sy, vol, k)


def neighbours(cell, begin, ncx, ncy, lx, ly, sx, sy, k):
    total = 0
    for i in prange(lx.shape[0]):
        total += P.neighbours_cells(i, cell, begin, ncx, ncy, lx, ly, sx, sy, k)
    return total


def cell_ids(lx, ly, sx, sy, cell, dx, x_grid, width, height, cw, ch, ncx, ncy):
    """particleIndex of every particle, after moving the lattice coordinates of those past a periodic seam by
    a period. Two loops: the wrap writes only where a particle crossed, and the cells, written for every
    particle and read from nothing else, vectorise (one loop of both ran 16 times slower: 40 against 2.5 ns
    a particle, measured here at 400K)."""
    for i in prange(lx.shape[0]):
        P.wrap_at(i, lx, ly, sx, sy, dx, width, height)
    for i in prange(lx.shape[0]):
        cell[i] = P.cell_index(lx[i], ly[i], sx[i], sy[i], dx, x_grid, width, height, cw, ch, ncx, ncy)
