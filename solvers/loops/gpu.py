"""The GPU solver's device kernels (numba-cuda), from the shared pair physics. A template of solvers.jitcache,
specialised by solvers.gpu.cuda_kernels.kernels: on a GPU compiled by numba-cuda with its cache (per compute
capability), in numba's CUDA simulator run as Python. ``cuda`` is a module global on purpose: the simulator
swaps the module global named ``cuda`` for its own, which a closure variable would hide from it."""

from numba import cuda, int32

P = None  # the pair functions as device functions (solvers.gpu.cuda_kernels.device_pairs), bound by solvers.jitcache
scan_threads = None  # threads of the one cell_begin block (solvers.gpu.cuda_kernels.scan_block), bound by jitcache
SCAN_ITEMS = 4  # cells per thread in one pass of the cellBegin scan


# ---- SNP as three launches and no host round trip: a counting sort by cell (DualSPHysics' cell list
# without the radix sort). cell_count: particleIndex and each particle's rank in its cell (atomics);
# cell_begin: cellBegin by an exclusive scan of the counts (one block), which also zeroes the counts for
# the next search; scatter: every per-particle array into cell order in one pass.
def cell_count(lx, ly, sx, sy, cell, rank, counts, dx, x_grid, width, height, cw, ch, ncx, ncy):
    i = cuda.grid(1)
    if i < lx.shape[0]:
        P.wrap_at(i, lx, ly, sx, sy, dx, width, height)
        c = P.cell_index(lx[i], ly[i], sx[i], sy[i], dx, x_grid, width, height, cw, ch, ncx, ncy)
        cell[i] = c
        rank[i] = cuda.atomic.add(counts, c, 1)


def cell_begin(counts, begin):
    """begin[c] = counts[0] + ... + counts[c-1], begin[ncells] = N; counts set back to 0. One block."""
    tid = cuda.threadIdx.x
    tile = cuda.shared.array(scan_threads, int32)
    carry = cuda.shared.array(1, int32)
    ncells = counts.shape[0]
    if tid == 0:
        carry[0] = 0
    cuda.syncthreads()
    for base in range(0, ncells, scan_threads * SCAN_ITEMS):
        first = base + tid * SCAN_ITEMS
        own = 0
        for q in range(SCAN_ITEMS):
            if first + q < ncells:
                own += counts[first + q]
        tile[tid] = own
        cuda.syncthreads()
        offset = 1
        while offset < scan_threads:  # Hillis-Steele inclusive scan of the threads' sums
            before = tile[tid - offset] if tid >= offset else 0
            cuda.syncthreads()
            tile[tid] += before
            cuda.syncthreads()
            offset *= 2
        start = carry[0] + tile[tid] - own
        for q in range(SCAN_ITEMS):
            if first + q < ncells:
                begin[first + q] = start
                start += counts[first + q]
                counts[first + q] = 0
        cuda.syncthreads()
        if tid == scan_threads - 1:
            carry[0] += tile[tid]
        cuda.syncthreads()
    if tid == 0:
        begin[ncells] = carry[0]


def scatter(cell, rank, begin, src, dst, cell_out, order):
    """Row r of ``src`` (one per-particle array per row) into cell order in ``dst``; order[d] = i."""
    i = cuda.grid(1)
    if i < cell.shape[0]:
        c = cell[i]
        d = begin[c] + rank[i]
        cell_out[d] = c
        order[d] = i
        for r in range(src.shape[0]):
            dst[r, d] = src[r, i]


def continuity(cell, begin, ncx, ncy, lx, ly, sx, sy, u, v, vol, drho, out, k):
    i = cuda.grid(1)
    if i < lx.shape[0]:
        out[i] = P.continuity_cells(i, cell, begin, ncx, ncy, lx, ly, sx, sy, u, v, vol, drho, k)


def momentum(cell, begin, ncx, ncy, lx, ly, sx, sy, mass, pr, ax, ay, k):
    i = cuda.grid(1)
    if i < lx.shape[0]:
        bx, by = P.momentum_cells(i, cell, begin, ncx, ncy, lx, ly, sx, sy, mass, pr, k)
        ax[i] = bx
        ay[i] = by


def moments(cell, begin, ncx, ncy, lx, ly, sx, sy, vol, mxx, mxy, myy, gx, gy, k):
    """The kernel gradient correction's moment matrix and Gamma of every particle (solvers/corrections/)."""
    i = cuda.grid(1)
    if i < lx.shape[0]:
        a, b, c, d, e = P.moments_cells(i, cell, begin, ncx, ncy, lx, ly, sx, sy, vol, k)
        mxx[i] = a
        mxy[i] = b
        myy[i] = c
        gx[i] = d
        gy[i] = e


def neighbours(cell, begin, ncx, ncy, lx, ly, sx, sy, counts, k):
    i = cuda.grid(1)
    if i < lx.shape[0]:
        counts[i] = P.neighbours_cells(i, cell, begin, ncx, ncy, lx, ly, sx, sy, k)


# the system update and the coefficients, each one launch instead of a chain of array operations
def coefficients(drho, mass, vol, pr, continuity, momentum, k):
    i = cuda.grid(1)
    if i < drho.shape[0]:
        P.coefficients_at(i, drho, mass, vol, pr, continuity, momentum, k)


def kick(u, v, ax, ay, c):
    i = cuda.grid(1)
    if i < u.shape[0]:
        P.kick_at(i, u, v, ax, ay, c)


def advance(drho, dd, sx, sy, u, v, c, moving, mass, vol, pr, k):
    """The update, then both coefficients from the new drho: no coefficients launch before a sweep."""
    i = cuda.grid(1)
    if i < drho.shape[0]:
        P.advance_at(i, drho, dd, sx, sy, u, v, c, moving)
        P.coefficients_at(i, drho, mass, vol, pr, True, True, k)


# the kernel gradient correction's passes per particle (solvers/corrections/gradient.py)
def corrected_velocity(u, v, lxx, lxy, lyy, wx, wy):
    i = cuda.grid(1)
    if i < u.shape[0]:
        P.corrected_velocity_at(i, u, v, lxx, lxy, lyy, wx, wy)


def corrected_continuity(dd, ddx, drho, wx, wy, gx, gy, split, k):
    i = cuda.grid(1)
    if i < dd.shape[0]:
        P.corrected_continuity_at(i, dd, ddx, drho, wx, wy, gx, gy, split, k)


def corrected_momentum(ax, ay, drho, lxx, lxy, lyy, gx, gy, k):
    i = cuda.grid(1)
    if i < ax.shape[0]:
        P.corrected_momentum_at(i, ax, ay, drho, lxx, lxy, lyy, gx, gy, k)
