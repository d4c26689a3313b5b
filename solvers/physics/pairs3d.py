"""Particle interaction (PI) in 3D: the SPH rates of one particle, one factory per sum, for every backend.

The 3D counterpart of solvers/physics/pairs.py (which keeps the 2D scenes' compiled loops as they are): the same
physics with a third component,

    d(drho_i)/dt = rho_i sum_j vol_j (u_i - u_j) . r_ij G_ij
    du_i/dt      = -sum_j m_j (pr_i + pr_j) G_ij r_ij,

built as small factories, each one sum over a range of particles j0..j1-1, over one rule for the separation
(:func:`separation_rule`): r_ij = (l_i - l_j) dx + (s_i - s_j) per axis, the lattice part exact, as in 2D. The
cell list's stencil is the rows along x at the y and z offsets the grid's reach allows
(solvers.interface.stencil_reach), each trimmed to the cells the cutoff's sphere reaches (:func:`stencil_rule`)
and one contiguous range of particles sorted by cell, shifted across the y and z seams by whole periods
(``k[NY]``, ``k[NZ]``), with the periodic images across the x seam (``k[NX]``) as a second range per row, as in
2D; particles that stay on their sites have one cell a site and one table of rows (:func:`site_rule`).
:func:`make_pairs3d` assembles them into a module object that
numba resolves inside the sweeps (solvers/loops/cells3d.py, allpair3d.py).
"""

import math
from types import ModuleType

from solvers.kernels import kernel_named
from solvers.kernels.constants import C0SQ, NONLIN, NX, NY, NZ, ONE, RC2, RHO0, SPACING, ZERO

TRIM_SLACK = 1e-5  # of the cutoff: the stencil's trim never drops a pair the sums' rounding puts within the cutoff


def separation_rule(jit, displaced: bool = True):
    """r_ij's three components, m: particle i at lattice coordinates (lxi, lyi, lzi) (shifted across a seam where
    the sum is) and its own displacements, j at its own; the lattice part whole numbers, exact. ``displaced``
    False (every displacement zero for the whole run, :attr:`solvers.interface.Solver.displaced`): the lattice
    part alone, the same bits without the displacements' loads (a compile-time constant)."""

    @jit
    def separation(lxi, lyi, lzi, sxi, syi, szi, j, lx, ly, lz, sx, sy, sz, k):
        rx = (lxi - lx[j]) * k[SPACING]
        ry = (lyi - ly[j]) * k[SPACING]
        rz = (lzi - lz[j]) * k[SPACING]
        if displaced:
            rx += sxi - sx[j]
            ry += syi - sy[j]
            rz += szi - sz[j]
        return rx, ry, rz

    return separation


def continuity_sum(jit, separation, gradient):
    """``acc`` + sum_j vol_j (u_i - u_j) . r_ij G_ij over particles j0..j1-1 (i's coordinates already shifted;
    ``fields``: u, v, w, vol)."""

    @jit
    def continuity_range(j0, j1, lxi, lyi, lzi, i, lx, ly, lz, sx, sy, sz, k, acc, fields):
        u, v, w, vol = fields
        sxi, syi, szi, ui, vi, wi = sx[i], sy[i], sz[i], u[i], v[i], w[i]
        for j in range(j0, j1):
            rx, ry, rz = separation(lxi, lyi, lzi, sxi, syi, szi, j, lx, ly, lz, sx, sy, sz, k)
            r2 = rx * rx + ry * ry + rz * rz
            if r2 < k[RC2]:
                acc += vol[j] * gradient(r2, k) * ((ui - u[j]) * rx + (vi - v[j]) * ry + (wi - w[j]) * rz)
        return acc

    return continuity_range


