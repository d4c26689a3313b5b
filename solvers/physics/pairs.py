"""Particle interaction (PI): the SPH rates of one particle, written once for every backend.

:func:`make_pairs` builds the pair functions with one backend's decorator
(``numba.njit(inline="always")`` for the CPU solvers,
``numba.cuda.jit(device=True)`` for the GPU solver and its simulator), that
backend's exp(-x) and one kernel's G (solvers/kernels/, chosen at compile
time), so that every solver evaluates exactly the same expressions. The functions call each other as
closure variables: numba compiles them as constants of the caller.

Positions are lattice coordinates (lx, ly: whole numbers held in the solver's
float type) plus a displacement (sx, sy, m): r_ij = (lx_i - lx_j) dx +
(sx_i - sx_j). The large part is exact, so float32 keeps its accuracy at
small dx (absolute float32 coordinates lose up to 2 % of the momentum term at
dx = 0.004 m). Periodicity in y is an exact shift by ny rows (``k[NY]``, 0 for
free y edges), in x (scenes periodic in x: ``k[NX]`` columns, 0 for free
edges) by nx columns. A rigid
wall at an x edge (``k[WALL_LO]``, ``k[WALL_HI]``) acts through mirror
particles computed where they are needed, never stored: the image of
particle j across the wall, at the mirrored position with the normal velocity
reversed and everything else j's (:func:`ranges` with ``mirror``), so that
the mirrors of moving particles follow them at every sweep. A moving
particle that crosses a periodic seam has its lattice coordinate moved by a
whole period at the next search (:func:`wrap_at`), so that its cell and its
coordinates agree.

Rates (design, section 1), with rho = rho0 + nonlin * drho (nonlin = 0 in the
`linear` model) and the per-particle coefficients prepared by the solver,
vol_j = m_j / rho_j and pr_j = c0^2 drho_j / rho_j^2:
    d(drho_i)/dt = rho_i sum_j vol_j (u_i - u_j) . r_ij G_ij
    du_i/dt      = -sum_j m_j (pr_i + pr_j) G_ij r_ij
with grad_i W_ij = G_ij r_ij (``gradient``, the kernel's compiled G). ``k`` is the constant tuple
of :func:`solvers.kernels.constants.constants`, read by its named slots.
"""

import math
from types import ModuleType

from solvers.kernels import kernel_named
from solvers.kernels.constants import (
    C0SQ,
    MIRROR_HI,
    NONLIN,
    NX,
    NY,
    ONE,
    RC2,
    RHO0,
    SPACING,
    WALL_HI,
    WALL_LO,
    ZERO,
)


def separation_rule(jit, mirror: bool, displaced: bool = True):
    """r_ij's two components, m: of particle j itself, r_ij = (lx_i - lx_j) dx + (sx_i - sx_j) per axis, or
    (``mirror``) of its image across a rigid wall: ``lxi`` is i's column minus the wall's mirror sum M (the image
    of column lx_j is column M - lx_j, its displacement -sx_j), so r_ij' = (lxi + lx_j) dx + (sx_i + sx_j). The
    lattice part is exact. ``displaced`` False (every displacement zero for the whole run: fixed particles on
    their sites, :attr:`solvers.interface.Solver.displaced`): the lattice part alone, the same bits without
    the displacements' loads. Both flags compile-time constants."""

    @jit
    def separation(lxi, lyi, sxi, syi, j, lx, ly, sx, sy, k):
        if mirror:
            rx = (lxi + lx[j]) * k[SPACING]
            if displaced:
                rx += sxi + sx[j]
        else:
            rx = (lxi - lx[j]) * k[SPACING]
            if displaced:
                rx += sxi - sx[j]
        ry = (lyi - ly[j]) * k[SPACING]
        if displaced:
            ry += syi - sy[j]
        return rx, ry

    return separation


def continuity_sum(jit, separation, gradient, mirror: bool):
    """sum_j vol_j u_ij . r_ij G_ij over the particles j0..j1-1 (lyi already shifted), of their mirror images
    (u_ij = u_i + u_j) where ``mirror``."""

    @jit
    def continuity_range(j0, j1, lxi, lyi, sxi, syi, ui, vi, lx, ly, sx, sy, u, v, vol, k):
        acc = k[ZERO]
        for j in range(j0, j1):
            rx, ry = separation(lxi, lyi, sxi, syi, j, lx, ly, sx, sy, k)
            uij = ui + u[j] if mirror else ui - u[j]
            r2 = rx * rx + ry * ry
            if r2 < k[RC2]:
                g = gradient(r2, k)
                acc += vol[j] * g * (uij * rx + (vi - v[j]) * ry)
        return acc

    return continuity_range


