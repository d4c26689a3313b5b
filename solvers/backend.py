"""Compile the shared pair physics (solvers/pairs.py) for one backend."""
from __future__ import annotations

import importlib.util
from functools import lru_cache
from pathlib import Path

PAIRS_SOURCE = Path(__file__).with_name("pairs.py")


def compile_pairs(jit, exp_neg, tag: str):
    """Execute pairs.py as module ``pcabench.solvers._pairs_<tag>`` with ``jit`` bound.

    Each function in it then calls the others through that module's globals,
    so one decorator (numba.njit or numba.cuda.jit(device=True)) compiles the
    whole interaction code for a backend.
    """
    name = f"{__package__}._pairs_{tag}"
    spec = importlib.util.spec_from_file_location(name, PAIRS_SOURCE)
    module = importlib.util.module_from_spec(spec)
    module.jit = jit
    module.exp_neg = jit(exp_neg)
    spec.loader.exec_module(module)
    return module


@lru_cache(maxsize=None)
def cpu_pairs(precision: str):
    """The pair physics compiled for numba's CPU target in ``precision`` (inlined into the sweeps)."""
    import numba

    from .kernel import make_exp_neg_table

    return compile_pairs(numba.njit(inline="always"), make_exp_neg_table(precision), f"cpu_{precision}")