def continuity_split_sum(jit, separation, gradient):
    """:func:`continuity_sum` and its x and y parts (the terms in u and in v: a split absorber's, the PML's) in one
    pass, ``acc`` = (whole, x part, y part); the whole summed as :func:`continuity_sum` sums it (the same
    rounding), each part as that sum does with the other components zero."""

    @jit
    def continuity_split_range(j0, j1, lxi, lyi, lzi, i, lx, ly, lz, sx, sy, sz, k, acc, fields):
        u, v, w, vol = fields
        whole, xpart, ypart = acc
        sxi, syi, szi, ui, vi, wi = sx[i], sy[i], sz[i], u[i], v[i], w[i]
        for j in range(j0, j1):
            rx, ry, rz = separation(lxi, lyi, lzi, sxi, syi, szi, j, lx, ly, lz, sx, sy, sz, k)
            r2 = rx * rx + ry * ry + rz * rz
            if r2 < k[RC2]:
                weight = vol[j] * gradient(r2, k)
                ux, vy = (ui - u[j]) * rx, (vi - v[j]) * ry
                whole += weight * (ux + vy + (wi - w[j]) * rz)
                xpart += weight * ux
                ypart += weight * vy
        return whole, xpart, ypart

    return continuity_split_range


def momentum_sum(jit, separation, gradient):
    """``acc`` + sum_j m_j (pr_i + pr_j) G_ij r_ij over particles j0..j1-1, as (x, y, z) (``fields``: mass, pr)."""

    @jit
    def momentum_range(j0, j1, lxi, lyi, lzi, i, lx, ly, lz, sx, sy, sz, k, acc, fields):
        mass, pr = fields
        ax, ay, az = acc
        sxi, syi, szi, pri = sx[i], sy[i], sz[i], pr[i]
        for j in range(j0, j1):
            rx, ry, rz = separation(lxi, lyi, lzi, sxi, syi, szi, j, lx, ly, lz, sx, sy, sz, k)
            r2 = rx * rx + ry * ry + rz * rz
            if r2 < k[RC2]:
                c = mass[j] * (pri + pr[j]) * gradient(r2, k)
                ax += c * rx
                ay += c * ry
                az += c * rz
        return ax, ay, az

    return momentum_range


def neighbour_count(jit, separation):
    """``acc`` + the particles j0..j1-1 within the cutoff (the particle itself included if in range)."""

    @jit
    def neighbours_range(j0, j1, lxi, lyi, lzi, i, lx, ly, lz, sx, sy, sz, k, acc, fields):
        sxi, syi, szi = sx[i], sy[i], sz[i]
        for j in range(j0, j1):
            rx, ry, rz = separation(lxi, lyi, lzi, sxi, syi, szi, j, lx, ly, lz, sx, sy, sz, k)
            if rx * rx + ry * ry + rz * rz < k[RC2]:
                acc += 1
        return acc

    return neighbours_range


def moment_sums(jit, separation, gradient):
    """The kernel gradient correction's sums over particles j0..j1-1 added to ``acc``: the moment matrix
    M = -sum_j vol_j G_ij r_ij (x) r_ij as (M_xx, M_xy, M_xz, M_yy, M_yz, M_zz) and Gamma = sum_j vol_j G_ij r_ij
    as (x, y, z) (``fields``: vol)."""

    @jit
    def moments_range(j0, j1, lxi, lyi, lzi, i, lx, ly, lz, sx, sy, sz, k, acc, fields):
        (vol,) = fields
        mxx, mxy, mxz, myy, myz, mzz, gx, gy, gz = acc
        sxi, syi, szi = sx[i], sy[i], sz[i]
        for j in range(j0, j1):
            rx, ry, rz = separation(lxi, lyi, lzi, sxi, syi, szi, j, lx, ly, lz, sx, sy, sz, k)
            r2 = rx * rx + ry * ry + rz * rz
            if r2 < k[RC2]:
                c = vol[j] * gradient(r2, k)
                gx += c * rx
                gy += c * ry
                gz += c * rz
                mxx -= c * rx * rx
                mxy -= c * rx * ry
                mxz -= c * rx * rz
                myy -= c * ry * ry
                myz -= c * ry * rz
                mzz -= c * rz * rz
        return mxx, mxy, mxz, myy, myz, mzz, gx, gy, gz

    return moments_range


