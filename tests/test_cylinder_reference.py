"""The exact reference of the CAA workshop's pulse scattered by a rigid cylinder (issue 42, its first part):
solvers/reference/cylinder.py, checked against what it must be: the initial field at t = 0 (nothing scattered
yet), the rigid condition dp/dr = 0 on the cylinder, and the free pulse when the radius goes to zero; and the
workshop's geometry's arrival times at its observation points."""

from __future__ import annotations

import math

import numpy as np
import pytest

pytest.importorskip("scipy")
pytestmark = pytest.mark.tier2  # a minute and a half of Bessel sums: .ci/run's second tier (pytest -m tier2)

from solvers.reference.cylinder import CylinderPulse  # noqa: E402

A, B, D = 0.5, 0.2, 4.0  # the workshop's radius, pulse width and pulse centre, m
AMP = 0.05  # rho0 Ma


def workshop(**kw) -> CylinderPulse:
    return CylinderPulse(kw.pop("a", A), B, D, 0.0, AMP, r_max=6.0, **kw)


def test_nothing_is_scattered_at_t_0_and_the_field_is_the_initial_pulse():
    ref = workshop()
    theta = np.linspace(0.0, math.pi, 7)
    r = np.array([0.6, 1.5, 3.9, 4.0, 4.1, 5.0])
    rr, tt = np.meshgrid(r, theta)
    x, y = rr * np.cos(tt), rr * np.sin(tt)
    scattered = ref.scattered(x, y, [0.0])[0]
    assert np.abs(scattered).max() < 1e-8 * AMP
    initial = AMP * np.exp(-math.log(2.0) * ((x - D) ** 2 + y**2) / B**2)
    assert np.abs(ref.drho(x, y, [0.0])[0] - initial).max() < 1e-8 * AMP


def test_the_cylinder_is_rigid_dp_dr_is_zero_on_its_surface():
    """The radial derivative of drho on r = a, by a one-sided difference of the field an h and 2h outside, is
    small beside the same derivative of the free pulse (which has no wall there) once the pulse has hit it."""
    ref = workshop()
    theta = np.linspace(0.0, math.pi, 9)
    h = 1e-4
    t = [3.6, 4.0, 4.5]
    radial = [ref.drho((A + s * h) * np.cos(theta), (A + s * h) * np.sin(theta), t) for s in (0, 1, 2)]
    free = [ref.free((A + s * h) * np.cos(theta), (A + s * h) * np.sin(theta), t) for s in (0, 1, 2)]
    slope = (-3 * radial[0] + 4 * radial[1] - radial[2]) / (2 * h)
    free_slope = (-3 * free[0] + 4 * free[1] - free[2]) / (2 * h)
    assert np.abs(free_slope).max() > 1e-2 * AMP  # the pulse is at the wall: the condition bites
    assert np.abs(slope).max() < 1e-4 * np.abs(free_slope).max(), (np.abs(slope).max(), np.abs(free_slope).max())


def test_a_vanishing_cylinder_scatters_nothing():
    t = [6.0, 8.0]
    x, y = np.array([0.0, -3.0, 2.0]), np.array([5.0, 3.0, -4.0])
    big = np.abs(workshop().scattered(x, y, t)).max()
    small, smaller = (np.abs(workshop(a=a).scattered(x, y, t)).max() for a in (0.02, 0.01))
    assert big > 1e-3 * AMP and small < 1e-2 * big and smaller < 0.5 * small, (big, small, smaller)


def test_the_observation_points_see_the_direct_pulse_then_the_reflection():
    """At the workshop's point A (r = 5 m, 90 degrees) the direct pulse arrives at t ~ sqrt(41) = 6.4 s and the
    one reflected off the cylinder's near side later (the path (4, 0) -> (0.5, 0)-ish -> A is longer); at C (5 m,
    180 degrees, behind the cylinder) the free pulse arrives at t ~ 9 s and the cylinder's shadow lowers it."""
    ref = workshop()
    t = np.linspace(5.0, 10.0, 201)
    a_point = ref.drho(np.array([0.0]), np.array([5.0]), t)[:, 0]
    free_a = ref.free(np.array([0.0]), np.array([5.0]), t)[:, 0]
    assert abs(t[np.argmax(free_a)] - math.sqrt(41.0)) < 0.15  # a 2D pulse's peak runs a little ahead of r / c0
    assert abs(t[np.argmax(a_point)] - t[np.argmax(free_a)]) < 0.05  # the direct pulse first
    reflected = a_point - free_a
    assert t[np.argmax(np.abs(reflected))] > math.sqrt(41.0) + 0.2
    c_point = ref.drho(np.array([-5.0]), np.array([0.0]), t)[:, 0]
    free_c = ref.free(np.array([-5.0]), np.array([0.0]), t)[:, 0]
    # behind the cylinder its shadow lowers the pulse, and diffraction (wavelengths of the body's size) fills it in
    assert 0.5 * np.abs(free_c).max() < np.abs(c_point).max() < 0.95 * np.abs(free_c).max()
