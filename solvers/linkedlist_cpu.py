"""Linked-list CPU solver: the paper's uniform cell list, numba-compiled.

SNP: the solver's search (solvers/search/celllist.CellList, held as
``self.nnps``) builds the paper's arrays by counting sort: the cell of each
particle (particleIndex), the count per cell (particleCellNum), cellBegin
(exclusive prefix sum, with the end sentinel) and the order of particles by
cell (cellParticleOrder). The solver then gathers every per-particle array
into cell order, so the three cells of a stencil row are one contiguous range
and the pair loops stream through memory. Cells are one cutoff wide in x and
at least one cutoff tall in y (a whole number of rows fills the periodic
height).

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

from solvers.boundaries import across
from solvers.physics.backend import COMPILED, cpu_loops, cpu_sorting, cpu_updates, use_threads
from solvers.scene import SceneError
from solvers.search import pairlist
from solvers.search.celllist import CellListSolver


@lru_cache(maxsize=None)
def sweeps(
    precision: str, kernel: str, parallel: bool, across: bool = True, dims: int = 2, displaced: bool = True
) -> dict:
    """The interaction loops for ``precision`` and ``kernel``, serial or on numba's thread pool, with or
    without the pairs across an x seam or wall (``across``; solvers/loops/cells.py, compiled once per
    machine), with or without the displacements in the separations (``displaced``), and the per-particle
    updates; in 3D the loops over the sites' grid (solvers/search/sites.py) and their updates
    (solvers/loops/cells3d.py)."""
    if dims == 3:
        loops = cpu_loops("cells3d", precision, kernel, parallel, across, displaced)
        return {
            **cpu_updates(precision, parallel, dims),
            **{name: getattr(loops, name) for name in COMPILED["cells3d"]},
        }
    loops = cpu_loops("cells", precision, kernel, parallel, across, displaced)
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
    boundaries = ("free-x", "periodic-x", "wall-x", "free-y", "periodic-y", "periodic-z", "free-z", "body")

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
    def pair_loops_for(cls, scene) -> tuple:
        """Both loops in 2D; a 3D scene's pairs (hundreds a particle) are summed on the fly: gather only."""
        return ("gather",) if scene.dims == 3 else tuple(cls.pair_loops)

    @classmethod
    def choose_pair_loop(cls, scene, requested: str = "auto") -> str:
        """``auto``: ``list`` where the arrays and the pair list fit in the scene's memory limit, else ``gather``."""
        if requested != "auto":
            return requested
        if "list" not in cls.pair_loops_for(scene):
            return "gather"
        return "list" if "list" in cls.pair_loops and cls.list_fits(scene) else "gather"

    def check_scene(self, scene) -> None:
        if not isinstance(self.threads, int) or not 1 <= self.threads <= numba.config.NUMBA_NUM_THREADS:
            raise SceneError(
                f"threads must be between 1 and {numba.config.NUMBA_NUM_THREADS} on this machine (got {self.threads!r})"
            )
        if self.requested_pair_loop == "list" and "list" not in self.pair_loops_for(scene):
            raise SceneError(
                f"pair_loop list: the {scene.name} scene is 3D, whose pairs are summed on the fly (no list of "
                "every pair); use --pair-loop gather (or auto)"
            )
        if self.requested_pair_loop == "list" and not self.list_fits(scene):
            arrays, pairs = scene.memory_bytes(), pairlist.list_bytes(scene)
            raise SceneError(
                f"pair_loop list: dx = {scene.dx} m needs {pairs / 2**30:.3g} GiB of pair list and "
                f"{arrays / 2**30:.3g} GiB of arrays, more than the {scene.memory_limit() / 2**30:.3g} "
                "GiB available; use --pair-loop gather (or auto)"
            )

    def search_for_scene(self):
        """The cell list; in 3D on the sites' grid that the loops are compiled for (solvers/search/sites.py,
        solvers.physics.pairs3d.site_rule)."""
        return self.neighbour_search(self.scene, self.launch, self.xp, on_sites=True)

    def probe(self) -> "LinkedListCPU":
        return type(self)(threads=self.threads, pair_loop=self.pair_loop)

    def allocate_cells(self) -> None:
        self.pairs = pairlist.PairList(self.scene, self.threads) if self.pair_loop == "list" else None
        self.spare = None  # the next gather's target array

    def launch(self, name: str, *args):
        if self.threads > 1:
            use_threads(self.threads)  # a call into numba only if another solver set another count since
        s = self.scene
        return sweeps(s.precision, s.kernel, self.threads > 1, across(s), s.dims, self.displaced)[name](*args)

    def sort_cells(self) -> None:
        """SNP: the search bins the particles (``self.nnps.bin``: particleIndex, cellParticleOrder,
        cellBegin), every per-particle array goes into that order (:meth:`permute`), then the pair list if
        used (x-sorted within each cell first: the list scans x-sorted stencil rows)."""
        a, nnps = self.arrays, self.nnps
        order = nnps.bin(*(a[name] for name in nnps.positions))
        if self.pairs is not None:
            cpu_sorting().sort_cells_by_x(order, nnps.begin, a["lx"], a["sx"], self.scene.dx)
        self.permute(order)
        nnps.settle()
        if self.pairs is not None:
            self.pairs.build(*self.geometry(), self.k)

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

    def continuity_parts(self) -> None:
        """The pair list and the 3D gather loop computed the parts with the rate (:meth:`_sweep`); the 2D gather
        loop sweeps again."""
        if not self.fused_split():
            super().continuity_parts()

    def moments(self) -> tuple:
        """The gradient correction's moments. Moving particles (at every search): from the pair list (its
        factors, no kernel evaluation; the mirrors' part at walls from the edge columns), with accumulators
        the list keeps (``list_bytes``). Particles that stay (once a run) or no list: the gather loop's."""
        if self.pairs is None or not self.moving:
            return super().moments()
        if self.threads > 1:
            use_threads(self.threads)
        a = self.arrays
        out = self.pairs.moments(a["lx"], a["ly"], a["sx"], a["sy"], a["vol"], self.k)
        if self.walls is not None:
            self.walls.mirror_moments(self, out)
        return out

    def fused_split(self) -> bool:
        """Whether a split absorber's parts of the continuity rate come out of the rate's own pass: the pair list
        (2D: its x part), the 3D gather loop (the x and y parts); else (the 2D gather loop) a sweep each."""
        return self.split and (self.pairs is not None or self.scene.dims == 3)

    def _sweep(self, continuity: bool, momentum: bool) -> None:
        if self.pairs is None and continuity and self.split and self.scene.dims == 3:
            a = self.arrays
            if a["dd"] is not a["ddx"]:  # the whole rate and its parts in one pass (continuity_parts: nothing left)
                self.launch(
                    "continuity_split", *self.geometry(), a["u"], a["v"], a["w"], a["vol"], a["drho"], a["dd"],
                    a["ddx"], a["ddy"], self.k,
                )  # fmt: skip
                continuity = False
        if self.pairs is None:
            return super()._sweep(continuity, momentum)
        if self.threads > 1:
            use_threads(self.threads)
        a = self.arrays
        if continuity:
            parts = [(a["v"], a["dd"])]  # (v, the rate): the whole rate, and a split absorber's x part (v = 0)
            if self.split and a["dd"] is not a["ddx"]:  # the x part in the same pass (continuity_parts: nothing left)
                parts.append((self.no_velocity, a["ddx"]))
                self.pairs.continuity_split(a["u"], a["v"], a["vol"], a["drho"], a["dd"], a["ddx"], self.k)
            else:
                self.pairs.continuity(a["u"], a["v"], a["vol"], a["drho"], a["dd"], self.k)
        if momentum:
            self.pairs.momentum(a["mass"], a["pr"], a["ax"], a["ay"])
        if self.walls is not None:  # the list holds the real pairs; the mirrors' part is added at the walls
            self.walls.mirror_sweeps(self, parts if continuity else (), momentum)
