"""All-pair CPU solver: the paper's O(N^2) search, every particle against every other.

SNP is empty: the pair loop itself tests every pair against the cutoff, as
the paper's all-pair code does. Same pair physics as the cell list
(solvers/physics/pairs.py), with the minimum image in y instead of a cell stencil.
"""

from __future__ import annotations

import time
from functools import lru_cache

from solvers.boundaries import across
from solvers.interface import Solver, tiny_scene
from solvers.physics.backend import COMPILED, cpu_loops, cpu_updates
from solvers.search.allpairs import AllPairs


@lru_cache(maxsize=None)
def sweeps(precision: str, kernel: str, across: bool = True, dims: int = 2, displaced: bool = True) -> dict:
    """The all-pair interaction loops for ``precision`` and ``kernel``, with or without the mirrors across a
    wall (``across``; serial, as in the paper; solvers/loops/allpair.py, compiled once per machine) and the
    displacements in the separations (``displaced``), and
    the per-particle updates; in 3D solvers/loops/allpair3d.py's."""
    if dims == 3:
        loops = cpu_loops("allpair3d", precision, kernel, False, across, displaced)
        return {**cpu_updates(precision, False, dims), **{name: getattr(loops, name) for name in COMPILED["allpair3d"]}}
    loops = cpu_loops("allpair", precision, kernel, False, across, displaced)
    return {**{name: getattr(loops, name) for name in COMPILED["allpair"]}, **cpu_updates(precision, False)}


class AllPairCPU(Solver):
    """Every pair tested, serial, as in the paper's Fig. 9 comparison."""

    name = "allpair-cpu"
    summary = "every pair tested (the paper's all-pair search), serial"
    pair_loops = ("all-pairs",)
    pair_loop = "all-pairs"
    search = "all-pair"
    neighbour_search = AllPairs
    order = 2.0
    boundaries = (
        "free-x",
        "periodic-x",
        "wall-x",
        "free-y",
        "periodic-y",
        "periodic-z",
        "free-z",
        "body",
    )  # the minimum image

    def snp(self) -> None:
        """Nothing to build: the all-pair search happens inside the interaction loop."""

    def launch(self, name: str, *args):
        s = self.scene
        return sweeps(s.precision, s.kernel, across(s), s.dims, self.displaced)[name](*args)

    def warmup(self) -> float:
        t0 = time.perf_counter()
        probe = type(self)()
        probe.input(tiny_scene(self.scene))
        probe.init()
        probe.rates(True, True)
        probe.kick(0.5)
        probe.advance(1.0)
        probe.mean_neighbours()
        return time.perf_counter() - t0
