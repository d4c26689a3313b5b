"""The cylinder scene's dispersion prediction: the exact series with the method's dispersion and an exact wall.

The series solution (solvers/reference/cylinder.py) evolves each wavenumber k of the pulse's spectrum from rest
by cos(c0 k t). The `linear` SPH sums act on a plane wave of wavenumber k by the lattice symbol D(k)
(solvers/reference/dispersion.py), so in the bulk a run's mode of wavenumber k evolves instead by the
integrator's own step program with c0 |D| in place of c0 k: the kernel's phase lag and the step's phase lead,
exactly. Replacing cos(c0 k t) by that evolution (with |D| averaged over the directions of the lattice, as the
cylinder's modes travel every way) gives what a run would give if its only error were the bulk's dispersion: the
wall exact, the particles off the lattice near it ignored. Against a run it says which part of the error is
the kernel's and the step's (the far field, where it should agree) and which the boundary method's (near the
body, where it cannot). Checked against the lattice's own FFT prediction of the free pulse
(tests/test_cylinder_prediction.py): the direction average moves the predicted error there by 0.03-0.3 %.
"""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np

from solvers.fields import Fields
from solvers.reference.dispersion import (
    Prediction,
    phase_errors,
    predicted_stable_cfl,
    scored_prediction,
    step_matrices,
    symbol,
)

DIRECTIONS = 9  # angles in [0, pi/4] (the lattice's symmetry covers the rest) over which |D(k)| is averaged


def isotropic_symbol(scene, k) -> np.ndarray:
    """|D(k)| averaged over the directions of travel (trapezoid over [0, pi/4]), 1/m, at wavenumbers ``k``."""
    k = np.asarray(k, dtype=np.float64)
    phi = np.linspace(0.0, math.pi / 4.0, DIRECTIONS)
    dx_, dy_ = symbol(scene, np.multiply.outer(k, np.cos(phi)), np.multiply.outer(k, np.sin(phi)))
    magnitude = np.hypot(dx_, dy_)
    weights = np.full(DIRECTIONS, 1.0)
    weights[[0, -1]] = 0.5
    return magnitude @ weights / weights.sum()


def method_factor(scene, magnitude=isotropic_symbol):
    """(k, t) -> array (len(t), len(k)): drho of a standing mode of wavenumber k from rest (drho 1, u 0) after
    the steps that reach each time ``t`` (a multiple of the scene's dt), stepped by the scene's integrator with
    the direction-averaged symbol ``magnitude(scene, k)`` (1/m; the square lattice's by default): the method's
    cos(c0 k t)."""
    dt, integrator = scene.dt, scene.integrator

    def factor(k, t) -> np.ndarray:
        k = np.asarray(k, dtype=np.float64)
        t = np.atleast_1d(np.asarray(t, dtype=np.float64))
        n = np.rint(t / dt).astype(np.int64)
        if np.any(n < 0) or np.any(np.abs(n * dt - t) > 1e-6 * dt + 1e-9 * np.abs(t)):
            raise ValueError(f"the method's evolution is known at multiples of dt = {dt:g} s only")
        d = magnitude(scene, k)
        first = step_matrices(integrator, d, scene.rho0, scene.c0, dt, first=True)
        rest = step_matrices(integrator, d, scene.rho0, scene.c0, dt)
        state = np.zeros((k.size, 4), dtype=complex)
        state[:, 0] = 1.0
        out = np.empty((t.size, k.size))
        done = 0
        for i in np.argsort(n, kind="stable"):
            while done < n[i]:
                state = np.einsum("kij,kj->ki", first if done == 0 else rest, state)
                done += 1
            out[i] = state[:, 0].real
        return out

    return factor


SITE_SPACING_WIDTHS = 0.05  # the predicted field is sampled every ~b/20 (m) of the lattice, at least every site


def site_stride(scene) -> int:
    """Every how many lattice sites (in x and in y) the predicted field is evaluated: the scored domain's whole
    lattice down to a spacing of SITE_SPACING_WIDTHS pulse widths, a quadrature of its RMS measures finer than
    the pulse (dx 0.0025 m has 23 million sites; a run scores at its particles, which it has anyway)."""
    return max(1, int(SITE_SPACING_WIDTHS * scene.pulse_width / scene.dx + 1e-9))


def predicted_probes(scene, method) -> dict:
    """{"t": times, name: drho}: ``method``'s (the series with the method's evolution) drho at the scene's probe
    points at every step of the workshop's window, as a run records them."""
    steps = np.arange(1, scene.n_steps + 1)
    times = steps[steps * scene.dt >= scene.kind.window[0] - 1e-9] * scene.dt
    probes = {"t": times}
    points = scene.probe_points()
    if not points:
        return probes
    px, py = (np.array([p[i] for p in points.values()], dtype=np.float64) for i in (0, 1))
    values = method.drho(px, py, times) if times.size else np.zeros((0, px.size))  # every probe in one series sum
    for i, name in enumerate(points):
        probes[name] = values[:, i]
    return probes


def predicted_fields(scene, method=None):
    """drho the method would give with an exact wall (:class:`solvers.interface.Fields` with ``probes``): at the
    scored domain's lattice sites outside the body (every :func:`site_stride`-th) at the run's final time, and
    at the probes at every step of the workshop's window, for the `linear` model."""

    scene = scene.replace(model="linear")
    kind = scene.kind
    method = method or kind.reference(scene, scene.t_final, factor=method_factor(scene))
    nx, ny = scene.nx - 2 * scene.layer_columns, scene.ny - 2 * scene.layer_rows
    stride = site_stride(scene)
    x, y = (a.reshape(ny, nx)[::stride, ::stride].ravel() for a in kind.lattice_sites(scene))
    keep = kind.fluid(scene, SimpleNamespace(x=x, y=y))
    x, y = x[keep], y[keep]
    drho = method.field(x, y, scene.t_final)
    zero = np.zeros_like(drho)
    return Fields(x=x, y=y, u=zero, v=zero.copy(), drho=drho, t=scene.t_final, probes=predicted_probes(scene, method))


def predict_cylinder(scene, field: bool = True) -> Prediction:
    """The cylinder scene's errors predicted from the bulk's dispersion with an exact wall (the module), scored
    with the scene's own measures (probes, and with ``field`` the near and far field); phase errors along the
    axis and the diagonal. Without ``field`` (advise's search) the probes' measures only, at a cost that hardly
    grows with the lattice."""
    scene = scene.replace(model="linear")
    kind = scene.kind
    if field:
        measures = kind.errors(scene, predicted_fields(scene))
    else:  # the headline as kind.errors gives it where a run recorded the window: the probes'
        method = kind.reference(scene, scene.t_final, factor=method_factor(scene))
        measures = kind.probe_errors(scene, predicted_probes(scene, method))
        measures.update(mse=measures["probe_rms"], me=measures.pop("probe_max"))
    axis, diagonal = phase_errors(scene, 0.0), phase_errors(scene, math.pi / 4)
    return scored_prediction(measures, predicted_stable_cfl(scene), scene.t_final, axis, diagonal)
