"""The per-particle loops of a CPU solver, serial or on numba's threads: the sweeps' coefficients, the
system update (kick, advance) and the gather that reorders an array (``parts`` ranges). A template of
solvers.jitcache, specialised by solvers.physics.backend.cpu_updates."""

import numba
from numba import prange

P = None  # the pair functions for numba's CPU target (solvers.physics.backend.cpu_pairs), bound by solvers.jitcache


@numba.njit(nogil=True)
def gather_range(src, order, out, lo, hi):
    """out[i] = src[order[i]] for lo <= i < hi. Compiled on its own: written inline in a parallel loop's
    body, numba compiled this loop 2.5 times slower (measured here)."""
    for i in range(lo, hi):
        out[i] = src[order[i]]


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


def corrected_velocity(u, v, lxx, lxy, lyy, wx, wy):
    for i in prange(u.shape[0]):
        P.corrected_velocity_at(i, u, v, lxx, lxy, lyy, wx, wy)


def corrected_continuity(dd, ddx, drho, wx, wy, gx, gy, split, k):
    for i in prange(dd.shape[0]):
        P.corrected_continuity_at(i, dd, ddx, drho, wx, wy, gx, gy, split, k)


def corrected_momentum(ax, ay, drho, lxx, lxy, lyy, gx, gy, k):
    for i in prange(ax.shape[0]):
        P.corrected_momentum_at(i, ax, ay, drho, lxx, lxy, lyy, gx, gy, k)
