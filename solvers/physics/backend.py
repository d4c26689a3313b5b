"""The shared per-particle physics (solvers/physics/pairs.py) compiled for numba's CPU target."""

from __future__ import annotations

import threading
from functools import lru_cache
from types import ModuleType

from solvers.kernels import DEFAULT_KERNEL

_numba_threads = threading.local()  # the thread count this Python thread last gave numba through use_threads


def use_threads(n: int, decided: bool = False) -> None:
    """numba's thread count for the parallel loops launched from this Python thread (numba keeps it per
    thread): set where a solver decides its count (``decided``: its input stage), and before a launch
    only when another count was set since, as when two solvers alternate in one process; else nothing
    but a thread-local read (numba.set_num_threads costs about 1 us a call)."""
    if decided or getattr(_numba_threads, "n", None) != n:
        import numba

        numba.set_num_threads(n)
        _numba_threads.n = n


@lru_cache(maxsize=None)
def cpu_pairs(precision: str, kernel: str = DEFAULT_KERNEL, across: bool = True, displaced: bool = True):
    """The pair functions for numba's CPU target in ``precision`` with ``kernel``'s G, inlined into the
    sweeps that call them; ``across``: with the pairs across an x seam or wall; ``displaced``: with the
    particles' displacements in every separation (solvers/physics/pairs.py)."""
    import numba

    from solvers.kernels.constants import make_exp_neg_table
    from solvers.physics.pairs import make_pairs

    exp_neg = make_exp_neg_table(precision)
    return make_pairs(numba.njit(inline="always"), exp_neg, kernel, precision, across, displaced)


@lru_cache(maxsize=None)
def cpu_pairs3d(precision: str, kernel: str = DEFAULT_KERNEL, across: bool = True, displaced: bool = True):
    """The 3D pair functions (solvers/physics/pairs3d.py) for numba's CPU target, as :func:`cpu_pairs`; the cell
    list's stencil the sites' (solvers/search/sites.py)."""
    import numba

    from solvers.kernels.constants import make_exp_neg_table
    from solvers.physics.pairs3d import make_pairs3d

    exp_neg = make_exp_neg_table(precision)
    return make_pairs3d(numba.njit(inline="always"), exp_neg, kernel, precision, across, displaced, sites=True)


def pair_sources(kernel: str = DEFAULT_KERNEL, dims: int = 2) -> tuple:
    """What the compiled pair functions are made of, for the cache's key (solvers/jitcache.py): the pair
    physics, the constant tuple and exp(-x), this module, and the kernel's own file (a plug-in's too)."""
    from solvers.kernels import kernel_named

    return (
        "solvers.physics.pairs3d" if dims == 3 else "solvers.physics.pairs",
        "solvers.kernels.constants",
        "solvers.physics.backend",
        type(kernel_named(kernel)),
    )


def cpu_loops(
    template: str,
    precision: str,
    kernel: str,
    parallel: bool | None,
    across: bool = True,
    displaced: bool = True,
    **bind,
) -> ModuleType:
    """The loops of ``template`` (solvers/loops/) over :func:`cpu_pairs` for ``precision``, ``kernel``,
    ``across`` and ``displaced``, compiled with numba's CPU target (on its threads where ``parallel``; every
    function the template lists in ``COMPILED``) and cached on disk once per machine (solvers/jitcache.py).
    ``bind``: more free names, as values."""
    from solvers import jitcache

    module = f"solvers.loops.{template}"
    options = {"nogil": True} if parallel is None else {"nogil": True, "parallel": parallel}
    options.update(LOOP_OPTIONS.get(template, {}))
    names = COMPILED[template]
    pairs = "cpu_pairs3d" if template.endswith("3d") else "cpu_pairs"  # a 3D template's pair functions are 3D
    return jitcache.specialise(
        module,
        bind={
            "P": f"{pairs}({precision!r}, {kernel!r}, {across!r}, {displaced!r})",
            **{k: repr(v) for k, v in bind.items()},
        },
        functions={name: ("numba.njit", options) for name in names},
        imports=("import numba", f"from solvers.physics.backend import {pairs}"),
        depends=pair_sources(kernel, 3 if pairs == "cpu_pairs3d" else 2),
    )


# The functions each CPU template compiles (the rest of a template is inlined helpers and constants), and
# the options a template adds to nogil (and parallel where a solver runs threads).
COMPILED = {
    "updates": (
        "coefficients",
        "kick",
        "advance",
        "gather",
        "corrected_velocity",
        "corrected_continuity",
        "corrected_momentum",
    ),
    "sorting": ("counting_sort", "sort_cells_by_x"),
    "cells": (
        "continuity",
        "momentum",
        "moments",
        "neighbours",
        "wall_continuity",
        "wall_momentum",
        "wall_moments",
        "cell_ids",
    ),
    "allpair": ("continuity", "momentum", "moments", "neighbours"),
    "cells3d": ("continuity", "continuity_split", "momentum", "moments", "neighbours", "cell_ids"),
    "allpair3d": ("continuity", "momentum", "moments", "neighbours"),
    "updates3d": ("kick", "advance", "corrected_velocity", "corrected_continuity", "corrected_momentum"),
    "pairlist": ("build", "continuity", "continuity_split", "momentum", "moments"),
}
LOOP_OPTIONS = {"pairlist": {"error_model": "numpy"}}


@lru_cache(maxsize=None)
def cpu_updates(precision: str, parallel: bool, dims: int = 2) -> dict:
    """The per-particle loops of a CPU solver, serial or on numba's threads: the sweeps' coefficients,
    the system update (kick, advance) and the gather that reorders an array (``parts`` ranges); in 3D the
    kick, the advance and the correction's passes with the third component (solvers/loops/updates3d.py)."""
    loops = cpu_loops("updates", precision, DEFAULT_KERNEL, parallel)  # they do not depend on the kernel
    out = {name: getattr(loops, name) for name in COMPILED["updates"]}
    if dims == 3:
        third = cpu_loops("updates3d", precision, DEFAULT_KERNEL, parallel)
        out.update({name: getattr(third, name) for name in COMPILED["updates3d"]})
    return out


@lru_cache(maxsize=None)
def cpu_sorting() -> ModuleType:
    """The serial cell sort (solvers/loops/sorting.py): ``counting_sort``, ``sort_cells_by_x``, compiled once."""
    from solvers import jitcache

    compiled = ("numba.njit", {"nogil": True})
    return jitcache.specialise(
        "solvers.loops.sorting",
        bind={},
        functions=dict.fromkeys(COMPILED["sorting"], compiled),
        imports=("import numba",),
    )