def momentum_sum(jit, separation, gradient):
    """sum_j m_j (pr_i + pr_j) G_ij r_ij over j0..j1-1, as (x, y) components."""

    @jit
    def momentum_range(j0, j1, lxi, lyi, sxi, syi, pri, lx, ly, sx, sy, mass, pr, k):
        ax = k[ZERO]
        ay = k[ZERO]
        for j in range(j0, j1):
            rx, ry = separation(lxi, lyi, sxi, syi, j, lx, ly, sx, sy, k)
            r2 = rx * rx + ry * ry
            if r2 < k[RC2]:
                w = mass[j] * (pri + pr[j]) * gradient(r2, k)
                ax += w * rx
                ay += w * ry
        return ax, ay

    return momentum_range


def neighbour_count(jit, separation):
    """Particles j0..j1-1 within the cutoff (the particle itself included if in range)."""

    @jit
    def neighbours_range(j0, j1, lxi, lyi, sxi, syi, lx, ly, sx, sy, k):
        count = 0
        for j in range(j0, j1):
            rx, ry = separation(lxi, lyi, sxi, syi, j, lx, ly, sx, sy, k)
            if rx * rx + ry * ry < k[RC2]:
                count += 1
        return count

    return neighbours_range


def moment_sums(jit, separation, gradient):
    """The kernel gradient correction's sums over j0..j1-1: the moment matrix
    M = -sum_j vol_j G_ij r_ij (x) r_ij as (M_xx, M_xy, M_yy) and Gamma = sum_j vol_j G_ij r_ij as (x, y)."""

    @jit
    def moments_range(j0, j1, lxi, lyi, sxi, syi, lx, ly, sx, sy, vol, k):
        mxx = k[ZERO]
        mxy = k[ZERO]
        myy = k[ZERO]
        gx = k[ZERO]
        gy = k[ZERO]
        for j in range(j0, j1):
            rx, ry = separation(lxi, lyi, sxi, syi, j, lx, ly, sx, sy, k)
            r2 = rx * rx + ry * ry
            if r2 < k[RC2]:
                w = vol[j] * gradient(r2, k)
                gx += w * rx
                gy += w * ry
                mxx -= w * rx * rx
                mxy -= w * rx * ry
                myy -= w * ry * ry
        return mxx, mxy, myy, gx, gy

    return moments_range


def range_sums(jit, gradient, mirror: bool, displaced: bool = True) -> tuple:
    """The four pair sums over the particles j0..j1-1, one factory each over one separation rule: of the particles
    themselves, or (``mirror``) of their mirror images across a rigid wall, x_j' = 2 x_w - x_j with the normal
    velocity reversed (u_j' = -u_j) and the same v, drho, mass and coefficients. ``mirror`` and ``displaced`` are
    compile-time constants: each variant has its own loop."""
    separation = separation_rule(jit, mirror, displaced)
    return (
        continuity_sum(jit, separation, gradient, mirror),
        momentum_sum(jit, separation, gradient),
        neighbour_count(jit, separation),
        moment_sums(jit, separation, gradient),
    )


