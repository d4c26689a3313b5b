"""The all-pair CPU solver's interaction loops, serial as in the paper. A template of solvers.jitcache,
specialised by solvers.allpair_cpu.sweeps."""

P = None  # the pair functions for numba's CPU target (solvers.physics.backend.cpu_pairs), bound by solvers.jitcache


def continuity(lx, ly, sx, sy, u, v, vol, drho, out, k):
    n = lx.shape[0]
    for i in range(n):
        out[i] = P.continuity_allpair(i, n, lx, ly, sx, sy, u, v, vol, drho, k)


def momentum(lx, ly, sx, sy, mass, pr, ax, ay, k):
    n = lx.shape[0]
    for i in range(n):
        ax[i], ay[i] = P.momentum_allpair(i, n, lx, ly, sx, sy, mass, pr, k)


def neighbours(lx, ly, sx, sy, k):
    n = lx.shape[0]
    total = 0
    for i in range(n):
        total += P.neighbours_allpair(i, n, lx, ly, sx, sy, k)
    return total


def moments(lx, ly, sx, sy, vol, mxx, mxy, myy, gx, gy, k):
    """The kernel gradient correction's moment matrix and Gamma of every particle (solvers/corrections/)."""
    n = lx.shape[0]
    for i in range(n):
        mxx[i], mxy[i], myy[i], gx[i], gy[i] = P.moments_allpair(i, n, lx, ly, sx, sy, vol, k)
