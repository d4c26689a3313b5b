"""Exact references of the 2D acoustic pulse (CAA workshop problem) for the linear equations

    d(drho)/dt = -rho0 div u,   du/dt = -(c0^2/rho0) grad drho

in a medium at rest (rho0 kg/m^3, c0 m/s), from u = v = 0 and
drho = rho0 Ma exp(-ln2 r^2/b^2) at t = 0 (r: distance to the centre, m; b: half-width, m).

* `periodic_linear`: the exact solution on a periodic box, sampled on a lattice (spectral in space,
  exact in time), with `PeriodicPulse.at` for points displaced from the lattice sites.
* `open_domain`: the exact solution in the unbounded plane by the Hankel (Bessel) integral.

numpy only: the Bessel functions J0, J1 are computed by the trapezoid rule on their integral
representations (`bessel_j0_j1`).
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

LN2 = float(np.log(2.0))


@lru_cache(maxsize=64)
def gauss_legendre(nodes: int) -> tuple[np.ndarray, np.ndarray]:
    """Gauss-Legendre nodes and weights on [-1, 1] (read-only), kept: the Bessel integrals here ask for the same
    few counts again and again (the cylinder's report section, 297 times). scipy's ``roots_legendre`` (a
    tridiagonal eigenproblem): numpy's ``leggauss`` solves a dense one, O(nodes^3), 0.2 to 1.5 s at 1,500 nodes
    here against 0.05 s, with the same nodes to 1e-16 and weights to 2e-11."""
    from scipy.special import roots_legendre

    z, w = roots_legendre(nodes)
    z.flags.writeable = False
    w.flags.writeable = False
    return z, w


def gaussian_pulse(r2, b: float, mach: float, rho0: float):
    """Initial density perturbation rho0 Ma exp(-ln2 r^2/b^2), kg/m^3, at squared distance ``r2`` (m^2)."""
    return rho0 * mach * np.exp(-LN2 * np.asarray(r2, dtype=np.float64) / b**2)


def _wrap(d, length: float):
    """``d`` (m) mapped to its minimum image in [-length/2, length/2)."""
    return d - length * np.floor(d / length + 0.5)


class PeriodicPulse:
    """Exact linear solution at time ``t`` (s) on the periodic lattice of `periodic_linear`.

    Attributes: ``x`` (nx,), ``y`` (ny,): lattice coordinates, m; ``drho`` (ny, nx), kg/m^3;
    ``u``, ``v`` (ny, nx), m/s (row j = y index); ``t``, s; ``dx``, ``x_lo``, ``y_lo``, m; ``rho0``, ``c0``.
    """

    def __init__(self, nx, ny, dx, x_lo, y_lo, t, rho0, c0, hats, kx, ky):
        self.nx, self.ny, self.dx = int(nx), int(ny), float(dx)
        self.rho0, self.c0 = float(rho0), float(c0)
        self.x_lo, self.y_lo, self.t = float(x_lo), float(y_lo), float(t)
        self.x = self.x_lo + (np.arange(self.nx) + 0.5) * self.dx
        self.y = self.y_lo + (np.arange(self.ny) + 0.5) * self.dx
        self._hats = hats  # Fourier coefficients of (drho, u, v) at t
        self._kx, self._ky = kx, ky  # (1, nx), (ny, 1), rad/m
        self._derivs: dict[tuple[int, int], np.ndarray] = {}
        self.drho, self.u, self.v = self.derivative(0, 0)

    def derivative(self, ax: int, ay: int) -> np.ndarray:
        """d^(ax+ay)/dx^ax dy^ay of (drho, u, v) on the lattice, shape (3, ny, nx), spectrally exact."""
        key = (int(ax), int(ay))
        if key not in self._derivs:
            mult = (1j * self._kx) ** key[0] * (1j * self._ky) ** key[1]
            self._derivs[key] = np.fft.ifft2(self._hats * mult, axes=(-2, -1)).real
        return self._derivs[key]

    def nearest_site(self, x, y):
        """Lattice indices (i, j) of the sites nearest to ``x``, ``y`` (m), periodic wrap included."""
        fi = np.rint((np.asarray(x, dtype=np.float64) - self.x_lo) / self.dx - 0.5).astype(np.int64)
        fj = np.rint((np.asarray(y, dtype=np.float64) - self.y_lo) / self.dx - 0.5).astype(np.int64)
        return fi % self.nx, fj % self.ny

    def at(self, x, y, i=None, j=None, order: int = 2):
        """(drho, u, v) at points ``x``, ``y`` (m, arrays of one shape) near the lattice sites.

        Taylor expansion of order ``order`` (2 by default; up to 6) about lattice site (i, j), with
        spectrally exact derivatives; (i, j) default to the nearest sites. The displacement
        s = (x, y) - site is taken as the minimum image, so positions may lie outside the box.
        The error is about |s|^(order+1) max|grad^(order+1) f| / (order+1)!: for |s| = 0.3 dx = 0.075 m
        and b = 3 m it is ~6e-6 rho0 Ma at order 2 and ~1e-7 at order 3.
        """
        x = np.asarray(x, dtype=np.float64)
        y = np.asarray(y, dtype=np.float64)
        if not 0 <= order <= 6:
            raise ValueError(f"order must be in 0..6 (got {order})")
        if i is None or j is None:
            i, j = self.nearest_site(x, y)
        i = np.asarray(i, dtype=np.int64) % self.nx
        j = np.asarray(j, dtype=np.int64) % self.ny
        sx = _wrap(x - (self.x_lo + (i + 0.5) * self.dx), self.nx * self.dx)
        sy = _wrap(y - (self.y_lo + (j + 0.5) * self.dx), self.ny * self.dx)
        out = np.zeros((3,) + x.shape)
        fact = 1.0
        for n in range(order + 1):  # sum_n (1/n!) sum_a C(n, a) sx^a sy^(n-a) d^n f/dx^a dy^(n-a)
            fact *= max(n, 1)
            binom = 1.0
            for a in range(n + 1):
                d = self.derivative(a, n - a)[:, j, i]
                out += (binom / fact) * sx**a * sy ** (n - a) * d
                binom = binom * (n - a) / (a + 1)
        return out[0], out[1], out[2]

    def energy(self) -> float:
        """Acoustic energy per unit depth, J/m: sum of (0.5 rho0 |u|^2 + 0.5 c0^2 drho^2/rho0) dx^2."""
        e = 0.5 * self.rho0 * (self.u**2 + self.v**2) + 0.5 * self.c0**2 * self.drho**2 / self.rho0
        return float(np.sum(e) * self.dx**2)


def periodic_linear(
    nx: int,
    ny: int,
    dx: float,
    x_lo: float,
    y_lo: float,
    xc: float,
    yc: float,
    b: float,
    mach: float,
    rho0: float,
    c0: float,
    t: float,
    images: tuple = (),
) -> PeriodicPulse:
    """Exact solution of the linear equations at time ``t`` (s) on the periodic box
    [x_lo, x_lo + nx dx) x [y_lo, y_lo + ny dx) (m), sampled at x = x_lo + (i+0.5) dx, y = y_lo + (j+0.5) dx.

    The initial drho is the Gaussian of the minimum-image distance to (xc, yc) (no sum over images):
    periodic, with a kink at distance L/2 of size ~rho0 Ma exp(-ln2 (L/2)^2/b^2) (4e-14 rho0 Ma for
    L = 40 m, b = 3 m). It is sampled on the lattice and every Fourier mode evolves exactly
    (w = c0 |k|): drho_hat(t) = drho_hat(0) cos(w t), u_hat(t) = -i (c0/rho0) (k/|k|) drho_hat(0) sin(w t);
    the k = 0 mode keeps its constant drho and zero velocity. The fields are the real parts of the
    inverse FFT (the imaginary parts only come from the Nyquist modes, which a resolved pulse leaves empty).
    ``images``: x centres (m) of further pulses at the same height, summed with the first at t = 0 (a wall's
    mirror image: the even extension of a walled box is periodic, solvers/scenes/pulse_wall.py).
    Returns a `PeriodicPulse` (drho kg/m^3, u and v m/s, shape (ny, nx), and ``at`` for displaced points).
    """
    x = x_lo + (np.arange(nx) + 0.5) * dx
    y = y_lo + (np.arange(ny) + 0.5) * dx
    ddy = _wrap(y - yc, ny * dx)[:, None]
    sampled = 0.0
    for centre in (xc, *images):
        ddx = _wrap(x - centre, nx * dx)[None, :]
        sampled = sampled + gaussian_pulse(ddx**2 + ddy**2, b, mach, rho0)
    d0 = np.fft.fft2(sampled)
    kx = 2.0 * np.pi * np.fft.fftfreq(nx, dx)[None, :]
    ky = 2.0 * np.pi * np.fft.fftfreq(ny, dx)[:, None]
    kk = np.sqrt(kx**2 + ky**2)
    safe = np.where(kk > 0, kk, 1.0)
    s = np.where(kk > 0, np.sin(c0 * kk * t), 0.0)
    amp = -1j * (c0 / rho0) * d0 * s / safe
    hats = np.stack([d0 * np.cos(c0 * kk * t), amp * kx, amp * ky])
    return PeriodicPulse(nx, ny, dx, x_lo, y_lo, t, rho0, c0, hats, kx, ky)


def bessel_j0_j1(x):
    """Bessel functions (J0(x), J1(x)) by the trapezoid rule on
    J0 = (2/pi) Int_0^(pi/2) cos(x sin tau) dtau,  J1 = (2/pi) Int_0^(pi/2) sin(tau) sin(x sin tau) dtau.

    Both integrands extend to smooth 2 pi-periodic functions, even about tau = 0 and pi/2, so M intervals
    on [0, pi/2] are the 4M-point periodic trapezoid rule, exact up to the aliased terms ~J_4M(x): M adapts
    to max|x| (4M > |x| + 10 |x|^(1/3) + 24), giving ~1e-15 absolute for |x| up to several hundred.
    """
    x = np.asarray(x, dtype=np.float64)
    xmax = float(np.max(np.abs(x))) if x.size else 0.0
    m = int(np.ceil((xmax + 10.0 * np.cbrt(xmax) + 24.0) / 4.0))
    tau = np.linspace(0.0, 0.5 * np.pi, m + 1)
    w = np.full(m + 1, 1.0 / m)
    w[[0, -1]] *= 0.5
    sin_tau = np.sin(tau)
    flat = x.reshape(-1)
    j0 = np.empty(flat.shape)
    j1 = np.empty(flat.shape)
    step = max(1, 1_000_000 // (m + 1))
    for lo in range(0, flat.size, step):
        arg = flat[lo : lo + step, None] * sin_tau[None, :]
        j0[lo : lo + step] = np.cos(arg) @ w
        j1[lo : lo + step] = np.sin(arg) @ (w * sin_tau)
    return j0.reshape(x.shape), j1.reshape(x.shape)


def open_domain(r, t: float, b: float, mach: float, rho0: float, c0: float, nodes: int | None = None):
    """Exact open-domain (unbounded plane) solution (drho kg/m^3, u_r m/s) at radii ``r`` >= 0 (m) and time ``t`` (s):

        drho = rho0 Ma (b^2/(2 ln2)) Int_0^inf exp(-k^2 b^2/(4 ln2)) cos(c0 k t) J0(k r) k dk,
        u_r  =   c0 Ma (b^2/(2 ln2)) Int_0^inf exp(-k^2 b^2/(4 ln2)) sin(c0 k t) J1(k r) k dk,

    from the Hankel transform of the Gaussian (drho_hat(k) = rho0 Ma b^2/(2 ln2) exp(-k^2 b^2/(4 ln2))) and
    du_r/dt = -(c0^2/rho0) d(drho)/dr with dJ0(kr)/dr = -k J1(kr): u_r > 0 (outward) on the leading front.
    The k integral is Gauss-Legendre on [0, k_max] with exp(-k_max^2 b^2/(4 ln2)) = 1e-18; the node count
    (``nodes``, default from the largest phase k_max (c0 t + max r)) gives ~1e-12 relative.
    """
    r = np.asarray(r, dtype=np.float64)
    if np.any(r < 0):
        raise ValueError("radii r must be >= 0")
    r_unique, inverse = np.unique(r, return_inverse=True)  # lattices repeat radii: evaluate each once
    beta = b**2 / (4.0 * LN2)
    k_max = np.sqrt(np.log(1e18) / beta)
    rmax = float(r_unique[-1]) if r.size else 0.0
    if nodes is None:
        nodes = int(np.ceil(0.5 * k_max * (abs(c0 * t) + rmax))) + 32
    z, wz = gauss_legendre(nodes)
    k = 0.5 * k_max * (z + 1.0)
    wk = 0.5 * k_max * wz * np.exp(-beta * k**2) * k * (b**2 / (2.0 * LN2))
    j0, j1 = bessel_j0_j1(r_unique[:, None] * k[None, :])
    drho = rho0 * mach * (j0 @ (wk * np.cos(c0 * k * t)))
    u_r = c0 * mach * (j1 @ (wk * np.sin(c0 * k * t)))
    inverse = inverse.reshape(r.shape)
    return drho[inverse], u_r[inverse]


def lagrange4(table, r, dr: float):
    """``table`` (values at radii 0, dr, 2 dr, ..., extended evenly below 0 by the caller's padding) at radii
    ``r`` (m) by 4-point Lagrange interpolation: error ~ (dr / b)^4 of the pulse's scale."""
    s = np.asarray(r, dtype=np.float64) / dr + 2.0  # two rows of padding below r = 0
    i = np.clip(np.floor(s).astype(np.int64), 1, table.size - 3)
    f = s - i
    w0 = -f * (f - 1.0) * (f - 2.0) / 6.0
    w1 = (f + 1.0) * (f - 1.0) * (f - 2.0) / 2.0
    w2 = -(f + 1.0) * f * (f - 2.0) / 2.0
    w3 = (f + 1.0) * f * (f - 1.0) / 6.0
    return w0 * table[i - 1] + w1 * table[i] + w2 * table[i + 1] + w3 * table[i + 2]


class OpenPulse:
    """The exact linear solution at time ``t`` (s) of the pulse centred at (``xc``, ``yc``) in the open plane
    (the CAA workshop's Bessel integral, :func:`open_domain`), with its images at whole periods along the
    axes that stay periodic (``periods`` (Px, Py), m, 0 where the axis is open): the reference of the 2D pulse
    with open edges. ``x`` (nx,), ``y`` (ny,): the lattice's coordinates (m); ``drho``, ``u``, ``v`` (ny, nx)
    there; :meth:`at` anywhere. The integral is tabulated on radii b/100 apart and interpolated (4 points:
    ~1e-9 of the peak), its images summed while they are within c0 t + 8 b of the lattice (farther ones add
    less than exp(-ln2 64) of the peak)."""

    def __init__(self, x, y, xc, yc, periods, b, mach, rho0, c0, t):
        self.x, self.y = np.asarray(x, dtype=np.float64), np.asarray(y, dtype=np.float64)
        self.t, self.rho0, self.c0 = float(t), float(rho0), float(c0)
        reach = abs(c0 * t) + 8.0 * b
        offsets = []
        for period, lo, hi, c in ((periods[0], self.x[0], self.x[-1], xc), (periods[1], self.y[0], self.y[-1], yc)):
            if period:
                m = int(np.ceil((reach + max(abs(hi - c), abs(lo - c))) / period))
                offsets.append(period * np.arange(-m, m + 1))
            else:
                offsets.append(np.zeros(1))
        near = self._distance_to_box  # an image farther than the reach from every lattice point adds nothing
        self.centres = [(xc + ox, yc + oy) for ox in offsets[0] for oy in offsets[1] if near(xc + ox, yc + oy) <= reach]
        far = max(
            np.hypot(max(abs(self.x[0] - cx), abs(self.x[-1] - cx)), max(abs(self.y[0] - cy), abs(self.y[-1] - cy)))
            for cx, cy in self.centres
        )
        self.dr = b / 100.0
        radii = np.arange(int(np.ceil((far + b) / self.dr)) + 3) * self.dr
        drho, u_r = open_domain(radii, t, b, mach, rho0, c0)
        # two rows below r = 0 by symmetry: drho is even in r, u_r odd
        self._drho = np.concatenate((drho[2:0:-1], drho))
        self._u_r = np.concatenate((-u_r[2:0:-1], u_r))
        gx, gy = np.meshgrid(self.x, self.y)
        self.drho, self.u, self.v = self.at(gx, gy)

    def _distance_to_box(self, cx: float, cy: float) -> float:
        """The distance from (cx, cy) to the lattice's bounding box, m (0 inside)."""
        gx = max(self.x[0] - cx, 0.0, cx - self.x[-1])
        gy = max(self.y[0] - cy, 0.0, cy - self.y[-1])
        return float(np.hypot(gx, gy))

    def at(self, x, y, order: int | None = None):
        """(drho, u, v) at points ``x``, ``y`` (m, arrays of one shape): the sum over the pulse and its images
        (``order`` is accepted for :meth:`PeriodicPulse.at`'s callers: the solution is exact at any point)."""
        x, y = np.asarray(x, dtype=np.float64), np.asarray(y, dtype=np.float64)
        drho, u, v = np.zeros(x.shape), np.zeros(x.shape), np.zeros(x.shape)
        for cx, cy in self.centres:
            px, py = x - cx, y - cy
            r = np.hypot(px, py)
            drho += lagrange4(self._drho, r, self.dr)
            u_r = lagrange4(self._u_r, r, self.dr)
            safe = np.where(r > 0, r, 1.0)
            u += np.where(r > 0, u_r * px / safe, 0.0)
            v += np.where(r > 0, u_r * py / safe, 0.0)
        return drho, u, v