def cell_search(jit) -> dict:
    """A particle's cell (particleIndex) and its lattice coordinates moved back across a periodic seam."""

    @jit
    def cell_index(lx, ly, sx, sy, dx, x_grid, width, height, cw, ch, ncx, ncy):
        """particleIndex of one particle: cy * ncx + cx from float64 positions.

        x_grid is the grid's left edge relative to the first lattice column's left
        edge; x is clamped to the grid (free edges, ``width`` 0) or taken modulo the
        periodic ``width``, y likewise: modulo the periodic ``height``, or clamped to the grid's first and last
        rows (free y edges, ``height`` 0: cells are at least a cutoff tall, so a particle past the edge still
        has all its neighbours in its clamped row's stencil).
        """
        x = (float(lx) + 0.5) * dx + float(sx)
        y = (float(ly) + 0.5) * dx + float(sy)
        if width > 0:
            x = x - math.floor(x / width) * width
        if height > 0:
            y = y - math.floor(y / height) * height
        cx = min(max(int(math.floor((x - x_grid) / cw)), 0), ncx - 1)
        cy = min(max(int(math.floor(y / ch)), 0), ncy - 1)
        return cy * ncx + cx

    @jit
    def wrap_at(i, lx, ly, sx, sy, dx, width, height):
        """Particle i's lattice coordinates moved by whole periods into the box [0, width) x [0, height)
        (measured from the first lattice site's cell corner) when it has crossed a periodic seam: the same
        position, exactly (``width`` 0: x is not periodic; ``height`` 0: y is not)."""
        if width > 0:
            x = (float(lx[i]) + 0.5) * dx + float(sx[i])
            if x >= width:
                lx[i] -= math.floor(width / dx + 0.5)
            elif x < 0:
                lx[i] += math.floor(width / dx + 0.5)
        if height > 0:
            y = (float(ly[i]) + 0.5) * dx + float(sy[i])
            if y >= height:
                ly[i] -= math.floor(height / dx + 0.5)
            elif y < 0:
                ly[i] += math.floor(height / dx + 0.5)

    return {"cell_index": cell_index, "wrap_at": wrap_at}


def stencil_rules(jit) -> dict:
    """The 3x3 stencil's rows: the row's own range, and the range across the x boundary (a seam or a wall)."""

    @jit
    def stencil_range(i, dcy, cell, begin, ncx, ncy, ly, k):
        """Row ``dcy`` (-1, 0, 1) of particle i's 3x3 cell stencil: (j0, j1, lyi), lyi being i's row shifted
        across the y seam.

        Cells are numbered cy * ncx + cx and particles are sorted by cell, so the
        three cells of a stencil row are one contiguous range [j0, j1). Crossing a
        periodic boundary shifts particle i by a whole period instead of wrapping
        every pair. The range alone, without :func:`across_range`'s: with both from
        one function and the across sums compiled in, the gather loop's PI on the
        paper's scene (free in x) took 3,100 ns a particle-step at 400K here instead of
        the 2,560 of f13fa50, before seams and walls; with this and ``across``, 2,560.
        Beyond a free y edge (``k[NY]`` 0) the row is empty.
        """
        c = cell[i]
        cx = c % ncx
        cy = c // ncx + dcy
        lyi = ly[i]
        if cy < 0 or cy >= ncy:
            if k[NY] == 0:  # past a free y edge: no particles
                return 0, 0, lyi
            if cy < 0:
                cy += ncy
                lyi += k[NY]
            else:
                cy -= ncy
                lyi -= k[NY]
        row = cy * ncx
        x0 = cx - 1 if cx > 0 else 0
        x1 = cx + 1 if cx < ncx - 1 else ncx - 1
        return begin[row + x0], begin[row + x1 + 1], lyi

    @jit
    def across_range(i, dcy, cell, begin, ncx, ncy, lx, k):
        """Row ``dcy`` of particle i's stencil across the x boundary: (q0, q1, lxq), the range of particles
        beyond it and i's column for their sums (empty unless i's cell is at a periodic seam or a wall).

        Where a periodic x seam cuts the row, the cell beyond the seam; at a rigid
        wall, the wall's own column of cells, whose mirror images are i's neighbours
        across the wall (lxq: i's column minus the wall's mirror sum, for the
        ``mirror`` sums); the cells are at least a cutoff wide and the wall is the
        grid's edge, so only particles in a wall's column have mirror neighbours,
        and only in that column.
        """
        c = cell[i]
        cx = c % ncx
        cy = c // ncx + dcy
        lxq = lx[i]
        if cy < 0 or cy >= ncy:
            if k[NY] == 0:  # past a free y edge: no particles
                return 0, 0, lxq
            cy = cy + ncy if cy < 0 else cy - ncy
        row = cy * ncx
        q0 = begin[row]
        q1 = q0
        if k[NX] > 0:
            if cx == 0:  # the last cell of the row, across the seam on the left
                q0, q1 = begin[row + ncx - 1], begin[row + ncx]
                lxq = lx[i] + k[NX]
            elif cx == ncx - 1:  # the first cell, across the seam on the right
                q0, q1 = begin[row], begin[row + 1]
                lxq = lx[i] - k[NX]
        elif cx == 0 and k[WALL_LO] > 0:  # the left wall's column, mirrored onto columns -1 - lx
            q0, q1 = begin[row], begin[row + 1]
            lxq = lx[i] + k[WALL_LO]
        elif cx == ncx - 1 and k[WALL_HI] > 0:  # the right wall's column, mirrored onto columns 2 nx - 1 - lx
            q0, q1 = begin[row + ncx - 1], begin[row + ncx]
            lxq = lx[i] - k[MIRROR_HI]
        return q0, q1, lxq

    @jit
    def stencil_row(i, dcy, cell, begin, ncx, ncy, ly, lx, k):
        """Row ``dcy`` of particle i's stencil as two ranges: (j0, j1, lyi, q0, q1, lxq), of
        :func:`stencil_range` and :func:`across_range`."""
        j0, j1, lyi = stencil_range(i, dcy, cell, begin, ncx, ncy, ly, k)
        q0, q1, lxq = across_range(i, dcy, cell, begin, ncx, ncy, lx, k)
        return j0, j1, lyi, q0, q1, lxq

    @jit
    def on_x_boundary(i, cell, ncx):
        """Whether particle i's cell is in the grid's first or last column (a seam or a wall may be there)."""
        cx = cell[i] % ncx
        return cx == 0 or cx == ncx - 1

    return {
        "stencil_range": stencil_range,
        "across_range": across_range,
        "stencil_row": stencil_row,
        "on_x_boundary": on_x_boundary,
    }


