"""The GPU solver's device kernels on a 3D scene (numba-cuda), from the shared 3D pair physics: the search's
particleIndex, the pair sweeps over the trimmed stencil (solvers.physics.pairs3d.stencil_rule), the system update
and the gradient correction's passes with the third component. cellBegin's scan, the scatter and the coefficients
do not depend on the dimension: they are the 2D template's (solvers/loops/gpu.py). A template of solvers.jitcache,
specialised by solvers.gpu.cuda_kernels.kernels; ``cuda`` a module global as there."""

from numba import cuda

P = None  # the 3D pair functions as device functions (solvers.gpu.cuda_kernels.device_pairs3d), bound by jitcache
C = None  # the 2D pair functions (their per-particle coefficients), bound by jitcache


def cell_count(lx, ly, lz, sx, sy, sz, cell, rank, counts, dx, x_grid, width, height, depth, cw, ch, cd, ncx, ncy, ncz):
    """particleIndex and each particle's rank in its cell (atomics), after moving the lattice coordinates of those
    past a periodic seam by a period."""
    i = cuda.grid(1)
    if i < lx.shape[0]:
        P.wrap_at(i, lx, ly, lz, sx, sy, sz, dx, width, height, depth)
        c = P.cell_index(
            lx[i], ly[i], lz[i], sx[i], sy[i], sz[i], dx, x_grid, width, height, depth, cw, ch, cd, ncx, ncy, ncz
        )
        cell[i] = c
        rank[i] = cuda.atomic.add(counts, c, 1)


def continuity(cell, begin, ncx, ncy, ncz, box, lx, ly, lz, sx, sy, sz, u, v, w, vol, drho, out, k):
    i = cuda.grid(1)
    if i < lx.shape[0]:
        out[i] = P.continuity_cells(i, cell, begin, ncx, ncy, ncz, box, lx, ly, lz, sx, sy, sz, u, v, w, vol, drho, k)


def momentum(cell, begin, ncx, ncy, ncz, box, lx, ly, lz, sx, sy, sz, mass, pr, ax, ay, az, k):
    i = cuda.grid(1)
    if i < lx.shape[0]:
        bx, by, bz = P.momentum_cells(i, cell, begin, ncx, ncy, ncz, box, lx, ly, lz, sx, sy, sz, mass, pr, k)
        ax[i] = bx
        ay[i] = by
        az[i] = bz


def moments(cell, begin, ncx, ncy, ncz, box, lx, ly, lz, sx, sy, sz, vol, mxx, mxy, mxz, myy, myz, mzz, gx, gy, gz, k):
    """The kernel gradient correction's moment matrix (6) and Gamma (3) of every particle (solvers/corrections/)."""
    i = cuda.grid(1)
    if i < lx.shape[0]:
        a, b, c, d, e, f, p, q, r = P.moments_cells(i, cell, begin, ncx, ncy, ncz, box, lx, ly, lz, sx, sy, sz, vol, k)
        mxx[i] = a
        mxy[i] = b
        mxz[i] = c
        myy[i] = d
        myz[i] = e
        mzz[i] = f
        gx[i] = p
        gy[i] = q
        gz[i] = r


def neighbours(cell, begin, ncx, ncy, ncz, box, lx, ly, lz, sx, sy, sz, counts, k):
    i = cuda.grid(1)
    if i < lx.shape[0]:
        counts[i] = P.neighbours_cells(i, cell, begin, ncx, ncy, ncz, box, lx, ly, lz, sx, sy, sz, k)


def kick(u, v, w, ax, ay, az, c):
    i = cuda.grid(1)
    if i < u.shape[0]:
        P.kick_at(i, u, v, w, ax, ay, az, c)


def advance(drho, dd, sx, sy, sz, u, v, w, c, moving, mass, vol, pr, k):
    """The update, then both coefficients from the new drho (as in 2D: no coefficients launch before a sweep)."""
    i = cuda.grid(1)
    if i < drho.shape[0]:
        P.advance_at(i, drho, dd, sx, sy, sz, u, v, w, c, moving)
        C.coefficients_at(i, drho, mass, vol, pr, True, True, k)


def corrected_velocity(u, v, w, lxx, lxy, lxz, lyy, lyz, lzz, wx, wy, wz):
    i = cuda.grid(1)
    if i < u.shape[0]:
        P.corrected_velocity_at(i, u, v, w, lxx, lxy, lxz, lyy, lyz, lzz, wx, wy, wz)


def corrected_continuity(dd, drho, wx, wy, wz, gx, gy, gz, k):
    i = cuda.grid(1)
    if i < dd.shape[0]:
        P.corrected_continuity_at(i, dd, drho, wx, wy, wz, gx, gy, gz, k)


def corrected_momentum(ax, ay, az, drho, lxx, lxy, lxz, lyy, lyz, lzz, gx, gy, gz, k):
    i = cuda.grid(1)
    if i < ax.shape[0]:
        P.corrected_momentum_at(i, ax, ay, az, drho, lxx, lxy, lxz, lyy, lyz, lzz, gx, gy, gz, k)
