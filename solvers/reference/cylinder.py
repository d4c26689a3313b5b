"""Exact linear reference of the CAA workshop's pulse scattered by a rigid circular cylinder (Second CAA Workshop,
category 1, problem 2: Tam and Hardin, eds., NASA CP-3352, 1997; its exact solution by Kurbatskii there).

The linear acoustic equations in a medium at rest (rho0, c0) with p = c0^2 drho:

    d(drho)/dt = -rho0 div u,   du/dt = -(c0^2 / rho0) grad drho,   u . n = 0 on r = a,

from u = 0 and drho = A exp(-ln2 ((x - d)^2 + y^2) / b^2) (A = rho0 Ma) at t = 0: a Gaussian pulse centred
at distance ``d`` from the axis of a cylinder of radius ``a``. Then p obeys the wave equation with
dp/dt = 0 at t = 0 and dp/dr = 0 on the cylinder.

**Method** (written here; ColESo's ``es_cylinder`` is an open implementation of the same problem). In polar
coordinates about the cylinder's axis, theta from the pulse's direction, the initial field is a cosine series,
exp(beta cos theta) = sum_n eps_n I_n(beta) cos(n theta) (eps_0 = 1, eps_n = 2), so that

    drho_0 = sum_n eps_n f_n(r) cos(n theta),  f_n(r) = A exp(-ln2 (r - d)^2 / b^2) ive_n(2 ln2 r d / b^2)

(ive the exponentially scaled modified Bessel function). Each angular order evolves by the Weber transform of
the exterior Neumann problem, whose radial eigenfunctions are C_n(k r) = J_n(k r) Y_n'(k a) - Y_n(k r) J_n'(k a):

    drho_n(r, t) = int_0^inf F_n(k) C_n(k r) cos(c0 k t) k dk / (J_n'(k a)^2 + Y_n'(k a)^2),
    F_n(k) = int_a^inf f_n(r) C_n(k r) r dr.

Subtracting the free-space mode (the Hankel transform, G_n(k) = int f_n J_n(k r) r dr: the pulse without the
cylinder, :func:`solvers.reference.pulse2d.open_domain`), the scattered part of each order is

    s_n(r, t) = -int_0^inf J_n'(k a) [G_n (J_n J_n'(k a) + Y_n Y_n'(k a)) + H_n (J_n Y_n'(k a) - Y_n J_n'(k a))]
                 cos(c0 k t) k dk / (J_n'(k a)^2 + Y_n'(k a)^2),   H_n(k) = int f_n Y_n(k r) r dr,

with J_n = J_n(k r), Y_n = Y_n(k r) (f_n vanishes inside the cylinder to round-off: the pulse is many widths
away). J_n'(k a) makes s_n negligible once n exceeds the largest k a by a margin, so the scattered field needs
a few tens of orders while the free part is the Bessel integral. The k integrals are Gauss-Legendre on
[0, k_max] with exp(-k_max^2 b^2 / (4 ln2)) = 1e-16 (the pulse's spectrum), the r integrals on the pulse's
support (8 widths either side of d). Needs scipy (Bessel functions of integer order).
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from solvers.reference.pulse2d import gauss_legendre

LN2 = math.log(2.0)
SPECTRUM_FLOOR = 1e-16  # exp(-k_max^2 b^2 / (4 ln2)): where the pulse's spectrum ends
FIELD_CHUNK = 1 << 20  # points a whole field is evaluated at in one piece
SUPPORT_WIDTHS = 8.0  # the pulse's radial support either side of d, in widths (exp(-ln2 64) = 5e-20)


def _special():
    try:
        from scipy import special
    except ImportError as exc:  # pragma: no cover - scipy is a dependency
        raise ImportError("the cylinder's exact reference needs scipy (pip install scipy)") from exc
    return special


@lru_cache(maxsize=8)
def _spectrum(a: float, d: float, b: float, orders: int, k_nodes: int, r_nodes: int):
    """The k nodes and weights (with k), and per order n < ``orders``: the coefficients of J_n(k r) and Y_n(k r)
    in the scattered part, arrays (orders, k_nodes), for a unit amplitude."""
    sp = _special()
    k_max = math.sqrt(-math.log(SPECTRUM_FLOOR) * 4.0 * LN2) / b
    z, w = gauss_legendre(k_nodes)
    k = 0.5 * k_max * (z + 1.0)
    wk = 0.5 * k_max * w * k
    lo, hi = max(d - SUPPORT_WIDTHS * b, a), d + SUPPORT_WIDTHS * b
    zr, wr = gauss_legendre(r_nodes)
    r = 0.5 * (hi - lo) * (zr + 1.0) + lo
    wr = 0.5 * (hi - lo) * wr * r
    beta = 2.0 * LN2 * r * d / b**2
    gauss = np.exp(-LN2 * (r - d) ** 2 / b**2)
    kr = k[:, None] * r[None, :]
    coef_j = np.empty((orders, k_nodes))
    coef_y = np.empty((orders, k_nodes))
    for n, (jn, yn) in enumerate(bessel_orders(orders, kr)):
        f = gauss * sp.ive(n, beta) * wr  # f_n(r) r dr
        with np.errstate(over="ignore", invalid="ignore"):
            g = jn @ f  # G_n(k)
            h = yn @ f  # H_n(k): -inf where Y_n(k r) overflows (k r << n), see below
            jp, yp = sp.jvp(n, k * a), sp.yvp(n, k * a)
            # s_n = -int jp [G (J jp + Y yp) + H (J yp - Y jp)] / (jp^2 + yp^2) cos(c k t) k dk, in the ratio of the
            # smaller derivative to the larger one so that nothing overflows: q = jp / yp (or p = yp / jp)
            big_y = np.abs(yp) >= np.abs(jp)
            q = np.where(big_y, jp / np.where(big_y, yp, 1.0), 0.0)
            p = np.where(big_y, 0.0, yp / np.where(big_y, 1.0, jp))
            cj = np.where(big_y, q * (g * q + h) / (1 + q * q), (g + h * p) / (1 + p * p))
            cy = np.where(big_y, q * (g - h * q) / (1 + q * q), (g * p - h) / (1 + p * p))
        # where Y_n(k r) overflows the true terms vanish (q ~ (k a)^(2n) against Y_n ~ (k r)^(-n), a < r): 0
        eps = 2.0 if n else 1.0
        coef_j[n] = -eps * np.nan_to_num(cj, nan=0.0, posinf=0.0, neginf=0.0)
        coef_y[n] = -eps * np.nan_to_num(cy, nan=0.0, posinf=0.0, neginf=0.0)
    return k, wk, coef_j, coef_y


def _miller(orders: int, x) -> np.ndarray:
    """J_n(x) for n < ``orders`` at ``x`` > 0 (1D), shape (orders, x.size): Miller's backward recurrence from an
    order well past both ``orders`` and x, normalised by 1 = J_0 + 2 sum J_2k, rescaled as it grows."""
    top = int(max(orders, x.max(initial=0.0)) + 30 + 4 * x.max(initial=0.0) ** (1 / 3))
    out = np.empty((orders, x.size))
    above, here = np.zeros_like(x), np.full_like(x, 1e-300)
    total = np.zeros_like(x)
    two_over_x = 2.0 / x
    for n in range(top, 0, -1):  # here = J_n (unnormalised), above = J_{n+1}
        if n < orders:
            out[n] = here
        if n % 2 == 0:
            total += 2.0 * here
        above, here = here, n * two_over_x * here - above
        big = np.abs(here) > 1e250
        if big.any():
            scale = np.where(big, 1e-250, 1.0)
            above, here, total = above * scale, here * scale, total * scale
            out[min(n, orders) :] *= scale  # the orders stored so far
    out[0] = here
    total += here
    return out / total


def bessel_orders(orders: int, x):
    """(J_n(x), Y_n(x)) for n = 0 .. ``orders`` - 1, in turn, at ``x`` > 0 (any shape): Y by the forward
    recurrence C_{n+1} = (2n / x) C_n - C_{n-1} from the zeroth and first orders (stable), J by it where
    x > n + 8 and by Miller's backward recurrence where not; Y_n is -inf where it overflows (x << n), as
    scipy's."""
    sp = _special()
    x = np.asarray(x, dtype=np.float64)
    with np.errstate(divide="ignore"):
        two_over_x = 2.0 / x
    slow = x < orders + 8.0
    low = _miller(orders, x[slow]) if slow.any() else None
    j_prev, j = sp.j0(x), sp.j1(x)
    y_prev, y = sp.y0(x), sp.y1(x)
    for n in range(orders):
        j_n = j_prev.copy()
        if low is not None:
            j_n[slow] = low[n]
        yield j_n, y_prev
        with np.errstate(over="ignore", invalid="ignore"):
            j_prev, j = j, (n + 1) * two_over_x * j - j_prev
            y_next = (n + 1) * two_over_x * y - y_prev
            y_prev, y = y, np.where(np.isfinite(y), y_next, -np.inf)


