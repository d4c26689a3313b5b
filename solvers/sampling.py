"""Fields sampled at points off the particles: first-order moving least squares over the particles in reach.

Used where a value is wanted between particles: a body's ghosts take the fluid's values at their mirror points
(solvers/boundaries/bodies/), and a run records drho at probe points (:meth:`solvers.interface.Solver.sample`).
"""

from __future__ import annotations

import numpy as np


def mls_weights(scene, points, fluid, volume: float):
    """The sampling matrix (scipy CSR, points x fluid): row p holds the weights that give a field's value at
    ``points[p]`` from its values at the ``fluid`` positions ((m, d) arrays, m; d = 2 or 3, the scene's), by
    first-order moving least squares with the scene's kernel W (cut at its cutoff) and each particle's ``volume``
    (m^d); Shepard's normalised average where the moment matrix is near singular (fewer than 3 d neighbours, or
    all to one side of a line or plane)."""
    from scipy.sparse import csr_matrix
    from scipy.spatial import cKDTree

    h, cutoff = scene.h, scene.cutoff
    tree = cKDTree(fluid)
    lists = tree.query_ball_point(points, cutoff)
    counts = np.array([len(n) for n in lists], dtype=np.int64)
    rows = np.repeat(np.arange(len(points)), counts)
    cols = np.concatenate([np.asarray(n, dtype=np.int64) for n in lists]) if counts.sum() else np.zeros(0, np.int64)
    dims = fluid.shape[1]
    n = dims + 1  # the basis 1, x, y (, z)
    d = (fluid[cols] - points[rows]) / h  # in units of h: a well-scaled basis
    distance = (np.hypot(d[:, 0], d[:, 1]) if dims == 2 else np.sqrt(np.sum(d * d, axis=1))) * h
    w = (scene.sph_kernel.value(distance, h, dims=3) if dims == 3 else scene.sph_kernel.value(distance, h)) * volume
    basis = np.concatenate([np.ones_like(w)[:, None], d], axis=1)
    moments = np.zeros((len(points), n, n))
    for i in range(n):
        for j in range(n):
            moments[:, i, j] = np.bincount(rows, weights=w * basis[:, i] * basis[:, j], minlength=len(points))
    total = moments[:, 0, 0]
    det = np.linalg.det(moments)
    good = (counts >= 3 * dims) & (total > 0) & (np.abs(det) > 1e-6 * np.maximum(total, 1e-300) ** n)
    coef = np.zeros((len(points), n))
    unit = np.eye(n)[0]
    if good.any():
        coef[good] = np.linalg.solve(moments[good], np.tile(unit, (int(good.sum()), 1))[..., None])[..., 0]
    shepard = ~good & (total > 0)
    coef[shepard, 0] = 1.0 / total[shepard]
    psi = w * np.einsum("pk,pk->p", coef[rows], basis)
    return csr_matrix((psi, (rows, cols)), shape=(len(points), len(fluid)))
