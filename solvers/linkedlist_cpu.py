"""Linked-list CPU solver: the paper's uniform cell list, numba-compiled.

SNP builds the paper's arrays by counting sort: the cell of each particle
(particleIndex), the count per cell (particleCellNum), cellBegin (exclusive
prefix sum, with the end sentinel) and the order of particles by cell
(cellParticleOrder). Every per-particle array is then gathered into cell
order, so the three cells of a stencil row are one contiguous range and the
pair loops stream through memory. Cells are one cutoff wide in x and at least
one cutoff tall in y (a whole number of rows fills the periodic height).

``threads=1`` runs the serial code, as the paper's CPU code did;
``threads=N`` runs the same source compiled with numba's parallel loops on N
threads, as the honest multi-core peer.

Two pair loops (``pair_loop``): ``gather``, the paper's, visits every
particle's 3x3 stencil in every sweep; ``list`` (solvers/search/pairlist.py) lists
each pair once per search with its kernel factors and updates both sides,
which is several times faster but takes memory. ``auto`` (the default) takes
the list where it fits in memory and the gather loop where it does not.
"""

from __future__ import annotations

from functools import lru_cache

import numba
import numpy as np

from solvers.interface import across_x
from solvers.physics.backend import COMPILED, cpu_loops, cpu_sorting, cpu_updates, use_threads
from solvers.scene import SceneError
from solvers.search import pairlist
from solvers.search.celllist import CellListSolver


def counting_sort(cell, ncells, begin, order, sorted_cell) -> None:
    """cellBegin and cellParticleOrder by a stable counting sort of ``cell`` (solvers/loops/sorting.py)."""
    cpu_sorting().counting_sort(cell, ncells, begin, order, sorted_cell)


@lru_cache(maxsize=None)
def sweeps(precision: str, kernel: str, parallel: bool, across: bool = True) -> dict:
    """The interaction loops for ``precision`` and ``kernel``, serial or on numba's thread pool, with or
    without the pairs across an x seam or wall (``across``; solvers/loops/cells.py, compiled once per
    machine), and the per-particle updates."""
    loops = cpu_loops("cells", precision, kernel, parallel, across)
    return {**{name: getattr(loops, name) for name in COMPILED["cells"]}, **cpu_updates(precision, parallel)}


