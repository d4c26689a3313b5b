"""Solvers: the scene, the shared physics, and the implementations behind one interface.

``make_solver(name)`` returns a solver; the GPU solver is imported lazily so
that the package works with no CUDA library installed.
"""
from __future__ import annotations

from .interface import STAGES, Fields, Solver, SolverUnavailable
from .scene import INTEGRATORS, MODELS, NUMERICS, PRECISIONS, Scene, SceneError

SOLVERS = ("allpair-cpu", "linkedlist-cpu", "linkedlist-gpu")


def make_solver(name: str, threads: int | None = None) -> Solver:
    """The solver called ``name`` (one of SOLVERS)."""
    if name == "allpair-cpu":
        from .allpair_cpu import AllPairCPU

        if threads not in (None, 1):
            raise SceneError(f"threads: allpair-cpu is serial, as in the paper (got {threads})")
        return AllPairCPU()
    if name == "linkedlist-cpu":
        from .linkedlist_cpu import LinkedListCPU

        return LinkedListCPU(threads=threads)
    if name == "linkedlist-gpu":
        from .linkedlist_gpu import LinkedListGPU

        return LinkedListGPU()
    raise SceneError(f"solver must be one of {', '.join(SOLVERS)} (got {name!r})")


__all__ = ["Scene", "SceneError", "Solver", "SolverUnavailable", "Fields", "STAGES", "SOLVERS",
           "MODELS", "INTEGRATORS", "PRECISIONS", "NUMERICS", "make_solver"]
