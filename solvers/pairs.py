"""Particle interaction (PI): the SPH rates of one particle, written once.

This file is plain Python. :func:`solvers.backend.compile_pairs` executes it
once per backend with ``jit`` bound to that backend's decorator
(``numba.njit`` for the CPU solvers, ``numba.cuda.jit(device=True)`` for the
GPU solver and its simulator) and ``exp_neg`` to that backend's exp(-x), so
that every solver evaluates exactly the same expressions.

Positions are lattice coordinates (lx, ly: whole numbers held in the solver's
float type) plus a displacement (sx, sy, m): r_ij = (lx_i - lx_j) dx +
(sx_i - sx_j). The large part is exact, so float32 keeps its accuracy at
small dx (absolute float32 coordinates lose up to 2 % of the momentum term at
dx = 0.004 m). Periodicity in y is an exact shift by ny rows.

Rates (design, section 1), with rho = rho0 + nonlin * drho (nonlin = 0 in the
`linear` model) and the per-particle coefficients prepared by the solver,
vol_j = m_j / rho_j and pr_j = c0^2 drho_j / rho_j^2:
    d(drho_i)/dt = rho_i sum_j vol_j (u_i - u_j) . grad_i W_ij
    du_i/dt      = -sum_j m_j (pr_i + pr_j) grad_i W_ij
"""
import math

try:
    jit  # noqa: B018 - injected by compile_pairs, with exp_neg
except NameError:  # imported plainly: pure Python, for reading and tests
    def jit(f):
        return f

    def exp_neg(x):
        return math.exp(-x)

# k is the constant tuple of solvers.kernel.constants: k[0] dx, k[1] ny,
# k[2] 1/h^2, k[3] G(0), k[4] cutoff^2, k[5] rho0, k[6] c0^2, k[7] nonlin, k[8] 0.


@jit
def grad_factor(r2, k):
    """G with grad_i W_ij = G * r_ij, 1/m^4; zero beyond the cutoff."""
    if r2 < k[4]:
        return k[3] * exp_neg(r2 * k[2])
    return k[8]


@jit
def continuity_range(j0, j1, lxi, lyi, sxi, syi, ui, vi, lx, ly, sx, sy, u, v, vol, k):
    """sum_j vol_j u_ij . r_ij G_ij over the particles j0..j1-1 (lyi already shifted)."""
    acc = k[8]
    for j in range(j0, j1):
        rx = (lxi - lx[j]) * k[0] + (sxi - sx[j])
        ry = (lyi - ly[j]) * k[0] + (syi - sy[j])
        r2 = rx * rx + ry * ry
        if r2 < k[4]:
            g = k[3] * exp_neg(r2 * k[2])
            acc += vol[j] * g * ((ui - u[j]) * rx + (vi - v[j]) * ry)
    return acc


@jit
def momentum_range(j0, j1, lxi, lyi, sxi, syi, pri, lx, ly, sx, sy, mass, pr, k):
    """sum_j m_j (pr_i + pr_j) G_ij r_ij over j0..j1-1, as (x, y) components."""
    ax = k[8]
    ay = k[8]
    for j in range(j0, j1):
        rx = (lxi - lx[j]) * k[0] + (sxi - sx[j])
        ry = (lyi - ly[j]) * k[0] + (syi - sy[j])
        r2 = rx * rx + ry * ry
        if r2 < k[4]:
            w = mass[j] * (pri + pr[j]) * (k[3] * exp_neg(r2 * k[2]))
            ax += w * rx
            ay += w * ry
    return ax, ay


@jit
def neighbours_range(j0, j1, lxi, lyi, sxi, syi, lx, ly, sx, sy, k):
    """Particles j0..j1-1 within the cutoff (the particle itself included if in range)."""
    count = 0
    for j in range(j0, j1):
        rx = (lxi - lx[j]) * k[0] + (sxi - sx[j])
        ry = (lyi - ly[j]) * k[0] + (syi - sy[j])
        if rx * rx + ry * ry < k[4]:
            count += 1
    return count


# ---------------------------------------------------------------- cell list
@jit
def cell_index(lx, ly, sx, sy, dx, x_grid, height, cw, ch, ncx, ncy):
    """particleIndex of one particle: cy * ncx + cx from float64 positions.

    x_grid is the grid's left edge relative to the first lattice column's left
    edge; x is clamped to the grid, y taken modulo the periodic height.
    """
    x = (float(lx) + 0.5) * dx + float(sx)
    y = (float(ly) + 0.5) * dx + float(sy)
    y = y - math.floor(y / height) * height
    cx = min(max(int(math.floor((x - x_grid) / cw)), 0), ncx - 1)
    cy = min(max(int(y / ch), 0), ncy - 1)
    return cy * ncx + cx