def corrected_passes(jit):
    """The gradient correction's passes per particle in 3D (solvers/corrections/gradient.py), L = M^-1 as its six
    components (xx, xy, xz, yy, yz, zz)."""

    @jit
    def corrected_velocity_at(i, u, v, w, lxx, lxy, lxz, lyy, lyz, lzz, wx, wy, wz):
        """w_i = L_i u_i (m/s)."""
        wx[i] = lxx[i] * u[i] + lxy[i] * v[i] + lxz[i] * w[i]
        wy[i] = lxy[i] * u[i] + lyy[i] * v[i] + lyz[i] * w[i]
        wz[i] = lxz[i] * u[i] + lyz[i] * v[i] + lzz[i] * w[i]

    @jit
    def corrected_continuity_at(i, dd, drho, wx, wy, wz, gx, gy, gz, k):
        """d(drho_i)/dt -= 2 rho_i w_i . Gamma_i."""
        rho2 = (k[RHO0] + k[NONLIN] * drho[i]) * (k[ONE] + k[ONE])
        dd[i] -= rho2 * (wx[i] * gx[i] + wy[i] * gy[i] + wz[i] * gz[i])

    @jit
    def corrected_momentum_at(i, ax, ay, az, drho, lxx, lxy, lxz, lyy, lyz, lzz, gx, gy, gz, k):
        """du_i/dt = -L_i (sum_j V_j (p_j - p_i) grad_i W_ij) / rho_i from the sweep's
        -sum_j V_j (drho_i + drho_j) grad_i W_ij in (ax, ay, az)."""
        rho = k[RHO0] + k[NONLIN] * drho[i]
        twice = (k[ONE] + k[ONE]) * drho[i]
        bx = k[C0SQ] * (ax[i] + twice * gx[i])
        by = k[C0SQ] * (ay[i] + twice * gy[i])
        bz = k[C0SQ] * (az[i] + twice * gz[i])
        ax[i] = (lxx[i] * bx + lxy[i] * by + lxz[i] * bz) / rho
        ay[i] = (lxy[i] * bx + lyy[i] * by + lyz[i] * bz) / rho
        az[i] = (lxz[i] * bx + lyz[i] * by + lzz[i] * bz) / rho

    return corrected_velocity_at, corrected_continuity_at, corrected_momentum_at


def seam_rule(jit):
    """``shifted(c, n, li, period)``: (cell index, i's coordinate) for a stencil offset that may cross a seam of
    ``period`` lattice rows (0: a free edge: the cell index -1 means no cell)."""

    @jit
    def shifted(c, n, li, period):
        if c < 0:
            return (c + n, li + period) if period > 0 else (-1, li)
        if c >= n:
            return (c - n, li - period) if period > 0 else (-1, li)
        return c, li

    return shifted