class LinkedListCPU(CellListSolver):
    """Uniform cell list on the CPU, serial or multi-threaded (``threads``), with the pair list or the gather loop."""

    name = "linkedlist-cpu"
    summary = (
        "uniform cell list (the paper's cellBegin arrays), serial or --threads N|all;\n"
        "--pair-loop list (default where it fits) or gather (the paper's loop)"
    )
    pair_loops = ("list", "gather")
    threaded = True
    boundaries = ("free-x", "periodic-x", "wall-x", "free-y", "periodic-y")

    def __init__(self, threads: int = 1, pair_loop: str = "auto"):
        super().__init__(threads=threads or 1, pair_loop=pair_loop)
        self.requested_pair_loop = pair_loop

    def input(self, scene) -> None:
        super().input(scene)
        self.pair_loop = self.choose_pair_loop(scene, self.requested_pair_loop)
        if self.threads > 1:  # the count is decided: numba's pool set once here, not on every launch
            use_threads(self.threads, decided=True)

    @classmethod
    def list_fits(cls, scene) -> bool:
        """Whether the particle arrays and the pair list fit in the scene's memory limit (a scene that
        states none: they do; the harness gives every scene the memory available before it resolves ``auto``)."""
        limit = scene.memory_limit()
        return limit is None or cls.memory_bytes(scene, "list") <= limit

    @classmethod
    def memory_bytes(cls, scene, pair_loop: str = "auto") -> int:
        """The particle arrays, and the pair list where the run keeps one, B."""
        lists = cls.choose_pair_loop(scene, pair_loop) == "list"
        return scene.memory_bytes() + (pairlist.list_bytes(scene) if lists else 0)

    @classmethod
    def choose_pair_loop(cls, scene, requested: str = "auto") -> str:
        """``auto``: ``list`` where the arrays and the pair list fit in the scene's memory limit, else ``gather``."""
        if requested != "auto":
            return requested
        return "list" if "list" in cls.pair_loops and cls.list_fits(scene) else "gather"

    def check_scene(self, scene) -> None:
        if not isinstance(self.threads, int) or not 1 <= self.threads <= numba.config.NUMBA_NUM_THREADS:
            raise SceneError(
                f"threads must be between 1 and {numba.config.NUMBA_NUM_THREADS} on this machine (got {self.threads!r})"
            )
        if self.requested_pair_loop == "list" and not self.list_fits(scene):
            arrays, pairs = scene.memory_bytes(), pairlist.list_bytes(scene)
            raise SceneError(
                f"pair_loop list: dx = {scene.dx} m needs {pairs / 2**30:.3g} GiB of pair list and "
                f"{arrays / 2**30:.3g} GiB of arrays, more than the {scene.memory_limit() / 2**30:.3g} "
                "GiB available; use --pair-loop gather (or auto)"
            )

    def probe(self) -> "LinkedListCPU":
        return type(self)(threads=self.threads, pair_loop=self.pair_loop)

    def allocate_cells(self) -> None:
        n = self.scene.n_particles
        self.cell = np.empty(n, np.int32)
        self.sorted_cell = np.empty(n, np.int32)
        self.order = np.empty(n, np.int64)
        # unsigned cell bounds: numba then skips negative-index wraparound on every
        # neighbour load (measured 20-25 % faster sweeps)
        self.begin = np.zeros(self.ncells + 1, np.uint32)
        self.pairs = pairlist.PairList(self.scene, self.threads) if self.pair_loop == "list" else None
        self.spare = None  # the next gather's target array

    def launch(self, name: str, *args):
        if self.threads > 1:
            use_threads(self.threads)  # a call into numba only if another solver set another count since
        s = self.scene
        return sweeps(s.precision, s.kernel, self.threads > 1, across_x(s))[name](*args)

    def sort_cells(self) -> None:
        """SNP in four steps, each its own method: the cell of every particle (:meth:`cell_ids`), the order
        by cell (:meth:`cell_order`), every per-particle array into that order (:meth:`permute`), then the
        pair list if used (x-sorted within each cell first: the list scans x-sorted stencil rows)."""
        a = self.arrays
        self.cell_ids()
        order, begin = self.cell_order()
        if begin is not self.begin:
            self.begin[:] = begin
        if order is not self.order:  # a variant's own order: the cells in it by one gather
            self.order = np.ascontiguousarray(order, dtype=np.int64)
            np.take(self.cell, self.order, out=self.sorted_cell)
        if self.pairs is not None:
            cpu_sorting().sort_cells_by_x(self.order, self.begin, a["lx"], a["sx"], self.scene.dx)
        self.permute(self.order)
        self.cell, self.sorted_cell = self.sorted_cell, self.cell
        if self.pairs is not None:
            self.pairs.build(*self.geometry(), self.k)

    def cell_order(self) -> tuple:
        """(cellParticleOrder, cellBegin) for the cells in ``self.cell`` (particleIndex): the permutation
        that puts the particles in cell order, stable (by particle within a cell), and the first position
        of every cell with the end sentinel (``ncells + 1`` entries). Here a counting sort into the
        solver's own arrays (which also leaves the cells in that order in ``self.sorted_cell``); a variant
        overrides this method alone and may return arrays of its own."""
        counting_sort(self.cell, self.ncells, self.begin, self.order, self.sorted_cell)
        return self.order, self.begin

    def gathered(self, arr, order):
        """``arr`` reordered on the solver's threads, into the spare array; ``arr`` becomes the spare.
        One extra array in all, and no fresh pages to fault in every step (a new array per gather cost
        40 ns per particle here)."""
        out = self.spare
        if out is None or out.shape != arr.shape or out.dtype != arr.dtype:
            out = np.empty_like(arr)
        self.launch("gather", arr, order, out, self.threads)
        self.spare = arr
        return out

    def _sweep(self, continuity: bool, momentum: bool) -> None:
        if self.pairs is None:
            return super()._sweep(continuity, momentum)
        if self.threads > 1:
            use_threads(self.threads)
        a = self.arrays
        walls = bool(self.scene.walls)  # the list holds the real pairs; the mirrors' part is added at the walls
        if continuity:
            self.pairs.continuity(a["u"], a["v"], a["vol"], a["drho"], a["dd"], self.k)
            if walls:
                self.launch("wall_continuity", *self.geometry(), a["u"], a["v"], a["vol"], a["drho"], a["dd"], self.k)
        if momentum:
            self.pairs.momentum(a["mass"], a["pr"], a["ax"], a["ay"])
            if walls:
                self.launch("wall_momentum", *self.geometry(), a["mass"], a["pr"], a["ax"], a["ay"], self.k)

    def count_neighbours(self) -> int:
        """On a cell list of its own, over copies of the positions in its cell order (the state untouched)."""
        a, n = self.arrays, self.scene.n_particles
        cell, sorted_cell, order = np.empty(n, np.int32), np.empty(n, np.int32), np.empty(n, np.int64)
        begin = np.zeros(self.ncells + 1, np.uint32)
        copies = [a[name].copy() for name in ("lx", "ly", "sx", "sy")]  # the kernel may wrap them
        self.launch("cell_ids", *self.grid_arguments(*copies, cell))
        counting_sort(cell, self.ncells, begin, order, sorted_cell)
        positions = [arr[order] for arr in copies]
        return int(self.launch("neighbours", sorted_cell, begin, self.ncx, self.ncy, *positions, self.k))
