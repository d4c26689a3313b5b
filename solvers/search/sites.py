"""The stencil of 3D particles on the CPU: one cell a site, one table of rows.

Cells one lattice spacing along every axis, each site in the middle of its own, make every particle's stencil
the same: the lines of sites the cutoff's sphere reaches, each trimmed to the sites within it. The table
(:func:`site_rows`, for the grid :class:`solvers.search.celllist.SiteGrid3D`) is computed once per scene where no
particle leaves its site (the linear model: :attr:`solvers.interface.Solver.displaced` False), and at each search
for twice the largest displacement more where particles move (:meth:`solvers.search.celllist.CellList.widen`);
a row's set-up in the loop (solvers.physics.pairs3d.site_rule)
is then two cellBegin reads instead of a chord and two divisions, and a candidate is a neighbour (the trimmed
grid of :func:`solvers.interface.cell_grid_3d`, the GPU's, looks at about three candidates a neighbour). Measured
(``python -m benchmarks.bench_three_d``): docs/performance.md "One cell a site".
"""

from __future__ import annotations

import math

import numpy as np

from solvers.physics.pairs3d import TRIM_SLACK


def site_rows(cutoff: float, dx: float) -> np.ndarray:
    """The stencil of a site (int64, one row per line of sites): (dy, dz, m), the line dy, dz sites away in y
    and z and its sites -m..m along x from the particle's own, every site within ``cutoff`` (widened by
    ``TRIM_SLACK``) and no line the sphere misses; ``cutoff`` and ``dx`` in m."""
    reach = cutoff * (1.0 + TRIM_SLACK) / dx  # in sites
    n = int(math.floor(reach))
    rows = []
    for dz in range(-n, n + 1):
        for dy in range(-n, n + 1):
            left = reach * reach - dy * dy - dz * dz
            if left >= 0.0:
                rows.append((dy, dz, int(math.floor(math.sqrt(left)))))
    return np.array(rows, np.int64)
