"""The shared per-particle physics (solvers/pairs.py) compiled for numba's CPU target."""

from __future__ import annotations

import threading
from functools import lru_cache

from .kernels import DEFAULT_KERNEL

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
def cpu_pairs(precision: str, kernel: str = DEFAULT_KERNEL):
    """The pair functions for numba's CPU target in ``precision`` with ``kernel``'s G, inlined into the
    sweeps that call them."""
    import numba

    from .kernel import make_exp_neg_table
    from .pairs import make_pairs

    return make_pairs(numba.njit(inline="always"), make_exp_neg_table(precision), kernel, precision)


def _gather_range(src, order, out, lo, hi):
    """out[i] = src[order[i]] for lo <= i < hi. Compiled on its own: written inline in a parallel loop's
    body, numba compiled this loop 2.5 times slower (measured here)."""
    for i in range(lo, hi):
        out[i] = src[order[i]]


@lru_cache(maxsize=None)
def cpu_updates(precision: str, parallel: bool) -> dict:
    """The per-particle loops of a CPU solver, serial or on numba's threads: the sweeps' coefficients,
    the system update (kick, advance) and the gather that reorders an array (``parts`` ranges)."""
    import numba

    P = cpu_pairs(precision)  # the per-particle functions only: they do not depend on the kernel
    prange = numba.prange
    gather_range = numba.njit(nogil=True)(_gather_range)

    def coefficients(drho, mass, vol, pr, continuity, momentum, k):
        for i in prange(drho.shape[0]):
            P.coefficients_at(i, drho, mass, vol, pr, continuity, momentum, k)

    def kick(u, v, ax, ay, c):
        for i in prange(u.shape[0]):
            P.kick_at(i, u, v, ax, ay, c)

    def advance(drho, dd, sx, sy, u, v, c, moving):
        for i in prange(drho.shape[0]):
            P.advance_at(i, drho, dd, sx, sy, u, v, c, moving)

    def gather(src, order, out, parts):
        n = order.shape[0]
        for t in prange(parts):
            gather_range(src, order, out, t * n // parts, (t + 1) * n // parts)

    jit = numba.njit(nogil=True, parallel=parallel)
    return {"coefficients": jit(coefficients), "kick": jit(kick), "advance": jit(advance), "gather": jit(gather)}
