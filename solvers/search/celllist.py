"""The paper's uniform cell list, shared by the CPU and GPU linked-list solvers.

Cells are one cutoff wide in x and at least one cutoff tall in y (a whole
number of rows fills the lattice's height). SNP finds each particle's cell
(particleIndex), orders particles by cell (cellParticleOrder), marks where
each cell starts (cellBegin, with the end sentinel) and gathers every
per-particle array into cell order, so the three cells of a stencil row are
one contiguous range. Particles that never move are searched once.

A subclass says only how cells are sorted (:meth:`sort_cells`) and how a
kernel is launched (:meth:`launch`: cell_ids, continuity, momentum and
neighbours here, besides the base's coefficients, kick and advance).
linkedlist-cpu splits its sort into steps a variant overrides one at a time
(``cell_ids``, ``cell_order``, ``permute``); ``pcabench check-solver``
(pcabench/conformance.py) checks a variant against the all-pair reference.
"""

from __future__ import annotations

import abc
import time

from solvers.interface import Solver, cell_grid, tiny_scene


class CellListSolver(Solver):
    """Cell-list neighbour search and gather sweeps; subclasses sort cells and launch kernels."""

    def after_init(self) -> None:
        self.cw, self.ch, self.ncx, self.ncy, self.x_grid, self.width, self.height = cell_grid(self.scene)
        self.ncells = self.ncx * self.ncy
        self.cells_valid = False
        self.allocate_cells()

    @abc.abstractmethod
    def allocate_cells(self) -> None:
        """The cell arrays (particleIndex, cellBegin, scratch) for ``self.scene``."""

    @abc.abstractmethod
    def sort_cells(self) -> None:
        """particleIndex, cellParticleOrder and cellBegin for the current positions; arrays into cell order."""

    @abc.abstractmethod
    def count_neighbours(self) -> int:
        """Neighbours within the cutoff summed over particles, at the current positions, on a cell list of
        its own: the particles, their order and the solver's cell list are left as they are."""

    def snp(self) -> None:
        """The cell list for the current positions: every step if particles move, once otherwise."""
        if self.cells_valid and not self.moving:
            return
        self.sort_cells()
        self.cells_valid = True

    def cell_ids(self) -> None:
        """particleIndex of every particle, into ``self.cell`` (a particle past a periodic seam has its lattice
        coordinates moved by a period first: the same position)."""
        self.launch(
            "cell_ids",
            *self.grid_arguments(self.arrays["lx"], self.arrays["ly"], self.arrays["sx"], self.arrays["sy"], self.cell),
        )

    def grid_arguments(self, lx, ly, sx, sy, cell) -> tuple:
        """The arguments of the cell-index kernels for positions ``lx, ly, sx, sy`` and output ``cell``."""
        s = self.scene
        return (lx, ly, sx, sy, cell, s.dx, self.x_grid, self.width, self.height, self.cw, self.ch, self.ncx, self.ncy)

    def geometry(self) -> tuple:
        """The arguments every stencil kernel starts with: cells and positions."""
        a = self.arrays
        return self.cell, self.begin, self.ncx, self.ncy, a["lx"], a["ly"], a["sx"], a["sy"]

    def _sweep(self, continuity: bool, momentum: bool) -> None:
        a = self.arrays
        if continuity:
            self.launch("continuity", *self.geometry(), a["u"], a["v"], a["vol"], a["drho"], a["dd"], self.k)
        if momentum:
            self.launch("momentum", *self.geometry(), a["mass"], a["pr"], a["ax"], a["ay"], self.k)

    def mean_neighbours(self) -> float:
        """Mean count of neighbours within the cutoff at the current positions; no side effect (the state
        is not re-sorted: the count is the same in any particle order)."""
        return self.count_neighbours() / self.scene.n_particles

    def probe(self) -> "CellListSolver":
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
        probe.amplitude()
        probe.output()
        probe.mean_neighbours()
        probe.synchronize()
        return time.perf_counter() - t0
