"""Fields sampled at points off the particles: first-order moving least squares over the particles in reach.

Used where a value is wanted between particles: a body's ghosts take the fluid's values at their mirror points
(solvers/bodies/), and a run records drho at probe points (:meth:`solvers.interface.Solver.sample`).
"""

from __future__ import annotations

import numpy as np


def mls_weights(scene, points, fluid, volume: float):
    """The sampling matrix (scipy CSR, points x fluid): row p holds the weights that give a field's value at
    ``points[p]`` from its values at the ``fluid`` positions ((m, 2) arrays, m), by first-order moving least
    squares with the scene's kernel W (cut at its cutoff) and each particle's ``volume`` (m^2); Shepard's
    normalised average where the moment matrix is near singular (fewer than 6 neighbours, or all to one side
    of a line)."""
    from scipy.sparse import csr_matrix
    from scipy.spatial import cKDTree

    h, cutoff = scene.h, scene.cutoff
    tree = cKDTree(fluid)
    lists = tree.query_ball_point(points, cutoff)
    counts = np.array([len(n) for n in lists], dtype=np.int64)
    rows = np.repeat(np.arange(len(points)), counts)
    cols = np.concatenate([np.asarray(n, dtype=np.int64) for n in lists]) if counts.sum() else np.zeros(0, np.int64)
    d = (fluid[cols] - points[rows]) / h  # in units of h: a well-scaled basis
    w = scene.sph_kernel.value(np.hypot(d[:, 0], d[:, 1]) * h, h) * volume
    basis = np.stack([np.ones_like(w), d[:, 0], d[:, 1]], axis=1)
    moments = np.zeros((len(points), 3, 3))
    for i in range(3):
        for j in range(3):
            moments[:, i, j] = np.bincount(rows, weights=w * basis[:, i] * basis[:, j], minlength=len(points))
    total = moments[:, 0, 0]
    det = np.linalg.det(moments)
    good = (counts >= 6) & (total > 0) & (np.abs(det) > 1e-6 * np.maximum(total, 1e-300) ** 3)
    coef = np.zeros((len(points), 3))
    if good.any():
        coef[good] = np.linalg.solve(moments[good], np.tile([1.0, 0.0, 0.0], (int(good.sum()), 1))[..., None])[..., 0]
    shepard = ~good & (total > 0)
    coef[shepard, 0] = 1.0 / total[shepard]
    psi = w * np.einsum("pk,pk->p", coef[rows], basis)
    return csr_matrix((psi, (rows, cols)), shape=(len(points), len(fluid)))