def scattered_orders(a: float, b: float, d: float) -> int:
    """Angular orders the scattered part needs: past the largest k a by a margin (J_n'(k a) falls off as
    (e k a / 2n)^n beyond it), at least 16."""
    k_max = math.sqrt(-math.log(SPECTRUM_FLOOR) * 4.0 * LN2) / b
    return max(16, int(math.ceil(1.3 * k_max * a + 12)))


class CylinderPulse:
    """The exact linear solution (drho, kg/m^3) of the pulse of amplitude ``amplitude`` = rho0 Ma and width ``b``
    (m) centred at (``xc``, ``yc``) scattered by a rigid cylinder of radius ``a`` (m) centred at (``x0``, ``y0``),
    c0 m/s: :meth:`drho` at points and times, the free pulse plus the scattered field (module docstring), for
    times up to ``t_max`` (s) and distances from the axis up to ``r_max`` (m), which size the k quadrature.

    ``factor`` (k, t) -> array (len(t), len(k)) is how each wavenumber k (1/m) evolves from rest: cos(c0 k t) for
    the wave equation (default); a method's own (solvers/reference/dispersive_cylinder.py) gives the same series
    in a dispersive medium with an exact wall."""

    def __init__(
        self,
        a,
        b,
        xc,
        yc,
        amplitude,
        c0=1.0,
        x0=0.0,
        y0=0.0,
        t_max=10.0,
        r_max=10.0,
        r_nodes=160,
        orders=None,
        factor=None,
    ):
        self.a, self.b, self.amplitude, self.c0 = float(a), float(b), float(amplitude), float(c0)
        self.factor = factor or self.wave_factor
        self.x0, self.y0, self.xc, self.yc = float(x0), float(y0), float(xc), float(yc)
        self.d = math.hypot(self.xc - self.x0, self.yc - self.y0)
        self.phase = math.atan2(self.yc - self.y0, self.xc - self.x0)  # the pulse's direction from the axis
        self.orders = orders or scattered_orders(self.a, self.b, self.d)
        self.t_max, self.r_max, self.r_nodes = float(t_max), float(r_max), int(r_nodes)
        k_max = math.sqrt(-math.log(SPECTRUM_FLOOR) * 4.0 * LN2) / self.b
        # Gauss-Legendre nodes for the k integral up to the phase k_max (c0 t + r + d): a few per oscillation
        self.k_nodes = int(math.ceil(0.6 * k_max * (self.c0 * self.t_max + self.r_max + self.d))) + 64

    def wave_factor(self, k, t) -> np.ndarray:
        """cos(c0 k t), shape (len(t), len(k)): the wave equation's evolution of a standing mode from rest."""
        return np.cos(self.c0 * np.outer(np.atleast_1d(t), k))

    def polar(self, x, y):
        """(r, theta) of points about the cylinder's axis, theta from the pulse's direction."""
        px, py = np.asarray(x, float) - self.x0, np.asarray(y, float) - self.y0
        return np.hypot(px, py), np.arctan2(py, px) - self.phase

    def scattered(self, x, y, t) -> np.ndarray:
        """The scattered part of drho at points ``x``, ``y`` (m, one shape) and times ``t`` (s, 1D): shape
        (len(t), *x.shape). Points inside the cylinder get NaN."""
        t = np.atleast_1d(np.asarray(t, float))
        r, theta = self.polar(x, y)
        shape = r.shape
        r, theta = r.ravel(), theta.ravel()
        if np.max(np.abs(t), initial=0.0) > self.t_max * (1 + 1e-12) or r.max(initial=0.0) > self.r_max:
            raise ValueError(f"the reference is built for t <= {self.t_max:g} s and r <= {self.r_max:g} m")
        k, wk, cj, cy = _spectrum(self.a, self.d, self.b, self.orders, self.k_nodes, self.r_nodes)
        kr = np.outer(r, k)  # (points, k)
        angular = np.zeros_like(kr)  # sum over the orders of each radial function times cos(n theta), per k
        for n, (j_n, y_n) in enumerate(bessel_orders(self.orders, kr)):  # every order by recurrence, not one by one
            with np.errstate(over="ignore", invalid="ignore"):
                radial = j_n * cj[n] + y_n * cy[n]
            radial = np.nan_to_num(radial, nan=0.0, posinf=0.0, neginf=0.0)  # Y_n overflowing where cy[n] is 0
            angular += radial * np.cos(n * theta)[:, None]
        out = (self.factor(k, t) * wk) @ angular.T  # (t, points): the time integral once, not once per order
        out *= self.amplitude
        out[:, r < self.a] = np.nan
        return out.reshape((t.size, *shape))

    def free(self, x, y, t) -> np.ndarray:
        """The pulse without the cylinder (the open plane's Bessel integral), shape (len(t), *x.shape)."""
        t = np.atleast_1d(np.asarray(t, float))
        x, y = np.asarray(x, float), np.asarray(y, float)
        rr = np.hypot(x - self.xc, y - self.yc)
        return self.free_radial(rr.ravel(), t).reshape((t.size, *rr.shape))

    def free_radial(self, radii, t) -> np.ndarray:
        """The free pulse's drho at distances ``radii`` (m, 1D) from its centre at ``t`` (s; one time, or 1D: then
        shape (len(t), len(radii))): the Bessel integral of solvers.reference.pulse2d.open_domain with the
        evolution ``factor``, by scipy's J0 (fast for many radii)."""
        sp = _special()
        beta = self.b**2 / (4.0 * LN2)
        k_max = math.sqrt(math.log(1e18) / beta)
        radii = np.asarray(radii, dtype=np.float64)
        times = np.atleast_1d(np.asarray(t, float))
        reach = np.max(np.abs(self.c0 * times), initial=0.0) + radii.max(initial=0.0)
        nodes = int(math.ceil(0.5 * k_max * reach)) + 32
        z, wz = gauss_legendre(nodes)
        k = 0.5 * k_max * (z + 1.0)
        wk = 0.5 * k_max * wz * np.exp(-beta * k**2) * k * (self.b**2 / (2.0 * LN2))
        out = self.amplitude * ((self.factor(k, times) * wk) @ sp.j0(np.outer(radii, k)).T)
        return out if np.ndim(t) else out[0]

    def drho(self, x, y, t) -> np.ndarray:
        """drho (kg/m^3) at points ``x``, ``y`` and times ``t``: the free pulse plus the scattered field."""
        return self.free(x, y, t) + self.scattered(x, y, t)

    def field(self, x, y, t: float, dr: float | None = None) -> np.ndarray:
        """drho (kg/m^3) at many points ``x``, ``y`` (m, one shape) at one time ``t`` (s): each angular order's
        radial function and the free pulse tabulated on radii ``dr`` apart (default b / 25) and interpolated
        by 4-point Lagrange (about 1e-6 of the peak); points inside the cylinder get NaN. The same values as
        :meth:`drho`, at a cost that does not grow with the points' count."""
        from solvers.reference.pulse2d import lagrange4

        x, y = np.asarray(x, float), np.asarray(y, float)
        if x.size > FIELD_CHUNK:  # in pieces: each order's interpolation holds a few arrays of the points' size
            flat_x, flat_y = x.ravel(), y.ravel()
            parts = [
                self.field(flat_x[lo : lo + FIELD_CHUNK], flat_y[lo : lo + FIELD_CHUNK], t, dr)
                for lo in range(0, flat_x.size, FIELD_CHUNK)
            ]
            return np.concatenate(parts).reshape(x.shape)
        dr = float(dr or self.b / 25.0)
        r, theta = self.polar(x, y)
        shape = r.shape
        r, theta = r.ravel(), theta.ravel()
        if abs(t) > self.t_max * (1 + 1e-12) or r.max(initial=0.0) > self.r_max:
            raise ValueError(f"the reference is built for t <= {self.t_max:g} s and r <= {self.r_max:g} m")
        k, wk, cj, cy = _spectrum(self.a, self.d, self.b, self.orders, self.k_nodes, self.r_nodes)
        nodes = self.a + dr * np.arange(int(math.ceil((self.r_max - self.a) / dr)) + 4)
        ckt = self.factor(k, [t])[0] * wk
        kr = np.outer(nodes, k)
        s = (r - self.a) / dr
        i = np.clip(np.floor(s).astype(np.int64), 1, nodes.size - 3)
        f = s - i
        weights = (
            -f * (f - 1.0) * (f - 2.0) / 6.0,
            (f + 1.0) * (f - 1.0) * (f - 2.0) / 2.0,
            -(f + 1.0) * f * (f - 2.0) / 2.0,
            (f + 1.0) * f * (f - 1.0) / 6.0,
        )
        out = np.zeros(r.size)
        for n, (jn, yn) in enumerate(bessel_orders(self.orders, kr)):
            with np.errstate(over="ignore", invalid="ignore"):
                radial = jn * cj[n] + yn * cy[n]
            table = np.nan_to_num(radial, nan=0.0, posinf=0.0, neginf=0.0) @ ckt
            value = sum(w * table[i + j - 1] for j, w in enumerate(weights))
            out += value * np.cos(n * theta)
        out *= self.amplitude
        # the free pulse, radial about its own centre: tabulated from r = 0 (two rows of even padding below)
        rr = np.hypot(np.asarray(x, float).ravel() - self.xc, np.asarray(y, float).ravel() - self.yc)
        step = self.b / 100.0
        radii = np.arange(int(math.ceil(rr.max(initial=0.0) / step)) + 4) * step
        free = self.free_radial(radii, t)
        out += lagrange4(np.concatenate((free[2:0:-1], free)), rr, step)
        out[r < self.a] = np.nan
        return out.reshape(shape)