def across_sums(jit, stencil_row, on_x_boundary, plain, mirrored) -> dict:
    """The sums over the particles across i's x boundary: periodic images beyond a seam, mirrors beyond a wall
    (``plain`` and ``mirrored``: :func:`range_sums`' four)."""
    continuity_range, momentum_range, neighbours_range, moments_range = plain
    continuity_mirror, momentum_mirror, neighbours_mirror, moments_mirror = mirrored

    @jit
    def continuity_across(i, cell, begin, ncx, ncy, lx, ly, sx, sy, u, v, vol, k):
        """The part of sum_j vol_j u_ij . r_ij G_ij from across particle i's x boundary: the periodic images
        beyond a seam, or the mirror particles beyond a wall (0 inside the grid)."""
        acc = k[ZERO]
        if not on_x_boundary(i, cell, ncx):
            return acc
        for dcy in range(-1, 2):
            _, _, lyi, q0, q1, lxq = stencil_row(i, dcy, cell, begin, ncx, ncy, ly, lx, k)
            if k[NX] > 0:
                acc += continuity_range(q0, q1, lxq, lyi, sx[i], sy[i], u[i], v[i], lx, ly, sx, sy, u, v, vol, k)
            else:
                acc += continuity_mirror(q0, q1, lxq, lyi, sx[i], sy[i], u[i], v[i], lx, ly, sx, sy, u, v, vol, k)
        return acc

    @jit
    def momentum_across(i, cell, begin, ncx, ncy, lx, ly, sx, sy, mass, pr, k):
        """The part of sum_j m_j (pr_i + pr_j) G_ij r_ij from across i's x boundary, as (x, y)."""
        ax = k[ZERO]
        ay = k[ZERO]
        if not on_x_boundary(i, cell, ncx):
            return ax, ay
        for dcy in range(-1, 2):
            _, _, lyi, q0, q1, lxq = stencil_row(i, dcy, cell, begin, ncx, ncy, ly, lx, k)
            if k[NX] > 0:
                bx, by = momentum_range(q0, q1, lxq, lyi, sx[i], sy[i], pr[i], lx, ly, sx, sy, mass, pr, k)
            else:
                bx, by = momentum_mirror(q0, q1, lxq, lyi, sx[i], sy[i], pr[i], lx, ly, sx, sy, mass, pr, k)
            ax += bx
            ay += by
        return ax, ay

    @jit
    def neighbours_across(i, cell, begin, ncx, ncy, lx, ly, sx, sy, k):
        """Neighbours of particle i across its x boundary (periodic images or mirrors)."""
        count = 0
        if not on_x_boundary(i, cell, ncx):
            return count
        for dcy in range(-1, 2):
            _, _, lyi, q0, q1, lxq = stencil_row(i, dcy, cell, begin, ncx, ncy, ly, lx, k)
            if k[NX] > 0:
                count += neighbours_range(q0, q1, lxq, lyi, sx[i], sy[i], lx, ly, sx, sy, k)
            else:
                count += neighbours_mirror(q0, q1, lxq, lyi, sx[i], sy[i], lx, ly, sx, sy, k)
        return count

    @jit
    def moments_across(i, cell, begin, ncx, ncy, lx, ly, sx, sy, vol, k):
        """The part of the moment sums (:func:`moments_range`) from across i's x boundary."""
        mxx = k[ZERO]
        mxy = k[ZERO]
        myy = k[ZERO]
        gx = k[ZERO]
        gy = k[ZERO]
        if not on_x_boundary(i, cell, ncx):
            return mxx, mxy, myy, gx, gy
        for dcy in range(-1, 2):
            _, _, lyi, q0, q1, lxq = stencil_row(i, dcy, cell, begin, ncx, ncy, ly, lx, k)
            if k[NX] > 0:
                a, b, c, d, e = moments_range(q0, q1, lxq, lyi, sx[i], sy[i], lx, ly, sx, sy, vol, k)
            else:
                a, b, c, d, e = moments_mirror(q0, q1, lxq, lyi, sx[i], sy[i], lx, ly, sx, sy, vol, k)
            mxx += a
            mxy += b
            myy += c
            gx += d
            gy += e
        return mxx, mxy, myy, gx, gy

    return {
        "continuity_across": continuity_across,
        "momentum_across": momentum_across,
        "neighbours_across": neighbours_across,
        "moments_across": moments_across,
    }


