"""Solvers: the scene, the shared physics, and the implementations behind one interface.

The solvers are found by the registry (solvers/registry.py): the modules of
this package and the ``pcabench.solvers`` entry points of installed packages.
The SPH kernels are found the same way (solvers/kernels/, ``pcabench.kernels``).
``make_solver(name)`` returns one; nothing here touches a GPU library.
"""

from __future__ import annotations

from solvers.interface import STAGES, Fields, Solver, SolverUnavailable
from solvers.kernels import DEFAULT_KERNEL, Kernel, kernel_named, kernel_names
from solvers.method import INTEGRATORS
from solvers.registry import (
    DEFAULT_SOLVER,
    ENTRY_POINT_GROUP,
    GPU_SOLVER,
    check_pair_loop,
    make_solver,
    registry,
    resolve_pair_loop,
    solver_class,
    solver_names,
)
from solvers.scene import MODELS, PRECISIONS, Scene, SceneError
from solvers.scenes import DEFAULT_SCENE, SceneKind, scene_kind, scene_names, scenes

__all__ = [
    "Scene",
    "SceneError",
    "Solver",
    "SolverUnavailable",
    "Fields",
    "STAGES",
    "MODELS",
    "INTEGRATORS",
    "PRECISIONS",
    "DEFAULT_KERNEL",
    "Kernel",
    "kernel_named",
    "kernel_names",
    "DEFAULT_SOLVER",
    "GPU_SOLVER",
    "ENTRY_POINT_GROUP",
    "registry",
    "solver_names",
    "solver_class",
    "check_pair_loop",
    "make_solver",
    "resolve_pair_loop",
    "DEFAULT_SCENE",
    "SceneKind",
    "scene_kind",
    "scene_names",
    "scenes",
]