def stencil_rule(jit, across: bool):
    """The 3D stencil as a loop: ``over_stencil(range_sum)`` gives the function that adds ``range_sum`` over every
    particle within the cutoff of particle i (and some beyond, which the sums' own test drops). The grid
    (solvers.interface.cell_grid_3d) has cells a cutoff over its reach wide along each axis (the ``box``: the
    lattice spacing, ``x_grid``, the cells' sizes and the reaches, cells a cutoff spans along x, y, z); the rows
    along x at every y and z offset within the reach are each trimmed to the cells the cutoff's sphere reaches:
    the row's gap from i in y and z leaves a chord in x, and a row the sphere misses is skipped. A row is one
    contiguous range of particles sorted by cell, i's coordinates shifted across the y and z seams by whole
    periods, with the chord's part beyond the x seam as a second range (``across`` False: x has no seam, a
    compile-time constant). i's cell and place in it are found once per particle, the gap once per slab. The
    trim is widened by ``TRIM_SLACK`` of the cutoff, so that a particle a rounding within it is never trimmed
    away."""

    shifted = seam_rule(jit)

    @jit
    def gap(p, d, size):
        """The distance, m, from a point ``p`` m above its cell's lower face to the slab of cells ``d`` away."""
        if d > 0:
            return max(d * size - p, 0.0)
        if d < 0:
            return max(p - (d + 1) * size, 0.0)
        return 0.0

    def over_stencil(range_sum):
        @jit
        def stencil_sum(i, cell, begin, ncx, ncy, ncz, box, lx, ly, lz, sx, sy, sz, k, acc, fields):
            c = cell[i]
            cx = c % ncx
            cy0 = c // ncx % ncy
            cz0 = c // (ncx * ncy)
            spacing = box[0]
            px = (float(lx[i]) + 0.5) * spacing + float(sx[i]) - box[1] - cx * box[2]  # m above its cell's faces
            py = (float(ly[i]) + 0.5) * spacing + float(sy[i]) - cy0 * box[3]
            pz = (float(lz[i]) + 0.5) * spacing + float(sz[i]) - cz0 * box[4]
            reach = math.sqrt(float(k[RC2])) * (1.0 + TRIM_SLACK)
            rx, ry, rz = int(box[5]), int(box[6]), int(box[7])
            for dz in range(-rz, rz + 1):
                gz = gap(pz, dz, box[4])
                left = reach * reach - gz * gz
                if left < 0.0:
                    continue
                cz, lzi = shifted(cz0 + dz, ncz, lz[i], k[NZ])
                if cz < 0:
                    continue
                for dy in range(-ry, ry + 1):
                    gy = gap(py, dy, box[3])
                    chord2 = left - gy * gy
                    if chord2 < 0.0:
                        continue
                    cy, lyi = shifted(cy0 + dy, ncy, ly[i], k[NY])
                    if cy < 0:
                        continue
                    chord = math.sqrt(chord2)
                    x0 = max(cx + int(math.floor((px - chord) / box[2])), cx - rx)
                    x1 = min(cx + int(math.floor((px + chord) / box[2])), cx + rx)
                    row = (cz * ncy + cy) * ncx
                    if across and k[NX] > 0:
                        if x0 < 0:  # the chord's left end lies beyond the seam: the row's last cells, i a period right
                            a0, a1 = begin[row + ncx + x0], begin[row + ncx]
                            acc = range_sum(a0, a1, lx[i] + k[NX], lyi, lzi, i, lx, ly, lz, sx, sy, sz, k, acc, fields)
                        elif x1 > ncx - 1:  # its right end: the row's first cells, i a period left
                            a0, a1 = begin[row], begin[row + x1 - ncx + 1]
                            acc = range_sum(a0, a1, lx[i] - k[NX], lyi, lzi, i, lx, ly, lz, sx, sy, sz, k, acc, fields)
                    x0 = max(x0, 0)
                    x1 = min(x1, ncx - 1)
                    if x1 >= x0:
                        a0, a1 = begin[row + x0], begin[row + x1 + 1]
                        acc = range_sum(a0, a1, lx[i], lyi, lzi, i, lx, ly, lz, sx, sy, sz, k, acc, fields)
            return acc

        return stencil_sum

    return over_stencil