def cell_sums(jit, across, stencil_range, plain, beyond) -> dict:
    """The sums over particle i's 3x3 cells, and across its x boundary where ``across`` (``beyond``:
    :func:`across_sums`')."""
    continuity_range, momentum_range, neighbours_range, moments_range = plain
    continuity_across, momentum_across, neighbours_across, moments_across = (
        beyond[name] for name in ("continuity_across", "momentum_across", "neighbours_across", "moments_across")
    )

    @jit
    def moments_cells(i, cell, begin, ncx, ncy, lx, ly, sx, sy, vol, k):
        """Particle i's moment matrix (M_xx, M_xy, M_yy) and Gamma (x, y) from the 3x3 cells around it and
        across its x boundary (the kernel gradient correction, solvers/corrections/)."""
        mxx = k[ZERO]
        mxy = k[ZERO]
        myy = k[ZERO]
        gx = k[ZERO]
        gy = k[ZERO]
        for dcy in range(-1, 2):
            j0, j1, lyi = stencil_range(i, dcy, cell, begin, ncx, ncy, ly, k)
            a, b, c, d, e = moments_range(j0, j1, lx[i], lyi, sx[i], sy[i], lx, ly, sx, sy, vol, k)
            mxx += a
            mxy += b
            myy += c
            gx += d
            gy += e
        if across:
            a, b, c, d, e = moments_across(i, cell, begin, ncx, ncy, lx, ly, sx, sy, vol, k)
            mxx += a
            mxy += b
            myy += c
            gx += d
            gy += e
        return mxx, mxy, myy, gx, gy

    @jit
    def continuity_cells(i, cell, begin, ncx, ncy, lx, ly, sx, sy, u, v, vol, drho, k):
        """d(drho_i)/dt from the 3x3 cells around particle i and across its x boundary, kg/m^3/s."""
        acc = k[ZERO]
        for dcy in range(-1, 2):
            j0, j1, lyi = stencil_range(i, dcy, cell, begin, ncx, ncy, ly, k)
            acc += continuity_range(j0, j1, lx[i], lyi, sx[i], sy[i], u[i], v[i], lx, ly, sx, sy, u, v, vol, k)
        if across:
            acc += continuity_across(i, cell, begin, ncx, ncy, lx, ly, sx, sy, u, v, vol, k)
        return (k[RHO0] + k[NONLIN] * drho[i]) * acc

    @jit
    def momentum_cells(i, cell, begin, ncx, ncy, lx, ly, sx, sy, mass, pr, k):
        """du_i/dt from the 3x3 cells around particle i and across its x boundary, m/s^2, as (x, y)."""
        ax = k[ZERO]
        ay = k[ZERO]
        for dcy in range(-1, 2):
            j0, j1, lyi = stencil_range(i, dcy, cell, begin, ncx, ncy, ly, k)
            bx, by = momentum_range(j0, j1, lx[i], lyi, sx[i], sy[i], pr[i], lx, ly, sx, sy, mass, pr, k)
            ax += bx
            ay += by
        if across:
            bx, by = momentum_across(i, cell, begin, ncx, ncy, lx, ly, sx, sy, mass, pr, k)
            ax += bx
            ay += by
        return -ax, -ay

    @jit
    def neighbours_cells(i, cell, begin, ncx, ncy, lx, ly, sx, sy, k):
        """Neighbours of particle i within the cutoff, itself excluded (mirror particles counted)."""
        count = neighbours_across(i, cell, begin, ncx, ncy, lx, ly, sx, sy, k) if across else 0
        for dcy in range(-1, 2):
            j0, j1, lyi = stencil_range(i, dcy, cell, begin, ncx, ncy, ly, k)
            count += neighbours_range(j0, j1, lx[i], lyi, sx[i], sy[i], lx, ly, sx, sy, k)
        return count - 1

    return {
        "moments_cells": moments_cells,
        "continuity_cells": continuity_cells,
        "momentum_cells": momentum_cells,
        "neighbours_cells": neighbours_cells,
    }