@jit
def stencil_row(i, dcy, cell, begin, ncx, ncy, ly, k):
    """Row ``dcy`` (-1, 0, 1) of particle i's 3x3 cell stencil: (j0, j1, lyi shifted).

    Cells are numbered cy * ncx + cx and particles are sorted by cell, so the
    three cells of a stencil row are one contiguous range [j0, j1). Crossing
    the periodic boundary shifts particle i by ny rows instead of wrapping
    every pair.
    """
    c = cell[i]
    cx = c % ncx
    cy = c // ncx + dcy
    lyi = ly[i]
    if cy < 0:
        cy += ncy
        lyi += k[1]
    elif cy >= ncy:
        cy -= ncy
        lyi -= k[1]
    x0 = cx - 1 if cx > 0 else 0
    x1 = cx + 1 if cx < ncx - 1 else ncx - 1
    return begin[cy * ncx + x0], begin[cy * ncx + x1 + 1], lyi


@jit
def continuity_cells(i, cell, begin, ncx, ncy, lx, ly, sx, sy, u, v, vol, drho, k):
    """d(drho_i)/dt from the 3x3 cells around particle i, kg/m^3/s."""
    acc = k[8]
    for dcy in range(-1, 2):
        j0, j1, lyi = stencil_row(i, dcy, cell, begin, ncx, ncy, ly, k)
        acc += continuity_range(j0, j1, lx[i], lyi, sx[i], sy[i], u[i], v[i],
                                lx, ly, sx, sy, u, v, vol, k)
    return (k[5] + k[7] * drho[i]) * acc


@jit
def momentum_cells(i, cell, begin, ncx, ncy, lx, ly, sx, sy, mass, pr, k):
    """du_i/dt from the 3x3 cells around particle i, m/s^2, as (x, y)."""
    ax = k[8]
    ay = k[8]
    for dcy in range(-1, 2):
        j0, j1, lyi = stencil_row(i, dcy, cell, begin, ncx, ncy, ly, k)
        bx, by = momentum_range(j0, j1, lx[i], lyi, sx[i], sy[i], pr[i],
                                lx, ly, sx, sy, mass, pr, k)
        ax += bx
        ay += by
    return -ax, -ay


@jit
def neighbours_cells(i, cell, begin, ncx, ncy, lx, ly, sx, sy, k):
    """Neighbours of particle i within the cutoff, itself excluded."""
    count = 0
    for dcy in range(-1, 2):
        j0, j1, lyi = stencil_row(i, dcy, cell, begin, ncx, ncy, ly, k)
        count += neighbours_range(j0, j1, lx[i], lyi, sx[i], sy[i], lx, ly, sx, sy, k)
    return count - 1


# ---------------------------------------------------------------- all pairs
@jit
def minimum_image_row(lyi, lyj, k):
    """lyi shifted by a whole period so that |lyi - lyj| <= ny/2 (exact)."""
    d = lyi - lyj
    if d > 0.5 * k[1]:
        return lyi - k[1]
    if d < -0.5 * k[1]:
        return lyi + k[1]
    return lyi


@jit
def continuity_allpair(i, n, lx, ly, sx, sy, u, v, vol, drho, k):
    """d(drho_i)/dt summed over all n particles (the paper's all-pair search)."""
    acc = k[8]
    for j in range(n):
        lyi = minimum_image_row(ly[i], ly[j], k)
        acc += continuity_range(j, j + 1, lx[i], lyi, sx[i], sy[i], u[i], v[i],
                                lx, ly, sx, sy, u, v, vol, k)
    return (k[5] + k[7] * drho[i]) * acc


@jit
def momentum_allpair(i, n, lx, ly, sx, sy, mass, pr, k):
    """du_i/dt summed over all n particles, as (x, y)."""
    ax = k[8]
    ay = k[8]
    for j in range(n):
        lyi = minimum_image_row(ly[i], ly[j], k)
        bx, by = momentum_range(j, j + 1, lx[i], lyi, sx[i], sy[i], pr[i],
                                lx, ly, sx, sy, mass, pr, k)
        ax += bx
        ay += by
    return -ax, -ay


@jit
def neighbours_allpair(i, n, lx, ly, sx, sy, k):
    count = 0
    for j in range(n):
        lyi = minimum_image_row(ly[i], ly[j], k)
        count += neighbours_range(j, j + 1, lx[i], lyi, sx[i], sy[i], lx, ly, sx, sy, k)
    return count - 1
