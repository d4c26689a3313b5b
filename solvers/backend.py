"""The shared pair physics (solvers/pairs.py) compiled for numba's CPU target."""
from __future__ import annotations

from functools import lru_cache


@lru_cache(maxsize=None)
def cpu_pairs(precision: str):
    """The pair functions for numba's CPU target in ``precision``, inlined into the sweeps that call them."""
    import numba

    from .kernel import make_exp_neg_table
    from .pairs import make_pairs

    return make_pairs(numba.njit(inline="always"), make_exp_neg_table(precision))