def site_rule(jit, across: bool):
    """The 3D stencil over the sites' grid: ``over_sites(range_sum)`` gives the function that adds ``range_sum``
    over the cells within the table's reach of particle i's (the cutoff, widened by twice the largest
    displacement where particles move: solvers.search.celllist.CellList.widen). The grid
    (solvers.search.celllist.SiteGrid3D) has one cell a site, so every particle's stencil is the same table of
    ``rows`` (dy, dz, m: solvers.search.sites.site_rows): row (dy, dz) is cells cx - m..cx + m of the line dy, dz
    away, one contiguous range of particles, i shifted across the y and z seams and the part beyond the x seam a
    second range, as in :func:`stencil_rule`, whose chord and trim this needs neither."""
    shifted = seam_rule(jit)

    def over_sites(range_sum):
        @jit
        def site_sum(i, cell, begin, ncx, ncy, ncz, rows, lx, ly, lz, sx, sy, sz, k, acc, fields):
            c = cell[i]
            cx = c % ncx
            cy0 = c // ncx % ncy
            cz0 = c // (ncx * ncy)
            n = -rows[0, 1]  # the table's reach in cells (its first row is the lowest line, its own row m = n)
            if n <= cx < ncx - n and n <= cy0 < ncy - n and n <= cz0 < ncz - n:  # no row meets a seam or an edge
                lxi, lyi, lzi = lx[i], ly[i], lz[i]
                for r in range(rows.shape[0]):
                    mid = c + (rows[r, 1] * ncy + rows[r, 0]) * ncx
                    acc = range_sum(begin[mid - rows[r, 2]], begin[mid + rows[r, 2] + 1], lxi, lyi, lzi, i, lx, ly,
                                    lz, sx, sy, sz, k, acc, fields)  # fmt: skip
                return acc
            for r in range(rows.shape[0]):
                cz, lzi = shifted(cz0 + rows[r, 1], ncz, lz[i], k[NZ])
                cy, lyi = shifted(cy0 + rows[r, 0], ncy, ly[i], k[NY])
                if cz < 0 or cy < 0:
                    continue
                x0, x1 = cx - rows[r, 2], cx + rows[r, 2]
                row = (cz * ncy + cy) * ncx
                if across and k[NX] > 0:
                    if x0 < 0:  # the row's left end lies beyond the seam: the row's last cells, i a period right
                        a0, a1 = begin[row + ncx + x0], begin[row + ncx]
                        acc = range_sum(a0, a1, lx[i] + k[NX], lyi, lzi, i, lx, ly, lz, sx, sy, sz, k, acc, fields)
                    elif x1 > ncx - 1:  # its right end: the row's first cells, i a period left
                        a0, a1 = begin[row], begin[row + x1 - ncx + 1]
                        acc = range_sum(a0, a1, lx[i] - k[NX], lyi, lzi, i, lx, ly, lz, sx, sy, sz, k, acc, fields)
                x0 = max(x0, 0)
                x1 = min(x1, ncx - 1)
                if x1 >= x0:
                    a0, a1 = begin[row + x0], begin[row + x1 + 1]
                    acc = range_sum(a0, a1, lx[i], lyi, lzi, i, lx, ly, lz, sx, sy, sz, k, acc, fields)
            return acc

        return site_sum

    return over_sites


def minimum_image_rule(jit):
    """The all-pair search as a loop: ``over_all(range_sum)`` adds ``range_sum`` over every particle j, i shifted
    to the nearest image of j along each periodic axis (exact)."""

    @jit
    def nearest(li, lj, period):
        if period > 0:
            d = li - lj
            if d > 0.5 * period:
                return li - period
            if d < -0.5 * period:
                return li + period
        return li

    def over_all(range_sum):
        @jit
        def all_sum(i, n, lx, ly, lz, sx, sy, sz, k, acc, fields):
            for j in range(n):
                lxi, lyi, lzi = nearest(lx[i], lx[j], k[NX]), nearest(ly[i], ly[j], k[NY]), nearest(lz[i], lz[j], k[NZ])
                acc = range_sum(j, j + 1, lxi, lyi, lzi, i, lx, ly, lz, sx, sy, sz, k, acc, fields)
            return acc

        return all_sum

    return over_all


