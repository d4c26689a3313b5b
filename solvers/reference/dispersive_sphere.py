"""The sphere scene's dispersion prediction: the exact series with the method's dispersion and an exact wall.

The 3D counterpart of solvers/reference/dispersive_cylinder.py. The series (solvers/reference/sphere.py) evolves
each wavenumber k of the pulse's spectrum, the free pulse's included, by cos(c0 k t); a `linear` run's mode of
wavenumber k in the bulk evolves instead by the integrator's own step program with c0 |D(k)| (the cubic
lattice's symbol, solvers/reference/dispersion3d.py) averaged over the directions of travel, as the scattered
sound travels every way. The series with that evolution is what a run would give if its only error were the
bulk's dispersion (the kernel's phase lag and the step's lead): the wall exact, the particles near it ignored.
Beside a run it splits the error into the bulk's share and the wall's (docs/accuracy.md "the rigid sphere").
The field's own error is not scored (as the scene's): the probes' over the window.
"""

from __future__ import annotations

import math

import numpy as np

from solvers.reference.dispersion import Prediction, scored_prediction
from solvers.reference.dispersion3d import phase_errors, predicted_stable_cfl, symbol
from solvers.reference.dispersive_cylinder import method_factor
from solvers.reference.pulse2d import gauss_legendre

POLAR_NODES = 6  # Gauss-Legendre nodes in cos(theta) over [0, 1] ...
AZIMUTHS = 6  # ... and midpoints in phi over [0, pi/2]: the octant (the cubic lattice's symmetry covers the rest)


def isotropic_symbol(scene, k) -> np.ndarray:
    """|D(k n)| averaged over the directions n of the unit sphere (the octant, by solid angle), 1/m, at
    wavenumbers ``k``."""
    k = np.asarray(k, dtype=np.float64)
    z, w = gauss_legendre(POLAR_NODES)
    mu, w_mu = 0.5 * (z + 1.0), 0.5 * w  # cos(theta) on [0, 1]
    phi = (np.arange(AZIMUTHS) + 0.5) * (0.5 * math.pi / AZIMUTHS)
    sin_theta = np.sqrt(1.0 - mu**2)
    n = np.stack(
        [np.outer(sin_theta, np.cos(phi)).ravel(), np.outer(sin_theta, np.sin(phi)).ravel(), np.repeat(mu, AZIMUTHS)]
    )  # (3, directions)
    weights = np.repeat(w_mu, AZIMUTHS) / AZIMUTHS  # sums to 1
    parts = symbol(scene, *(np.multiply.outer(k, c) for c in n))
    return np.sqrt(sum(p**2 for p in parts)) @ weights


def predicted_probes(scene) -> dict:
    """{"t": times, name: drho}: the series with the method's evolution at the scene's probes at every step of the
    window, as a run records them."""
    from solvers.reference.sphere import scene_drho

    steps = np.arange(1, scene.n_steps + 1)
    times = steps[steps * scene.dt >= scene.kind.window[0] - 1e-9] * scene.dt
    probes = {"t": times}
    points = scene.probe_points()
    if not points or not times.size:
        return probes
    values = scene_drho(scene, list(points.values()), times, factor=method_factor(scene, isotropic_symbol))
    for i, name in enumerate(points):
        probes[name] = values[i]
    return probes


def predict_sphere(scene) -> Prediction:
    """The sphere scene's probe errors predicted from the bulk's dispersion with an exact wall (the module), scored
    as a run's; the phase errors along the lattice's axis and its body diagonal."""
    scene = scene.replace(model="linear")
    measures = scene.kind.probe_errors(scene, predicted_probes(scene))
    measures.update(mse=measures.pop("probe_rms"), me=measures.pop("probe_max"))
    axis, diagonal = phase_errors(scene, (1.0, 0.0, 0.0)), phase_errors(scene, (1.0, 1.0, 1.0))
    return scored_prediction(measures, predicted_stable_cfl(scene), scene.t_final, axis, diagonal)
