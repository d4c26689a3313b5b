"""The paper's uniform cell list as an object a solver holds (PySPH's NNPS), and the solvers built on it.

Cells are one cutoff wide in x and at least one cutoff tall in y (a whole
number of rows fills the lattice's height; :class:`CellGrid`); in 3D one cell
a site (:class:`SiteGrid3D`, solvers/search/sites.py: the CPU's), or an eighth
of a cutoff wide in x and a cutoff or half a cutoff in y and z, each stencil
row trimmed to the cutoff's sphere (:class:`CellGrid3D`: the GPU's). SNP finds each
particle's cell (particleIndex), orders particles by cell
(cellParticleOrder) and marks where each cell starts (cellBegin, with the
end sentinel): that is the search's job (:class:`CellList`). The solver then
gathers every per-particle array into cell order, so the three cells of a
stencil row are one contiguous range, and its pair loops take the search's
:meth:`CellList.arguments` first. Particles that never move are searched once.

A solver is given its search by the class attribute ``neighbour_search``;
a variant of the search overrides one of its steps (``cell_ids``,
``cell_order``) in a subclass and hands it to a solver (the README's plug-in).
``pcabench check-solver`` (pcabench/conformance.py) checks a variant against
the all-pair reference.
"""

from __future__ import annotations

import abc
import math
import time
from dataclasses import dataclass

import numpy as np

from solvers.interface import POSITIONS, Solver, cell_grid, cell_grid_3d, tiny_scene
from solvers.physics.backend import cpu_sorting
from solvers.search.sites import site_rows


@dataclass(frozen=True)
class CellGrid:
    """The uniform grid of a scene (solvers.interface.cell_grid): cells ``cw`` x ``ch`` m, ``ncx`` x ``ncy`` of
    them, the grid's left edge ``x_grid`` (m, from the first lattice column's left edge), and the x and y
    periods ``width``, ``height`` (m; 0 on an axis that is not periodic)."""

    cw: float
    ch: float
    ncx: int
    ncy: int
    x_grid: float
    width: float
    height: float

    @classmethod
    def of(cls, scene) -> CellGrid:
        return cls(*cell_grid(scene))

    @property
    def ncells(self) -> int:
        return self.ncx * self.ncy

    def index_arguments(self, dx: float) -> tuple:
        """What the cell-index kernels take after the positions and the output: the lattice spacing (m) and
        the grid."""
        return dx, self.x_grid, self.width, self.height, self.cw, self.ch, self.ncx, self.ncy

    def stencil_arguments(self, dx: float) -> tuple:
        """What the stencil loops take after cellBegin: the cell counts along each axis."""
        return self.ncx, self.ncy


@dataclass(frozen=True)
class CellGrid3D:
    """The uniform grid of a 3D scene (solvers.interface.cell_grid_3d): cells ``cw`` x ``ch`` x ``cd`` m,
    ``ncx`` x ``ncy`` x ``ncz`` of them, numbered (cz ncy + cy) ncx + cx; ``x_grid`` and the periods as in 2D
    (``depth``: z's, 0 where z is not periodic); the cells a cutoff spans along each axis (``reach_*``)."""

    cw: float
    ch: float
    cd: float
    ncx: int
    ncy: int
    ncz: int
    x_grid: float
    width: float
    height: float
    depth: float
    reach_x: int
    reach_y: int
    reach_z: int

    @classmethod
    def of(cls, scene) -> CellGrid3D:
        return cls(*cell_grid_3d(scene))

    @property
    def ncells(self) -> int:
        return self.ncx * self.ncy * self.ncz

    def index_arguments(self, dx: float) -> tuple:
        """:meth:`CellGrid.index_arguments` with z's."""
        g = self
        return dx, g.x_grid, g.width, g.height, g.depth, g.cw, g.ch, g.cd, g.ncx, g.ncy, g.ncz

    def stencil_arguments(self, dx: float) -> tuple:
        """What the stencil loops take after cellBegin: the cell counts along each axis and the box (float64:
        the lattice spacing, ``x_grid``, ``cw``, ``ch``, ``cd``, m, and the reaches) by which a row is trimmed to
        the cutoff's sphere (solvers.physics.pairs3d.stencil_rule)."""
        g = self
        box = np.array([dx, g.x_grid, g.cw, g.ch, g.cd, g.reach_x, g.reach_y, g.reach_z], np.float64)
        return self.ncx, self.ncy, self.ncz, box