def make_pairs3d(
    jit, exp_neg, kernel: str, precision: str, across: bool = True, displaced: bool = True, sites: bool = False
) -> ModuleType:
    """The 3D pair functions compiled with ``jit`` for ``kernel`` (normalised in 3D) in ``precision``: each sum
    over a range, over the stencil (``*_cells``) and over every particle (``*_allpair``), and the cell index of a
    position. ``across``: whether x has a periodic seam; ``displaced``: whether particles can leave their lattice
    sites (:func:`separation_rule`); ``sites``: the stencil of :func:`site_rule` over the sites' grid (the CPU's),
    else :func:`stencil_rule`'s over the trimmed grid (the GPU's); all three compile-time."""
    gradient = jit(kernel_named(kernel).compiled_gradient(precision, jit(exp_neg), dims=3))
    separation = separation_rule(jit, displaced)
    continuity_range = continuity_sum(jit, separation, gradient)
    continuity_split_range = continuity_split_sum(jit, separation, gradient)
    momentum_range = momentum_sum(jit, separation, gradient)
    neighbours_range = neighbour_count(jit, separation)
    moments_range = moment_sums(jit, separation, gradient)
    corrected_velocity_at, corrected_continuity_at, corrected_momentum_at = corrected_passes(jit)
    over_stencil = site_rule(jit, across) if sites else stencil_rule(jit, across)
    over_all = minimum_image_rule(jit)
    continuity_stencil, continuity_all = over_stencil(continuity_range), over_all(continuity_range)
    continuity_split_stencil = over_stencil(continuity_split_range)
    momentum_stencil, momentum_all = over_stencil(momentum_range), over_all(momentum_range)
    neighbours_stencil, neighbours_all = over_stencil(neighbours_range), over_all(neighbours_range)
    moments_stencil, moments_all = over_stencil(moments_range), over_all(moments_range)

    @jit
    def moments_cells(i, cell, begin, ncx, ncy, ncz, box, lx, ly, lz, sx, sy, sz, vol, k):
        """Particle i's moment matrix (6) and Gamma (3) from the stencil around it (solvers/corrections/)."""
        z = k[ZERO]
        acc = (z, z, z, z, z, z, z, z, z)
        return moments_stencil(i, cell, begin, ncx, ncy, ncz, box, lx, ly, lz, sx, sy, sz, k, acc, (vol,))

    @jit
    def moments_allpair(i, n, lx, ly, lz, sx, sy, sz, vol, k):
        """Particle i's moment matrix and Gamma summed over all n particles (the nearest image)."""
        z = k[ZERO]
        return moments_all(i, n, lx, ly, lz, sx, sy, sz, k, (z, z, z, z, z, z, z, z, z), (vol,))

    @jit
    def continuity_cells(i, cell, begin, ncx, ncy, ncz, box, lx, ly, lz, sx, sy, sz, u, v, w, vol, drho, k):
        """d(drho_i)/dt from the stencil around particle i, kg/m^3/s."""
        fields = (u, v, w, vol)
        acc = continuity_stencil(i, cell, begin, ncx, ncy, ncz, box, lx, ly, lz, sx, sy, sz, k, k[ZERO], fields)
        return (k[RHO0] + k[NONLIN] * drho[i]) * acc

    @jit
    def continuity_split_cells(i, cell, begin, ncx, ncy, ncz, box, lx, ly, lz, sx, sy, sz, u, v, w, vol, drho, k):
        """d(drho_i)/dt and its x and y parts (the terms in u, in v) from the stencil around particle i,
        kg/m^3/s."""
        z = k[ZERO]
        fields = (u, v, w, vol)
        whole, xpart, ypart = continuity_split_stencil(
            i, cell, begin, ncx, ncy, ncz, box, lx, ly, lz, sx, sy, sz, k, (z, z, z), fields
        )
        factor = k[RHO0] + k[NONLIN] * drho[i]
        return factor * whole, factor * xpart, factor * ypart

    @jit
    def momentum_cells(i, cell, begin, ncx, ncy, ncz, box, lx, ly, lz, sx, sy, sz, mass, pr, k):
        """du_i/dt from the stencil around particle i, m/s^2, as (x, y, z)."""
        z = k[ZERO]
        acc = (z, z, z)
        ax, ay, az = momentum_stencil(i, cell, begin, ncx, ncy, ncz, box, lx, ly, lz, sx, sy, sz, k, acc, (mass, pr))
        return -ax, -ay, -az

    @jit
    def neighbours_cells(i, cell, begin, ncx, ncy, ncz, box, lx, ly, lz, sx, sy, sz, k):
        """Neighbours of particle i within the cutoff, itself excluded."""
        return neighbours_stencil(i, cell, begin, ncx, ncy, ncz, box, lx, ly, lz, sx, sy, sz, k, 0, ()) - 1

    @jit
    def continuity_allpair(i, n, lx, ly, lz, sx, sy, sz, u, v, w, vol, drho, k):
        """d(drho_i)/dt summed over all n particles (the nearest image along periodic axes)."""
        acc = continuity_all(i, n, lx, ly, lz, sx, sy, sz, k, k[ZERO], (u, v, w, vol))
        return (k[RHO0] + k[NONLIN] * drho[i]) * acc

    @jit
    def momentum_allpair(i, n, lx, ly, lz, sx, sy, sz, mass, pr, k):
        """du_i/dt summed over all n particles, as (x, y, z)."""
        z = k[ZERO]
        ax, ay, az = momentum_all(i, n, lx, ly, lz, sx, sy, sz, k, (z, z, z), (mass, pr))
        return -ax, -ay, -az

    @jit
    def neighbours_allpair(i, n, lx, ly, lz, sx, sy, sz, k):
        return neighbours_all(i, n, lx, ly, lz, sx, sy, sz, k, 0, ()) - 1

    @jit
    def cell_index(lx, ly, lz, sx, sy, sz, dx, x_grid, width, height, depth, cw, ch, cd, ncx, ncy, ncz):
        """particleIndex of one particle, (cz ncy + cy) ncx + cx: modulo each periodic axis's period, clamped
        into the grid along the others (a free axis's grid has a spare cell each side)."""
        x = (float(lx) + 0.5) * dx + float(sx)
        y = (float(ly) + 0.5) * dx + float(sy)
        z = (float(lz) + 0.5) * dx + float(sz)
        if width > 0:
            x = x - math.floor(x / width) * width
        if height > 0:
            y = y - math.floor(y / height) * height
        if depth > 0:
            z = z - math.floor(z / depth) * depth
        cx = min(max(int(math.floor((x - x_grid) / cw)), 0), ncx - 1)
        cy = min(max(int(math.floor(y / ch)), 0), ncy - 1)
        cz = min(max(int(math.floor(z / cd)), 0), ncz - 1)
        return (cz * ncy + cy) * ncx + cx

    @jit
    def wrap_at(i, lx, ly, lz, sx, sy, sz, dx, width, height, depth):
        """Particle i's lattice coordinates moved by whole periods back into the box when it has crossed a
        periodic seam (the same position, exactly; a period 0: that axis is not periodic)."""
        for site, shift, period in ((lx, sx, width), (ly, sy, height), (lz, sz, depth)):
            if period > 0:
                p = (float(site[i]) + 0.5) * dx + float(shift[i])
                if p >= period:
                    site[i] -= math.floor(period / dx + 0.5)
                elif p < 0:
                    site[i] += math.floor(period / dx + 0.5)

    @jit
    def kick_at(i, u, v, w, ax, ay, az, c):
        """u_i += c a_i (c = f dt, s)."""
        u[i] += c * ax[i]
        v[i] += c * ay[i]
        w[i] += c * az[i]

    @jit
    def advance_at(i, drho, dd, sx, sy, sz, u, v, w, c, moving):
        """drho_i += c D_i and, for moving particles, x_i += c u_i (c = f dt, s)."""
        drho[i] += c * dd[i]
        if moving:
            sx[i] += c * u[i]
            sy[i] += c * v[i]
            sz[i] += c * w[i]

    pairs = ModuleType(f"{__name__}.compiled", "The 3D pair functions for one backend (see make_pairs3d).")
    pairs.__dict__.update(
        gradient=gradient,
        separation=separation,
        continuity_range=continuity_range,
        momentum_range=momentum_range,
        neighbours_range=neighbours_range,
        moments_range=moments_range,
        moments_cells=moments_cells,
        moments_allpair=moments_allpair,
        corrected_velocity_at=corrected_velocity_at,
        corrected_continuity_at=corrected_continuity_at,
        corrected_momentum_at=corrected_momentum_at,
        continuity_cells=continuity_cells,
        continuity_split_cells=continuity_split_cells,
        momentum_cells=momentum_cells,
        neighbours_cells=neighbours_cells,
        continuity_allpair=continuity_allpair,
        momentum_allpair=momentum_allpair,
        neighbours_allpair=neighbours_allpair,
        cell_index=cell_index,
        wrap_at=wrap_at,
        kick_at=kick_at,
        advance_at=advance_at,
    )
    return pairs
