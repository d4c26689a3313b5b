"""The cell sort of the CPU solvers, serial: cellBegin and cellParticleOrder by a counting sort, and the
x-sort within each cell that the pair list scans. A template of solvers.jitcache with no free names."""


def counting_sort(cell, ncells, begin, order, sorted_cell):
    """cellBegin and cellParticleOrder by a stable counting sort of ``cell``."""
    begin[:] = 0
    for i in range(cell.shape[0]):  # particleCellNum, shifted by one
        begin[cell[i] + 1] += 1
    for c in range(ncells):  # exclusive prefix sum: cellBegin
        begin[c + 1] += begin[c]
    fill = begin[:-1].copy()
    for i in range(cell.shape[0]):
        c = cell[i]
        order[fill[c]] = i
        sorted_cell[fill[c]] = c
        fill[c] += 1


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