@dataclass(frozen=True)
class SiteGrid3D(CellGrid3D):
    """:class:`solvers.search.celllist.CellGrid3D` with cells of one lattice spacing, site (lx, ly, lz) in cell
    (lx + spare, ly, lz) (along a free x a cutoff's whole cells spare each side, ``x_grid`` = -spare dx), and the
    cutoff (m) its table of rows is made for (:meth:`stencil_arguments`)."""

    cutoff: float

    @classmethod
    def of(cls, scene) -> SiteGrid3D:
        reach = int(math.ceil(scene.cutoff / scene.dx))
        spare = 0 if scene.periodic_x else reach
        periods = (
            span if periodic else 0.0
            for span, periodic in (
                (scene.width, scene.periodic_x),
                (scene.height, scene.periodic_y),
                (scene.depth, scene.periodic_z),
            )
        )
        d = scene.dx
        counts = (scene.nx + 2 * spare, scene.ny, scene.nz)
        return cls(d, d, d, *counts, -spare * d, *periods, reach, reach, reach, scene.cutoff)

    def stencil_arguments(self, dx: float, allowance: float = 0.0) -> tuple:
        """What the site loops take after cellBegin: the cell counts and the table of rows (:func:`site_rows`) for
        particles at most ``allowance`` (m) from their cells' centres: every pair within the cutoff is then within
        the cutoff and twice the allowance of its cells' centres."""
        return self.ncx, self.ncy, self.ncz, site_rows(self.cutoff + 2.0 * allowance, dx)