def allpair_sums(jit, across, plain, mirrored) -> dict:
    """The sums over every particle (the paper's all-pair search): the nearest image along a periodic axis, each
    wall's mirrors."""
    continuity_range, momentum_range, neighbours_range, moments_range = plain
    continuity_mirror, momentum_mirror, neighbours_mirror, moments_mirror = mirrored

    @jit
    def minimum_image_row(lyi, lyj, k):
        """lyi shifted by a whole period so that |lyi - lyj| <= ny/2 where y is periodic (exact)."""
        if k[NY] == 0:
            return lyi
        d = lyi - lyj
        if d > 0.5 * k[NY]:
            return lyi - k[NY]
        if d < -0.5 * k[NY]:
            return lyi + k[NY]
        return lyi

    @jit
    def minimum_image_column(lxi, lxj, k):
        """lxi shifted by a whole period so that |lxi - lxj| <= nx/2 where x is periodic (exact)."""
        if k[NX] > 0:
            d = lxi - lxj
            if d > 0.5 * k[NX]:
                return lxi - k[NX]
            if d < -0.5 * k[NX]:
                return lxi + k[NX]
        return lxi

    @jit
    def continuity_allpair(i, n, lx, ly, sx, sy, u, v, vol, drho, k):
        """d(drho_i)/dt summed over all n particles (the paper's all-pair search)."""
        acc = k[ZERO]
        for j in range(n):
            lyi = minimum_image_row(ly[i], ly[j], k)
            lxi = minimum_image_column(lx[i], lx[j], k)
            acc += continuity_range(j, j + 1, lxi, lyi, sx[i], sy[i], u[i], v[i], lx, ly, sx, sy, u, v, vol, k)
            if across and k[WALL_LO] > 0:  # j's mirror across each wall, tested like every other pair
                lxm = lx[i] + k[WALL_LO]
                acc += continuity_mirror(j, j + 1, lxm, lyi, sx[i], sy[i], u[i], v[i], lx, ly, sx, sy, u, v, vol, k)
            if across and k[WALL_HI] > 0:
                lxm = lx[i] - k[MIRROR_HI]
                acc += continuity_mirror(j, j + 1, lxm, lyi, sx[i], sy[i], u[i], v[i], lx, ly, sx, sy, u, v, vol, k)
        return (k[RHO0] + k[NONLIN] * drho[i]) * acc

    @jit
    def momentum_allpair(i, n, lx, ly, sx, sy, mass, pr, k):
        """du_i/dt summed over all n particles, as (x, y)."""
        ax = k[ZERO]
        ay = k[ZERO]
        for j in range(n):
            lyi = minimum_image_row(ly[i], ly[j], k)
            lxi = minimum_image_column(lx[i], lx[j], k)
            bx, by = momentum_range(j, j + 1, lxi, lyi, sx[i], sy[i], pr[i], lx, ly, sx, sy, mass, pr, k)
            ax += bx
            ay += by
            if across and k[WALL_LO] > 0:
                bx, by = momentum_mirror(
                    j, j + 1, lx[i] + k[WALL_LO], lyi, sx[i], sy[i], pr[i], lx, ly, sx, sy, mass, pr, k
                )
                ax += bx
                ay += by
            if across and k[WALL_HI] > 0:
                bx, by = momentum_mirror(
                    j, j + 1, lx[i] - k[MIRROR_HI], lyi, sx[i], sy[i], pr[i], lx, ly, sx, sy, mass, pr, k
                )
                ax += bx
                ay += by
        return -ax, -ay

    @jit
    def moments_allpair(i, n, lx, ly, sx, sy, vol, k):
        """Particle i's moment matrix and Gamma (:func:`moments_cells`) summed over all n particles."""
        mxx = k[ZERO]
        mxy = k[ZERO]
        myy = k[ZERO]
        gx = k[ZERO]
        gy = k[ZERO]
        for j in range(n):
            lyi = minimum_image_row(ly[i], ly[j], k)
            lxi = minimum_image_column(lx[i], lx[j], k)
            a, b, c, d, e = moments_range(j, j + 1, lxi, lyi, sx[i], sy[i], lx, ly, sx, sy, vol, k)
            mxx += a
            mxy += b
            myy += c
            gx += d
            gy += e
            for wall, lxm in ((k[WALL_LO], lx[i] + k[WALL_LO]), (k[WALL_HI], lx[i] - k[MIRROR_HI])):
                if across and wall > 0:
                    a, b, c, d, e = moments_mirror(j, j + 1, lxm, lyi, sx[i], sy[i], lx, ly, sx, sy, vol, k)
                    mxx += a
                    mxy += b
                    myy += c
                    gx += d
                    gy += e
        return mxx, mxy, myy, gx, gy

    @jit
    def neighbours_allpair(i, n, lx, ly, sx, sy, k):
        count = 0
        for j in range(n):
            lyi = minimum_image_row(ly[i], ly[j], k)
            lxi = minimum_image_column(lx[i], lx[j], k)
            count += neighbours_range(j, j + 1, lxi, lyi, sx[i], sy[i], lx, ly, sx, sy, k)
            if across and k[WALL_LO] > 0:
                count += neighbours_mirror(j, j + 1, lx[i] + k[WALL_LO], lyi, sx[i], sy[i], lx, ly, sx, sy, k)
            if across and k[WALL_HI] > 0:
                count += neighbours_mirror(j, j + 1, lx[i] - k[MIRROR_HI], lyi, sx[i], sy[i], lx, ly, sx, sy, k)
        return count - 1

    return {
        "minimum_image_row": minimum_image_row,
        "minimum_image_column": minimum_image_column,
        "continuity_allpair": continuity_allpair,
        "momentum_allpair": momentum_allpair,
        "moments_allpair": moments_allpair,
        "neighbours_allpair": neighbours_allpair,
    }


