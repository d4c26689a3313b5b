"""Particle interaction (PI) in 3D: the SPH rates of one particle, one factory per sum, for every backend.

The 3D counterpart of solvers/physics/pairs.py (which keeps the 2D scenes' compiled loops as they are): the same
physics with a third component,

    d(drho_i)/dt = rho_i sum_j vol_j (u_i - u_j) . r_ij G_ij
    du_i/dt      = -sum_j m_j (pr_i + pr_j) G_ij r_ij,

built as small factories, each one sum over a range of particles j0..j1-1, over one rule for the separation
(:func:`separation_rule`): r_ij = (l_i - l_j) dx + (s_i - s_j) per axis, the lattice part exact, as in 2D. The
cell list's stencil is 27 cells: nine rows of three (y and z offsets -1, 0, 1), each one contiguous range of
particles sorted by cell, shifted across the y and z seams by whole periods (``k[NY]``, ``k[NZ]``), and the
periodic images across the x seam (``k[NX]``) as a second range per row, as in 2D. :func:`make_pairs3d` assembles
them into a module object that numba resolves inside the sweeps (solvers/loops/cells3d.py, allpair3d.py).
"""

import math
from types import ModuleType

from solvers.kernels import kernel_named
from solvers.kernels.constants import C0SQ, NONLIN, NX, NY, NZ, ONE, RC2, RHO0, SPACING, ZERO


def separation_rule(jit):
    """r_ij's three components, m: particle i at lattice coordinates (lxi, lyi, lzi) (shifted across a seam where
    the sum is) and its own displacements, j at its own; the lattice part whole numbers, exact."""

    @jit
    def separation(lxi, lyi, lzi, i, j, lx, ly, lz, sx, sy, sz, k):
        rx = (lxi - lx[j]) * k[SPACING] + (sx[i] - sx[j])
        ry = (lyi - ly[j]) * k[SPACING] + (sy[i] - sy[j])
        rz = (lzi - lz[j]) * k[SPACING] + (sz[i] - sz[j])
        return rx, ry, rz

    return separation


def continuity_sum(jit, separation, gradient):
    """sum_j vol_j (u_i - u_j) . r_ij G_ij over particles j0..j1-1 (i's coordinates already shifted)."""

    @jit
    def continuity_range(j0, j1, lxi, lyi, lzi, i, lx, ly, lz, sx, sy, sz, u, v, w, vol, k):
        acc = k[ZERO]
        for j in range(j0, j1):
            rx, ry, rz = separation(lxi, lyi, lzi, i, j, lx, ly, lz, sx, sy, sz, k)
            r2 = rx * rx + ry * ry + rz * rz
            if r2 < k[RC2]:
                acc += vol[j] * gradient(r2, k) * ((u[i] - u[j]) * rx + (v[i] - v[j]) * ry + (w[i] - w[j]) * rz)
        return acc

    return continuity_range


def momentum_sum(jit, separation, gradient):
    """sum_j m_j (pr_i + pr_j) G_ij r_ij over particles j0..j1-1, as (x, y, z)."""

    @jit
    def momentum_range(j0, j1, lxi, lyi, lzi, i, lx, ly, lz, sx, sy, sz, mass, pr, k):
        ax = k[ZERO]
        ay = k[ZERO]
        az = k[ZERO]
        for j in range(j0, j1):
            rx, ry, rz = separation(lxi, lyi, lzi, i, j, lx, ly, lz, sx, sy, sz, k)
            r2 = rx * rx + ry * ry + rz * rz
            if r2 < k[RC2]:
                c = mass[j] * (pr[i] + pr[j]) * gradient(r2, k)
                ax += c * rx
                ay += c * ry
                az += c * rz
        return ax, ay, az

    return momentum_range


def neighbour_count(jit, separation):
    """Particles j0..j1-1 within the cutoff (the particle itself included if in range)."""

    @jit
    def neighbours_range(j0, j1, lxi, lyi, lzi, i, lx, ly, lz, sx, sy, sz, k):
        count = 0
        for j in range(j0, j1):
            rx, ry, rz = separation(lxi, lyi, lzi, i, j, lx, ly, lz, sx, sy, sz, k)
            if rx * rx + ry * ry + rz * rz < k[RC2]:
                count += 1
        return count

    return neighbours_range


def moment_sums(jit, separation, gradient):
    """The kernel gradient correction's sums over particles j0..j1-1: the moment matrix
    M = -sum_j vol_j G_ij r_ij (x) r_ij as (M_xx, M_xy, M_xz, M_yy, M_yz, M_zz) and Gamma = sum_j vol_j G_ij r_ij
    as (x, y, z)."""

    @jit
    def moments_range(j0, j1, lxi, lyi, lzi, i, lx, ly, lz, sx, sy, sz, vol, k):
        mxx = k[ZERO]
        mxy = k[ZERO]
        mxz = k[ZERO]
        myy = k[ZERO]
        myz = k[ZERO]
        mzz = k[ZERO]
        gx = k[ZERO]
        gy = k[ZERO]
        gz = k[ZERO]
        for j in range(j0, j1):
            rx, ry, rz = separation(lxi, lyi, lzi, i, j, lx, ly, lz, sx, sy, sz, k)
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