class CellList:
    """The paper's cell list on the CPU: particleIndex (``cell``), cellParticleOrder (``order``) and cellBegin
    (``begin``) for a scene, built by the solver's compiled kernels (``launch``: ``cell_ids``, ``neighbours``).

    :meth:`bin` finds the cells and their order for the current positions; the solver puts its arrays in
    that order, then :meth:`settle` puts the cells in it too. A variant overrides :meth:`cell_ids` or
    :meth:`cell_order` alone. ``on_sites``: a 3D scene's grid is the sites' (solvers/search/sites.py; the solver's
    loops are compiled for it), its table widened as the particles move (:meth:`widen`).
    """

    def __init__(self, scene, launch, xp=np, on_sites: bool = False):
        self.scene, self.launch, self.xp = scene, launch, xp
        self.on_sites = on_sites and scene.dims == 3  # the sites' grid (solvers/search/sites.py): 3D only
        if self.on_sites:
            self.grid = SiteGrid3D.of(scene)
        else:
            self.grid = CellGrid3D.of(scene) if scene.dims == 3 else CellGrid.of(scene)
        self.positions = POSITIONS[scene.dims]  # the arrays it bins: lattice coordinates, then displacements
        self.ncells = self.grid.ncells
        self.allowance = 0.0  # m: the sites' table holds pairs whose particles are this far from their sites
        self.stencil = self.stencil_for(0.0)
        self.valid = False  # whether the cells are those of the current positions
        self.allocate()

    def stencil_for(self, allowance: float) -> tuple:
        """The grid's stencil arguments as the loops take them (the sites' table for ``allowance``, m)."""
        dx = self.scene.dx
        args = self.grid.stencil_arguments(dx, allowance) if self.on_sites else self.grid.stencil_arguments(dx)
        return tuple(self.xp.asarray(a) if isinstance(a, np.ndarray) else a for a in args)

    def widen(self, shifts) -> None:
        """The sites' table for particles displaced by ``shifts`` (sx, sy, sz, m) from their sites. A particle is
        no further from its cell's centre than from its site (the site is its own cell's centre; in another
        cell, each axis's distance to that cell's centre is at most half a cell, less than it moved along that
        axis), so with the table widened by twice the largest displacement no pair within the cutoff is missed.
        Made again at every search where the largest displacement changed (a table is a few hundred rows at
        most); none while no particle moves."""
        xp = self.xp
        largest = math.sqrt(float(xp.max(sum(s * s for s in shifts)))) if len(shifts[0]) else 0.0
        if largest != self.allowance:
            self.allowance = largest
            self.stencil = self.stencil_for(largest)

    def allocate(self) -> None:
        n = self.scene.n_particles
        self.cell = np.empty(n, np.int32)
        self.sorted_cell = np.empty(n, np.int32)
        self.order = np.empty(n, np.int64)
        # unsigned cell bounds: numba then skips negative-index wraparound on every
        # neighbour load (measured 20-25 % faster sweeps)
        self.begin = np.zeros(self.ncells + 1, np.uint32)

    def bin(self, *positions):
        """particleIndex, cellParticleOrder and cellBegin for particles at lattice sites ``lx, ly`` (and ``lz``)
        shifted by ``sx, sy`` (and ``sz``, m); returns cellParticleOrder, the order to put the particle arrays in."""
        if self.on_sites:
            self.widen(positions[3:])
        self.cell_ids(*positions)
        order, begin = self.cell_order()
        if begin is not self.begin:
            self.begin[:] = begin
        if order is not self.order:  # a variant's own order: the cells in it by one gather
            self.order = np.ascontiguousarray(order, dtype=np.int64)
            np.take(self.cell, self.order, out=self.sorted_cell)
        return self.order

    def cell_ids(self, *positions) -> None:
        """particleIndex of every particle at ``positions`` (lx, ly, sx, sy; in 3D lz and sz too), into
        ``self.cell`` (a particle past a periodic seam has its lattice coordinates moved by a period first: the
        same position)."""
        self.launch("cell_ids", *positions, self.cell, *self.grid.index_arguments(self.scene.dx))

    def cell_order(self) -> tuple:
        """(cellParticleOrder, cellBegin) for the cells in ``self.cell`` (particleIndex): the permutation
        that puts the particles in cell order, stable (by particle within a cell), and the first position
        of every cell with the end sentinel (``ncells + 1`` entries). Here a counting sort
        (solvers/loops/sorting.py) into the search's own arrays (which also leaves the cells in that order in
        ``self.sorted_cell``); a variant overrides this method alone and may return arrays of its own."""
        cpu_sorting().counting_sort(self.cell, self.ncells, self.begin, self.order, self.sorted_cell)
        return self.order, self.begin

    def settle(self) -> None:
        """The particles are in cellParticleOrder now: so are their cells."""
        self.cell, self.sorted_cell = self.sorted_cell, self.cell

    def arguments(self, arrays) -> tuple:
        """What every stencil loop takes first: the cells, cellBegin, the grid (:meth:`CellGrid.stencil_arguments`)
        and the positions."""
        return (self.cell, self.begin, *self.stencil, *(arrays[name] for name in self.positions))

    def count(self, arrays, k) -> int:
        """Neighbours within the cutoff summed over particles at the positions in ``arrays``, on a search of
        its own over copies of the positions: ``arrays`` and this search are left as they are."""
        fresh = type(self)(self.scene, self.launch, self.xp, on_sites=self.on_sites)
        copies = [arrays[name].copy() for name in self.positions]  # the kernel may wrap them
        order = fresh.bin(*copies)
        fresh.settle()
        positions = dict(zip(self.positions, (arr[order] for arr in copies)))
        return int(self.launch("neighbours", *fresh.arguments(positions), k))


class CellListSolver(Solver):
    """A solver with a cell-list search (``neighbour_search``, held as ``self.nnps``); subclasses put their
    arrays in cell order (:meth:`sort_cells`) and launch kernels."""

    neighbour_search = CellList

    def after_init(self) -> None:
        super().after_init()
        self.allocate_cells()

    @abc.abstractmethod
    def allocate_cells(self) -> None:
        """What the solver keeps beside the search's arrays (scratch, spare blocks, a pair list)."""

    @abc.abstractmethod
    def sort_cells(self) -> None:
        """The search for the current positions (``self.nnps``), then every array into cell order."""

    def snp(self) -> None:
        """The cell list for the current positions: every step if particles move, once otherwise."""
        if self.nnps.valid and not self.moving:
            return
        self.sort_cells()
        self.nnps.valid = True

    def probe(self) -> CellListSolver:
        """A fresh solver configured like this one (for the warm-up)."""
        return type(self)(threads=self.threads)

    def warmup(self) -> float:
        """Compile every kernel and make the first launches on a tiny scene, outside the timing; wall s."""
        t0 = time.perf_counter()
        probe = self.probe()
        probe.input(tiny_scene(self.scene))
        probe.init()
        probe.snp()
        probe.rates(True, True)
        probe.kick(0.5)
        probe.advance(1.0)
        probe.extremes()
        probe.output()
        probe.mean_neighbours()
        probe.synchronize()
        return time.perf_counter() - t0