def particle_passes(jit) -> dict:
    """Per particle: the sweeps' coefficients (PI), the system update (SU) and the gradient correction's passes."""

    # ---- per particle: the sweeps' coefficients (PI) and the system update (SU), one particle each, so that a
    # device kernel or a CPU loop (parallel or not) makes each a single pass instead of a chain of array operations
    @jit
    def coefficients_at(i, drho, mass, vol, pr, continuity, momentum, k):
        """vol_i = m_i / rho_i (continuity), pr_i = c0^2 drho_i / rho_i^2 (momentum)."""
        rho = k[RHO0] + k[NONLIN] * drho[i]
        if continuity:
            vol[i] = mass[i] / rho
        if momentum:
            pr[i] = k[C0SQ] * drho[i] / (rho * rho)

    @jit
    def kick_at(i, u, v, ax, ay, c):
        """u_i += c a_i (c = f dt, s)."""
        u[i] += c * ax[i]
        v[i] += c * ay[i]

    @jit
    def advance_at(i, drho, dd, sx, sy, u, v, c, moving):
        """drho_i += c D_i and, for moving particles, x_i += c u_i (c = f dt, s)."""
        drho[i] += c * dd[i]
        if moving:
            sx[i] += c * u[i]
            sy[i] += c * v[i]

    # ---- the kernel gradient correction's passes per particle (solvers/corrections/gradient.py), L = M^-1
    @jit
    def corrected_velocity_at(i, u, v, lxx, lxy, lyy, wx, wy):
        """w_i = L_i u_i: what continuity's negative adjoint sums (m/s)."""
        wx[i] = lxx[i] * u[i] + lxy[i] * v[i]
        wy[i] = lxy[i] * u[i] + lyy[i] * v[i]

    @jit
    def corrected_continuity_at(i, dd, ddx, drho, wx, wy, gx, gy, split, k):
        """d(drho_i)/dt -= 2 rho_i w_i . Gamma_i (the sweep gave rho_i sum_j V_j (w_i - w_j) . grad_i W_ij);
        ``split``: the x part too."""
        rho2 = (k[RHO0] + k[NONLIN] * drho[i]) * (k[ONE] + k[ONE])
        dd[i] -= rho2 * (wx[i] * gx[i] + wy[i] * gy[i])
        if split:
            ddx[i] -= rho2 * wx[i] * gx[i]

    @jit
    def corrected_momentum_at(i, ax, ay, drho, lxx, lxy, lyy, gx, gy, k):
        """du_i/dt = -L_i (sum_j V_j (p_j - p_i) grad_i W_ij) / rho_i, p = c0^2 drho, from the sweep's
        -sum_j V_j (drho_i + drho_j) grad_i W_ij in (ax, ay)."""
        rho = k[RHO0] + k[NONLIN] * drho[i]
        twice = (k[ONE] + k[ONE]) * drho[i]
        bx = k[C0SQ] * (ax[i] + twice * gx[i])
        by = k[C0SQ] * (ay[i] + twice * gy[i])
        ax[i] = (lxx[i] * bx + lxy[i] * by) / rho
        ay[i] = (lxy[i] * bx + lyy[i] * by) / rho

    return {
        "coefficients_at": coefficients_at,
        "kick_at": kick_at,
        "advance_at": advance_at,
        "corrected_velocity_at": corrected_velocity_at,
        "corrected_continuity_at": corrected_continuity_at,
        "corrected_momentum_at": corrected_momentum_at,
    }


