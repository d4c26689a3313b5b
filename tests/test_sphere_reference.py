"""The rigid sphere's exact reference (solvers/reference/sphere.py): the free closed form where the sphere vanishes,
the initial data at t = 0, the wall's Neumann condition at t > 0, and convergence in orders and nodes."""

from __future__ import annotations

import numpy as np
import pytest

from solvers.reference import sphere
from solvers.reference.pulse3d import open_pulse

pytestmark = pytest.mark.tier2  # Bessel sums of some seconds each: .ci/run's second tier (pytest -m tier2)

A, D, B = 0.5, 1.5, 0.4  # the sphere's radius, the pulse's distance and width (the scene)
PROBES = np.array([[0.0, 1.5, 0.0], [-1.0607, 1.0607, 0.0], [-1.5, 0.0, 0.0]])  # A, B, C
WINDOW = np.linspace(1.5, 4.0, 26)  # the probes' window, s


def test_a_vanishing_sphere_leaves_the_free_pulse():
    got = sphere.drho(PROBES, WINDOW, 1e-3, D, B, 1.0)
    free = np.array([open_pulse(np.linalg.norm(PROBES - [D, 0, 0], axis=1), t, B, 1.0)[0] for t in WINDOW]).T
    assert np.abs(got - free).max() < 1e-8 * np.abs(free).max()
    with_body = sphere.drho(PROBES, WINDOW, A, D, B, 1.0)
    assert np.abs(with_body - free).max() > 0.1 * np.abs(free).max()  # the sphere scatters: not the free pulse


def test_at_t0_it_is_the_gaussian_in_the_fluid():
    """To 1e-4 of the amplitude: the data cut at the wall has a spectrum past the Gaussian's k_max (its kink
    there), a ripple of 6e-5 at t = 0 that reaches the probes over their window below 1e-6 of their signal
    (measured with k_max 1.4 times larger: 4e-7, 2e-8, 8e-9 at A, B, C)."""
    points = np.vstack([PROBES, [[1.2, 0.3, 0.0], [1.5, 0.0, 0.4], [1.0, -0.5, 0.2]]])
    got = sphere.drho(points, [0.0], A, D, B, 2.0)[:, 0]
    gaussian = 2.0 * np.exp(-np.log(2.0) * np.sum((points - [D, 0, 0]) ** 2, axis=1) / B**2)
    assert np.abs(got - gaussian).max() < 1e-4 * 2.0


def test_the_wall_is_rigid_at_every_angle():
    """d(drho)/dr = 0 on r = a for t > 0 (one-sided second-order differences, h = 1e-3 m), against the pulse's own
    gradient scale A / b."""
    h = 1e-3
    for theta in (0.0, 1.0, 2.0, 3.0):
        normal = np.array([np.cos(theta), np.sin(theta), 0.0])
        values = sphere.drho(np.array([normal * (A + i * h) for i in range(3)]), [0.5, 1.0, 1.5], A, D, B, 1.0)
        slope = (-3 * values[0] + 4 * values[1] - values[2]) / (2 * h)
        assert np.abs(slope).max() < 1e-4 / B, (theta, slope)


def test_the_probes_converge_in_orders_and_nodes():
    base = sphere.drho(PROBES, WINDOW, A, D, B, 1.0)
    more_orders = sphere.drho(PROBES, WINDOW, A, D, B, 1.0, orders=sphere.orders_needed(A, D, B) + 12)
    more_nodes = sphere.drho(PROBES, WINDOW, A, D, B, 1.0, k_nodes=960, r_nodes=720)
    scale = np.abs(base).max()
    assert np.abs(more_orders - base).max() < 1e-12 * scale
    assert np.abs(more_nodes - base).max() < 1e-10 * scale


def test_the_series_evolved_by_a_given_factor_is_the_exact_one_for_cos():
    """The dispersion prediction's hook (``factor``): cos(c0 k t) gives the exact series, the free pulse by its k
    integral equal to the closed form (2e-14 measured)."""
    exact = sphere.drho(PROBES, WINDOW, A, D, B, 1.0)
    same = sphere.drho(PROBES, WINDOW, A, D, B, 1.0, factor=lambda k, t: np.cos(np.multiply.outer(t, k)))
    assert np.abs(same - exact).max() < 1e-10 * np.abs(exact).max()
    slower = sphere.drho(PROBES, WINDOW, A, D, B, 1.0, factor=lambda k, t: np.cos(0.99 * np.multiply.outer(t, k)))
    assert np.abs(slower - exact).max() > 0.05 * np.abs(exact).max()  # a 1 % slower sound is seen


def test_the_predicted_bulk_error_falls_at_the_fourth_order_kernels_rate():
    """The sphere's prediction (solvers/reference/dispersive_sphere.py): the high-order method's bulk error at the
    probes falls from dx 0.1 to 0.05 at the order of its kernel and step (4 at least), and a smaller step at dx
    0.05 (CFL 0.25) changes it: the step's phase lead is in it."""
    from solvers import Scene
    from solvers.reference.dispersive_sphere import predict_sphere

    high = dict(kernel="laguerre-gauss", h_factor=1.5, cutoff_factor=4.0, correction="gradient", model="linear")
    coarse, fine = (predict_sphere(Scene(dx, "sphere", t_end=4.0, cfl=0.5, **high)) for dx in (0.1, 0.05))
    order = np.log(coarse.predicted_error / fine.predicted_error) / np.log(2.0)
    assert 0 < fine.predicted_error < coarse.predicted_error < 0.5 and order >= 4.0, (coarse, fine, order)
    small_step = predict_sphere(Scene(0.05, "sphere", t_end=4.0, cfl=0.25, **high)).predicted_error
    assert abs(small_step / fine.predicted_error - 1) > 0.05, (small_step, fine.predicted_error)
