"""The 3D cell list of particles that stay on their lattice sites: one cell a site, the stencil one table.

When no particle ever leaves its site (the linear model: :attr:`solvers.interface.Solver.displaced` False),
cells one lattice spacing along every axis, each site in the middle of its own, make every particle's stencil
the same: the lines of sites the cutoff's sphere reaches, each trimmed to the sites within it. The table
(:func:`site_rows`) is computed once per scene; a row's set-up in the loop (solvers.physics.pairs3d.site_rule)
is then two cellBegin reads instead of a chord and two divisions, and a candidate is a neighbour (the trimmed
grid of :func:`solvers.interface.cell_grid_3d` looks at about three candidates a neighbour). Measured
(``python -m benchmarks.bench_three_d``): docs/performance.md "One cell a site".
"""

from __future__ import annotations

import math
from dataclasses import dataclass

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


@dataclass(frozen=True)
class SiteGrid3D:
    """The grid of a 3D scene's sites: ``ncx`` x ``ncy`` x ``ncz`` cells of ``dx`` m, numbered (cz ncy + cy) ncx
    + cx as :class:`solvers.search.celllist.CellGrid3D`'s, site (lx, ly, lz) in cell (lx + spare, ly, lz);
    along a free x a cutoff's whole cells spare each side (``x_grid`` = -spare dx), the periods as there."""

    dx: float
    ncx: int
    ncy: int
    ncz: int
    x_grid: float
    width: float
    height: float
    depth: float
    cutoff: float

    @classmethod
    def of(cls, scene) -> SiteGrid3D:
        spare = 0 if scene.periodic_x else int(math.ceil(scene.cutoff / scene.dx))
        periods = (
            span if periodic else 0.0
            for span, periodic in (
                (scene.width, scene.periodic_x),
                (scene.height, scene.periodic_y),
                (scene.depth, scene.periodic_z),
            )
        )
        return cls(scene.dx, scene.nx + 2 * spare, scene.ny, scene.nz, -spare * scene.dx, *periods, scene.cutoff)

    @property
    def ncells(self) -> int:
        return self.ncx * self.ncy * self.ncz

    def index_arguments(self, dx: float) -> tuple:
        """What the cell-index kernels take (as :meth:`solvers.search.celllist.CellGrid3D.index_arguments`)."""
        g = self
        return dx, g.x_grid, g.width, g.height, g.depth, g.dx, g.dx, g.dx, g.ncx, g.ncy, g.ncz

    def stencil_arguments(self, dx: float) -> tuple:
        """What the site loops take after cellBegin: the cell counts and the table of rows (:func:`site_rows`)."""
        return self.ncx, self.ncy, self.ncz, site_rows(self.cutoff, dx)
