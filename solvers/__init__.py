"""Solvers: the scene, the shared physics, and the implementations behind one interface.

``make_solver(name)`` returns a solver; the GPU solver is imported lazily so
that the package works with no CUDA library installed.
"""
from __future__ import annotations

from .interface import STAGES, Fields, Solver, SolverUnavailable
from .kernel import KERNELS
from .scene import INTEGRATORS, MODELS, NUMERICS, PRECISIONS, Scene, SceneError

SOLVERS = ("allpair-cpu", "linkedlist-cpu", "linkedlist-gpu")


# How each solver can visit pairs; "auto" lets the solver choose for the scene.
PAIR_LOOPS = {"allpair-cpu": ("all-pairs",), "linkedlist-cpu": ("list", "gather"), "linkedlist-gpu": ("gather",)}


def check_pair_loop(name: str, requested: str) -> None:
    """SceneError unless solver ``name`` offers ``requested`` (or it is ``auto``)."""
    if name not in SOLVERS:
        raise SceneError(f"solver must be one of {', '.join(SOLVERS)} (got {name!r})")
    if requested != "auto" and requested not in PAIR_LOOPS[name]:
        raise SceneError(f"pair_loop: {name} offers auto, {', '.join(PAIR_LOOPS[name])} (got {requested!r})")


def resolve_pair_loop(name: str, scene: Scene, requested: str = "auto") -> str:
    """The pair loop solver ``name`` uses for ``scene``: ``requested``, or its choice for ``auto``.

    linkedlist-cpu offers ``list`` (each pair once, kernel factors kept; its
    choice where it fits in memory) and ``gather`` (the paper's stencil loop).
    """
    check_pair_loop(name, requested)
    if name == "linkedlist-cpu":
        from .linkedlist_cpu import LinkedListCPU

        return LinkedListCPU.choose_pair_loop(scene, requested)
    return PAIR_LOOPS[name][0]


def make_solver(name: str, threads: int = 1, pair_loop: str = "auto") -> Solver:
    """The solver called ``name`` (one of SOLVERS) on ``threads`` CPU threads, with ``pair_loop``."""
    check_pair_loop(name, pair_loop)
    if name == "allpair-cpu":
        from .allpair_cpu import AllPairCPU

        if threads not in (None, 1):
            raise SceneError(f"threads: allpair-cpu is serial, as in the paper (got {threads})")
        return AllPairCPU()
    if name == "linkedlist-cpu":
        from .linkedlist_cpu import LinkedListCPU

        return LinkedListCPU(threads=threads, pair_loop=pair_loop)
    from .linkedlist_gpu import LinkedListGPU

    return LinkedListGPU()


__all__ = ["Scene", "SceneError", "Solver", "SolverUnavailable", "Fields", "STAGES", "SOLVERS",
           "MODELS", "INTEGRATORS", "PRECISIONS", "KERNELS", "NUMERICS", "PAIR_LOOPS", "check_pair_loop", "make_solver",
           "resolve_pair_loop"]
