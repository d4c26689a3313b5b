"""The linked-list CPU solver's interaction loops in 3D over the trimmed stencil
(solvers.physics.pairs3d.stencil_rule; ``box`` its grid's box) or, for particles that stay on their sites, the
sites' table (site_rule; ``box`` is then the table of rows), serial or on numba's thread pool, and its per-particle
updates. A template of solvers.jitcache, specialised by solvers.linkedlist_cpu.sweeps."""

from numba import prange

P = None  # the 3D pair functions for numba's CPU target (solvers.physics.backend.cpu_pairs3d), bound by jitcache


def continuity(cell, begin, ncx, ncy, ncz, box, lx, ly, lz, sx, sy, sz, u, v, w, vol, drho, out, k):
    for i in prange(lx.shape[0]):
        out[i] = P.continuity_cells(i, cell, begin, ncx, ncy, ncz, box, lx, ly, lz, sx, sy, sz, u, v, w, vol, drho, k)


def continuity_split(cell, begin, ncx, ncy, ncz, box, lx, ly, lz, sx, sy, sz, u, v, w, vol, drho, out, outx, outy, k):
    """The continuity rate and its x and y parts (a split absorber's ddx and ddy) in one pass."""
    for i in prange(lx.shape[0]):
        out[i], outx[i], outy[i] = P.continuity_split_cells(
            i, cell, begin, ncx, ncy, ncz, box, lx, ly, lz, sx, sy, sz, u, v, w, vol, drho, k
        )


def momentum(cell, begin, ncx, ncy, ncz, box, lx, ly, lz, sx, sy, sz, mass, pr, ax, ay, az, k):
    for i in prange(lx.shape[0]):
        ax[i], ay[i], az[i] = P.momentum_cells(i, cell, begin, ncx, ncy, ncz, box, lx, ly, lz, sx, sy, sz, mass, pr, k)


def neighbours(cell, begin, ncx, ncy, ncz, box, lx, ly, lz, sx, sy, sz, k):
    total = 0
    for i in prange(lx.shape[0]):
        total += P.neighbours_cells(i, cell, begin, ncx, ncy, ncz, box, lx, ly, lz, sx, sy, sz, k)
    return total


def cell_ids(lx, ly, lz, sx, sy, sz, cell, dx, x_grid, width, height, depth, cw, ch, cd, ncx, ncy, ncz):
    """particleIndex of every particle, after moving the lattice coordinates of those past a periodic seam by a
    period (two loops, as in 2D: solvers/loops/cells.py)."""
    for i in prange(lx.shape[0]):
        P.wrap_at(i, lx, ly, lz, sx, sy, sz, dx, width, height, depth)
    for i in prange(lx.shape[0]):
        cell[i] = P.cell_index(
            lx[i], ly[i], lz[i], sx[i], sy[i], sz[i], dx, x_grid, width, height, depth, cw, ch, cd, ncx, ncy, ncz
        )


def moments(cell, begin, ncx, ncy, ncz, box, lx, ly, lz, sx, sy, sz, vol, mxx, mxy, mxz, myy, myz, mzz, gx, gy, gz, k):
    """The kernel gradient correction's moment matrix (6) and Gamma (3) of every particle (solvers/corrections/)."""
    for i in prange(lx.shape[0]):
        mxx[i], mxy[i], mxz[i], myy[i], myz[i], mzz[i], gx[i], gy[i], gz[i] = P.moments_cells(
            i, cell, begin, ncx, ncy, ncz, box, lx, ly, lz, sx, sy, sz, vol, k
        )