def stencil_rule(jit, across: bool):
    """The 27-cell stencil: :func:`stencil_row` gives row (dy, dz) of particle i's stencil as its range of
    particles, i's coordinates shifted across the y and z seams, and the range across the x seam (empty unless
    i's cell is at it, or ``across`` False: x has no seam, a compile-time constant)."""

    @jit
    def shifted(c, n, li, period):
        """(cell index, i's coordinate) for a stencil offset that may cross a seam of ``period`` lattice rows (0:
        a free edge: the cell index -1 means no cell)."""
        if c < 0:
            return (c + n, li + period) if period > 0 else (-1, li)
        if c >= n:
            return (c - n, li - period) if period > 0 else (-1, li)
        return c, li

    @jit
    def stencil_row(i, dy, dz, cell, begin, ncx, ncy, ncz, lx, ly, lz, k):
        """(j0, j1, lyi, lzi, q0, q1, lxq): the row's own range, i's shifted y and z, and the range beyond the x
        seam with i's column shifted for it."""
        c = cell[i]
        cx = c % ncx
        cy, lyi = shifted(c // ncx % ncy + dy, ncy, ly[i], k[NY])
        cz, lzi = shifted(c // (ncx * ncy) + dz, ncz, lz[i], k[NZ])
        if cy < 0 or cz < 0:
            return 0, 0, lyi, lzi, 0, 0, lx[i]
        row = (cz * ncy + cy) * ncx
        x0 = cx - 1 if cx > 0 else 0
        x1 = cx + 1 if cx < ncx - 1 else ncx - 1
        q0 = begin[row]
        q1 = q0
        lxq = lx[i]
        if across and k[NX] > 0:
            if cx == 0:
                q0, q1 = begin[row + ncx - 1], begin[row + ncx]
                lxq = lx[i] + k[NX]
            elif cx == ncx - 1:
                q0, q1 = begin[row], begin[row + 1]
                lxq = lx[i] - k[NX]
        return begin[row + x0], begin[row + x1 + 1], lyi, lzi, q0, q1, lxq

    return stencil_row


def minimum_image_rule(jit):
    """The all-pair search's shift of i's coordinate to the nearest image of j along a periodic axis (exact)."""

    @jit
    def nearest(li, lj, period):
        if period > 0:
            d = li - lj
            if d > 0.5 * period:
                return li - period
            if d < -0.5 * period:
                return li + period
        return li

    return nearest


def make_pairs3d(jit, exp_neg, kernel: str, precision: str, across: bool = True) -> ModuleType:
    """The 3D pair functions compiled with ``jit`` for ``kernel`` (normalised in 3D) in ``precision``: the sums
    over a range, over the 27-cell stencil (``*_cells``) and over every particle (``*_allpair``), and the cell
    index of a position. ``across``: whether x has a periodic seam (compile-time)."""
    gradient = jit(kernel_named(kernel).compiled_gradient(precision, jit(exp_neg), dims=3))
    separation = separation_rule(jit)
    continuity_range = continuity_sum(jit, separation, gradient)
    momentum_range = momentum_sum(jit, separation, gradient)
    neighbours_range = neighbour_count(jit, separation)
    moments_range = moment_sums(jit, separation, gradient)
    corrected_velocity_at, corrected_continuity_at, corrected_momentum_at = corrected_passes(jit)
    stencil_row = stencil_rule(jit, across)
    nearest = minimum_image_rule(jit)

    @jit
    def moments_cells(i, cell, begin, ncx, ncy, ncz, lx, ly, lz, sx, sy, sz, vol, k):
        """Particle i's moment matrix (6) and Gamma (3) from the 27 cells around it (solvers/corrections/)."""
        m0 = m1 = m2 = m3 = m4 = m5 = g0 = g1 = g2 = k[ZERO]
        for dz in range(-1, 2):
            for dy in range(-1, 2):
                j0, j1, lyi, lzi, q0, q1, lxq = stencil_row(i, dy, dz, cell, begin, ncx, ncy, ncz, lx, ly, lz, k)
                for a0, a1, lxi in ((j0, j1, lx[i]), (q0, q1, lxq)):  # the row, then beyond the x seam
                    a, b, c, d, e, f, p, q, r = moments_range(a0, a1, lxi, lyi, lzi, i, lx, ly, lz, sx, sy, sz, vol, k)
                    m0 += a
                    m1 += b
                    m2 += c
                    m3 += d
                    m4 += e
                    m5 += f
                    g0 += p
                    g1 += q
                    g2 += r
        return m0, m1, m2, m3, m4, m5, g0, g1, g2

    @jit
    def moments_allpair(i, n, lx, ly, lz, sx, sy, sz, vol, k):
        """Particle i's moment matrix and Gamma summed over all n particles (the nearest image)."""
        m0 = m1 = m2 = m3 = m4 = m5 = g0 = g1 = g2 = k[ZERO]
        for j in range(n):
            lxi, lyi, lzi = nearest(lx[i], lx[j], k[NX]), nearest(ly[i], ly[j], k[NY]), nearest(lz[i], lz[j], k[NZ])
            a, b, c, d, e, f, p, q, r = moments_range(j, j + 1, lxi, lyi, lzi, i, lx, ly, lz, sx, sy, sz, vol, k)
            m0 += a
            m1 += b
            m2 += c
            m3 += d
            m4 += e
            m5 += f
            g0 += p
            g1 += q
            g2 += r
        return m0, m1, m2, m3, m4, m5, g0, g1, g2

    @jit
    def continuity_cells(i, cell, begin, ncx, ncy, ncz, lx, ly, lz, sx, sy, sz, u, v, w, vol, drho, k):
        """d(drho_i)/dt from the 27 cells around particle i, kg/m^3/s."""
        acc = k[ZERO]
        for dz in range(-1, 2):
            for dy in range(-1, 2):
                j0, j1, lyi, lzi, q0, q1, lxq = stencil_row(i, dy, dz, cell, begin, ncx, ncy, ncz, lx, ly, lz, k)
                for a0, a1, lxi in ((j0, j1, lx[i]), (q0, q1, lxq)):  # the row, then beyond the x seam
                    acc += continuity_range(a0, a1, lxi, lyi, lzi, i, lx, ly, lz, sx, sy, sz, u, v, w, vol, k)
        return (k[RHO0] + k[NONLIN] * drho[i]) * acc

    @jit
    def momentum_cells(i, cell, begin, ncx, ncy, ncz, lx, ly, lz, sx, sy, sz, mass, pr, k):
        """du_i/dt from the 27 cells around particle i, m/s^2, as (x, y, z)."""
        ax = k[ZERO]
        ay = k[ZERO]
        az = k[ZERO]
        for dz in range(-1, 2):
            for dy in range(-1, 2):
                j0, j1, lyi, lzi, q0, q1, lxq = stencil_row(i, dy, dz, cell, begin, ncx, ncy, ncz, lx, ly, lz, k)
                for a0, a1, lxi in ((j0, j1, lx[i]), (q0, q1, lxq)):
                    bx, by, bz = momentum_range(a0, a1, lxi, lyi, lzi, i, lx, ly, lz, sx, sy, sz, mass, pr, k)
                    ax += bx
                    ay += by
                    az += bz
        return -ax, -ay, -az

    @jit
    def neighbours_cells(i, cell, begin, ncx, ncy, ncz, lx, ly, lz, sx, sy, sz, k):
        """Neighbours of particle i within the cutoff, itself excluded."""
        count = 0
        for dz in range(-1, 2):
            for dy in range(-1, 2):
                j0, j1, lyi, lzi, q0, q1, lxq = stencil_row(i, dy, dz, cell, begin, ncx, ncy, ncz, lx, ly, lz, k)
                for a0, a1, lxi in ((j0, j1, lx[i]), (q0, q1, lxq)):
                    count += neighbours_range(a0, a1, lxi, lyi, lzi, i, lx, ly, lz, sx, sy, sz, k)
        return count - 1

    @jit
    def continuity_allpair(i, n, lx, ly, lz, sx, sy, sz, u, v, w, vol, drho, k):
        """d(drho_i)/dt summed over all n particles (the nearest image along periodic axes)."""
        acc = k[ZERO]
        for j in range(n):
            lxi, lyi, lzi = nearest(lx[i], lx[j], k[NX]), nearest(ly[i], ly[j], k[NY]), nearest(lz[i], lz[j], k[NZ])
            acc += continuity_range(j, j + 1, lxi, lyi, lzi, i, lx, ly, lz, sx, sy, sz, u, v, w, vol, k)
        return (k[RHO0] + k[NONLIN] * drho[i]) * acc

    @jit
    def momentum_allpair(i, n, lx, ly, lz, sx, sy, sz, mass, pr, k):
        """du_i/dt summed over all n particles, as (x, y, z)."""
        ax = k[ZERO]
        ay = k[ZERO]
        az = k[ZERO]
        for j in range(n):
            lxi, lyi, lzi = nearest(lx[i], lx[j], k[NX]), nearest(ly[i], ly[j], k[NY]), nearest(lz[i], lz[j], k[NZ])
            bx, by, bz = momentum_range(j, j + 1, lxi, lyi, lzi, i, lx, ly, lz, sx, sy, sz, mass, pr, k)
            ax += bx
            ay += by
            az += bz
        return -ax, -ay, -az

    @jit
    def neighbours_allpair(i, n, lx, ly, lz, sx, sy, sz, k):
        count = 0
        for j in range(n):
            lxi, lyi, lzi = nearest(lx[i], lx[j], k[NX]), nearest(ly[i], ly[j], k[NY]), nearest(lz[i], lz[j], k[NZ])
            count += neighbours_range(j, j + 1, lxi, lyi, lzi, i, lx, ly, lz, sx, sy, sz, k)
        return count - 1

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
        stencil_row=stencil_row,
        continuity_cells=continuity_cells,
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
