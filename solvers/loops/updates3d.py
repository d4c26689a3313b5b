"""The per-particle loops of a CPU solver on a 3D scene, serial or on numba's threads: the system update (kick,
advance) and the gradient correction's passes, with the third component (the sweeps' coefficients and the gather
are the 2D template's, solvers/loops/updates.py). A template of solvers.jitcache, specialised by
solvers.physics.backend.cpu_updates."""

from numba import prange

P = None  # the 3D pair functions for numba's CPU target (solvers.physics.backend.cpu_pairs3d), bound by jitcache


def kick(u, v, w, ax, ay, az, c):
    for i in prange(u.shape[0]):
        P.kick_at(i, u, v, w, ax, ay, az, c)


def advance(drho, dd, sx, sy, sz, u, v, w, c, moving):
    for i in prange(drho.shape[0]):
        P.advance_at(i, drho, dd, sx, sy, sz, u, v, w, c, moving)


def corrected_velocity(u, v, w, lxx, lxy, lxz, lyy, lyz, lzz, wx, wy, wz):
    for i in prange(u.shape[0]):
        P.corrected_velocity_at(i, u, v, w, lxx, lxy, lxz, lyy, lyz, lzz, wx, wy, wz)


def corrected_continuity(dd, drho, wx, wy, wz, gx, gy, gz, k):
    for i in prange(dd.shape[0]):
        P.corrected_continuity_at(i, dd, drho, wx, wy, wz, gx, gy, gz, k)


def corrected_momentum(ax, ay, az, drho, lxx, lxy, lxz, lyy, lyz, lzz, gx, gy, gz, k):
    for i in prange(ax.shape[0]):
        P.corrected_momentum_at(i, ax, ay, az, drho, lxx, lxy, lxz, lyy, lyz, lzz, gx, gy, gz, k)