def make_pairs(jit, exp_neg, kernel: str, precision: str, across: bool = True, displaced: bool = True) -> ModuleType:
    """The pair functions compiled with ``jit`` for ``kernel`` in ``precision``, using
    ``exp_neg(x) = exp(-x)`` (itself compiled here) where the kernel needs it. ``across``: whether an x
    edge of the scene has images (a periodic seam or a rigid wall); False compiles the stencil sums and the
    all-pair sums without the pairs across it (a compile-time constant: the paper's scene, free in x, pays
    nothing for seams and walls it does not have; see :func:`stencil_range`). ``displaced`` False: every
    displacement is zero for the whole run (:func:`separation_rule`).

    They come back as attributes of a module object, which numba resolves inside the jitted sweeps
    that call them (it cannot type a plain namespace).
    """
    gradient = jit(kernel_named(kernel).compiled_gradient(precision, jit(exp_neg)))
    plain = range_sums(jit, gradient, mirror=False, displaced=displaced)
    mirrored = range_sums(jit, gradient, mirror=True, displaced=displaced)
    stencil = stencil_rules(jit)
    beyond = across_sums(jit, stencil["stencil_row"], stencil["on_x_boundary"], plain, mirrored)
    pairs = ModuleType(f"{__name__}.compiled", "The pair functions for one backend (see make_pairs).")
    pairs.__dict__.update(
        gradient=gradient,
        **dict(zip(("continuity_range", "momentum_range", "neighbours_range", "moments_range"), plain)),
        **dict(zip(("continuity_mirror", "momentum_mirror", "neighbours_mirror", "moments_mirror"), mirrored)),
        **cell_search(jit),
        **stencil,
        **beyond,
        **cell_sums(jit, across, stencil["stencil_range"], plain, beyond),
        **allpair_sums(jit, across, plain, mirrored),
        **particle_passes(jit),
    )
    return pairs
