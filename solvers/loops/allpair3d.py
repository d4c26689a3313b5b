"""The all-pair CPU solver's interaction loops in 3D, serial as in the paper, and its per-particle updates. A
template of solvers.jitcache, specialised by solvers.allpair_cpu.sweeps."""

P = None  # the 3D pair functions for numba's CPU target (solvers.physics.backend.cpu_pairs3d), bound by jitcache


def continuity(lx, ly, lz, sx, sy, sz, u, v, w, vol, drho, out, k):
    n = lx.shape[0]
    for i in range(n):
        out[i] = P.continuity_allpair(i, n, lx, ly, lz, sx, sy, sz, u, v, w, vol, drho, k)


def momentum(lx, ly, lz, sx, sy, sz, mass, pr, ax, ay, az, k):
    n = lx.shape[0]
    for i in range(n):
        ax[i], ay[i], az[i] = P.momentum_allpair(i, n, lx, ly, lz, sx, sy, sz, mass, pr, k)


def neighbours(lx, ly, lz, sx, sy, sz, k):
    n = lx.shape[0]
    total = 0
    for i in range(n):
        total += P.neighbours_allpair(i, n, lx, ly, lz, sx, sy, sz, k)
    return total


def moments(lx, ly, lz, sx, sy, sz, vol, mxx, mxy, mxz, myy, myz, mzz, gx, gy, gz, k):
    """The kernel gradient correction's moment matrix (6) and Gamma (3) of every particle (solvers/corrections/)."""
    n = lx.shape[0]
    for i in range(n):
        mxx[i], mxy[i], mxz[i], myy[i], myz[i], mzz[i], gx[i], gy[i], gz[i] = P.moments_allpair(
            i, n, lx, ly, lz, sx, sy, sz, vol, k
        )
