"""The error of a run predicted from the discrete operator's dispersion relation, with no simulation.

On the square lattice the SPH sums of the `linear` model act on a plane wave
exp(i k.x) as i D(k), with

    D(k) = -sum_j V sin(k.x_ij) x_ij G(r_ij)        (V = dx^2, G = W'(r)/r, r_ij < cutoff)

over the lattice neighbours: d(drho)/dt = -i rho0 D.u and du/dt = -i (c0^2/rho0) D drho.
D(k) -> k as k dx -> 0; its departure from k is the lattice's phase error
(the truncated or smoothed kernel gives a phase speed c0 |D|/|k| below c0).
Each wavenumber then evolves by the integrator's own step program
(solvers/physics/integrators.py) run on one complex amplitude per wavenumber
(:class:`ModeSolver`), so the leapfrog's phase lead and any growth come out of
the same code the solvers run. The pulse's lattice spectrum (an FFT of the
sampled initial fields) evolved to t and transformed back gives u on the
lattice, scored exactly as a run is (solvers/reference/analytic.py). This is exact
linear algebra of the same discrete operator on an unbounded lattice: for
`linear` it matches a run up to the pulse's contact with the domain's ends.
For `fixed` and `lagrangian` it is their linear part only.

The largest |D(k)| over the Brillouin zone bounds the step: a mode is stable
while the integrator's amplification over one step has spectral radius <= 1,
which depends only on z = c0 |D| dt; :func:`predicted_stable_cfl` turns the largest
stable z into the largest stable CFL = dt c0 / dx.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from solvers.fields import Fields
from solvers.physics.integrators import step_program

STABLE_GROWTH = 1e-9  # spectral radius above 1 + this is unstable
Z_SCAN = np.linspace(1e-3, 8.0, 8000)  # c0 |D| dt: where stability is looked for


def lattice_offsets(scene) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(a, b, G): the lattice neighbours' offsets in units of dx (x_ij = (a, b) dx) within the cutoff,
    and G(r) of the scene's kernel at each, 1/m^4. The particle itself is left out."""
    reach = int(math.ceil(scene.cutoff / scene.dx))
    a, b = np.meshgrid(np.arange(-reach, reach + 1), np.arange(-reach, reach + 1), indexing="ij")
    r = np.hypot(a, b) * scene.dx
    keep = (r < scene.cutoff) & (r > 0)
    return a[keep].astype(float), b[keep].astype(float), scene.sph_kernel.gradient(r[keep], scene.h)


SYMBOL_CHUNK = 1 << 21  # wavenumbers x neighbours evaluated at once (16 MiB of phases)


def symbol(scene, kx, ky=0.0) -> tuple[np.ndarray, np.ndarray]:
    """(D_x, D_y) at wavenumbers (kx, ky), 1/m (arrays broadcast together), in chunks of wavenumbers."""
    a, b, g = lattice_offsets(scene)
    kx, ky = np.broadcast_arrays(np.asarray(kx, float), np.asarray(ky, float))
    shape, kx, ky = kx.shape, kx.ravel(), ky.ravel()
    out_x, out_y = np.empty(kx.size), np.empty(kx.size)
    step = max(1, SYMBOL_CHUNK // max(a.size, 1))
    for lo in range(0, kx.size, step):
        part = slice(lo, lo + step)
        phase = np.multiply.outer(kx[part], a * scene.dx) + np.multiply.outer(ky[part], b * scene.dx)
        weight = -(scene.dx**2) * np.sin(phase) * g
        out_x[part], out_y[part] = weight @ (a * scene.dx), weight @ (b * scene.dx)
    scale = scene.sph_correction.lattice_factor(scene)  # a correction's factor in the lattice's interior
    return scale * out_x.reshape(shape), scale * out_y.reshape(shape)


def largest_symbol(scene, points: int = 161) -> float:
    """max |D(k)| over the Brillouin zone [0, pi/dx]^2 (the lattice's symmetry covers the rest), 1/m."""
    k = np.linspace(0.0, math.pi / scene.dx, points)
    kx, ky = np.meshgrid(k, k, indexing="ij")
    dx_, dy_ = symbol(scene, kx.ravel(), ky.ravel())
    return float(np.sqrt(dx_**2 + dy_**2).max())


class ModeSolver:
    """The solver primitives on one complex amplitude per wavenumber (linear model, waves along x).

    Enough of the solver interface for :func:`step_program`: ``drho`` and ``u`` are the modes' amplitudes,
    ``ax`` and ``dd`` their rates, ``d`` the symbol D_x(k) (1/m) of each mode.
    """

    def __init__(self, d, drho, u, rho0: float, c0: float, dt: float):
        self.d, self.rho0, self.c0, self.dt = np.asarray(d, float), rho0, c0, dt
        self.drho, self.u = np.array(drho, complex), np.array(u, complex)
        self.ax, self.dd = np.zeros_like(self.u), np.zeros_like(self.u)
        self.saved, self.t = {}, 0.0

    def snp(self) -> None:
        """Particles on the lattice: nothing to search."""

    def rates(self, continuity: bool, momentum: bool) -> None:
        if continuity:
            self.dd = -1j * self.rho0 * self.d * self.u
        if momentum:
            self.ax = -1j * (self.c0**2 / self.rho0) * self.d * self.drho

    def kick(self, f: float) -> None:
        self.u = self.u + f * self.dt * self.ax

    def advance(self, f: float) -> None:
        self.drho = self.drho + f * self.dt * self.dd
        self.t += f * self.dt

    def save(self) -> None:
        self.saved = {"u": self.u.copy(), "drho": self.drho.copy(), "t": self.t}

    def restore(self, names) -> None:
        if "u" in names:
            self.u = self.saved["u"].copy()
        if "drho" in names:
            self.drho, self.t = self.saved["drho"].copy(), self.saved["t"]

    def accumulate(self, weight: float, first: bool = False) -> None:
        """A Runge-Kutta stage's rates, weighted, into the step's sums (solvers/interface.py)."""
        if first:
            self.sums = {"dd": 0.0, "ax": 0.0}
        self.sums = {"dd": self.sums["dd"] + weight * self.dd, "ax": self.sums["ax"] + weight * self.ax}

    def use_sum(self) -> None:
        self.dd, self.ax = self.sums["dd"], self.sums["ax"]

    def state(self) -> np.ndarray:
        return np.stack([self.drho, self.u, self.ax, self.dd])

    def set_state(self, s) -> None:
        self.drho, self.u, self.ax, self.dd = (np.array(row, complex) for row in s)


def step_matrices(integrator: str, d, rho0: float, c0: float, dt: float, first: bool = False) -> np.ndarray:
    """One step of ``integrator``'s program as a matrix per mode, (len(d), 4, 4), acting on (drho, u, ax, dd):
    the program run on the four basis states (the step is linear)."""
    d = np.asarray(d, float)
    solver = ModeSolver(d, np.zeros_like(d), np.zeros_like(d), rho0, c0, dt)
    columns = []
    for e in np.eye(4):
        solver.set_state(np.multiply.outer(e, np.ones_like(d)))
        for _stage, op in step_program(integrator, solver, first=first):
            op()
        columns.append(solver.state())
    return np.moveaxis(np.stack(columns, axis=1), -1, 0)  # column j: the step of basis state e_j


def evolve(solver: ModeSolver, integrator: str, steps: int) -> ModeSolver:
    """``steps`` steps of ``integrator``'s program, the first one primed as a run's is: the first step's
    matrix, then the power of the others' (so the cost does not grow with the number of steps)."""
    first = step_matrices(integrator, solver.d, solver.rho0, solver.c0, solver.dt, first=True)
    rest = np.linalg.matrix_power(step_matrices(integrator, solver.d, solver.rho0, solver.c0, solver.dt), steps - 1)
    state = np.einsum("nij,njk,kn->in", rest, first, solver.state())
    solver.set_state(state)
    solver.t += steps * solver.dt
    return solver


def unbounded(scene) -> tuple:
    """(closed, columns, rows): for a scene with open edges, the closed scene whose periodic lattice holds its
    domain with room on each open axis, so that no periodic image of the pulse comes within c0 t + 8 pulse
    widths of the domain by the run's end (the open plane's answer, which a perfect absorber gives), and the
    slices of its lattice's columns and rows that are the scene's scored domain; a closed scene, itself."""
    if not scene.open:
        return scene, slice(None), slice(None)
    reach = scene.c0 * scene.t_final + 8.0 * scene.pulse_width
    changes, cut = {"open": "", "layer_width": None, "absorber_strength": None}, [slice(None), slice(None)]
    centre = (scene.pulse_center, 0.5 * (scene.y_min + scene.y_max))
    for i, (axis, lo, hi) in enumerate((("x", scene.x_min, scene.x_max), ("y", scene.y_min, scene.y_max))):
        if axis in scene.open:
            far = max(hi - centre[i], centre[i] - lo)
            pad = max(math.ceil((reach + far - (hi - lo)) / (2.0 * scene.dx)), 0)
            changes.update({f"{axis}_min": lo - pad * scene.dx, f"{axis}_max": hi + pad * scene.dx})
            n = int(round((hi - lo) / scene.dx))
            cut[i] = slice(pad, pad + n)
    return scene.replace(**changes), cut[0], cut[1]


def predicted_velocity(scene) -> tuple[np.ndarray, np.ndarray, float]:
    """(x, u, t): u on one lattice row at the run's final time, predicted mode by mode from the scene kind's
    initial row (with walls, on its mirror extension: solvers/scenes/base.py; with open edges, on the
    :func:`unbounded` lattice, cut to the scored domain)."""
    if scene.open:
        closed, columns, _ = unbounded(scene)
        x, u, t = predicted_velocity(closed)
        return x[columns], u[columns], t
    x = scene.x_lo + (np.arange(scene.nx) + 0.5) * scene.dx
    u0, v0, drho0 = scene.kind.initial_fields(scene, x, np.zeros_like(x), np)
    u0, _, drho0, keep = scene.kind.mirror_extension(scene, u0, v0, drho0)
    k = 2.0 * math.pi * np.fft.fftfreq(u0.size, d=scene.dx)
    d, _ = symbol(scene, k)
    modes = ModeSolver(d, np.fft.fft(drho0), np.fft.fft(u0), scene.rho0, scene.c0, scene.dt)
    evolve(modes, scene.integrator, scene.n_steps)
    return x, np.fft.ifft(modes.u).real[keep], modes.t


def predicted_primary(scene, fields) -> np.ndarray:
    """The `linear` prediction of the scene's primary field at a run's lattice sites (``fields``: its output,
    the scored domain row by row): u of a plane scene, drho of a 2D one (on the :func:`unbounded` lattice where
    edges are open)."""
    if scene.kind.primary == "u" and scene.kind.strip:
        x, u, _ = predicted_velocity(scene)
        return np.interp(np.asarray(fields.x, float), x, u)
    return predicted_fields_2d(scene.replace(model="linear"))[2].ravel()


def amplification_radius(integrator: str, z) -> np.ndarray:
    """Spectral radius of one step (after the first) of ``integrator`` for c0 |D| dt = z (rho0 = c0 = dt = 1)."""
    return np.abs(np.linalg.eigvals(step_matrices(integrator, z, 1.0, 1.0, 1.0))).max(axis=1)


def largest_stable_z(integrator: str) -> float:
    """The largest c0 |D| dt up to which one step never grows (0 where it grows at any step: euler, kdk1,
    and rk2, whose growth 1 + z^4/8 per step is slow but never 1)."""
    if amplification_radius(integrator, [0.1])[0] > 1.0 + 1e-13:
        return 0.0
    unstable = amplification_radius(integrator, Z_SCAN) > 1.0 + STABLE_GROWTH
    return float(Z_SCAN[np.argmax(unstable)]) if unstable.any() else float(Z_SCAN[-1])


def predicted_stable_cfl(scene) -> float:
    """The largest stable CFL (dt c0 / dx) on the periodic lattice for the scene's (or a
    :class:`~solvers.method.Method`'s) kernel, h/dx, cutoff, integrator and correction (it does not depend on dx: D
    scales as 1/dx at fixed h/dx). The harness's stable CFL of a run (pcabench/predict/stability.py ``stable_cfl``)
    is this, or the lower limit long runs of its scene measured."""
    from solvers.scene import Scene

    # a 3D scene's: the cubic lattice's
    own = scene.kind.predicted_stable_cfl(scene) if hasattr(scene, "kind") else None
    if own is not None:
        return own
    cut = getattr(scene, "cutoff_factor", None)
    cut = Scene.default("cutoff_factor") if cut is None else cut  # a compact kernel's: its support, whatever this
    return lattice_stable_cfl(scene.kernel, float(scene.h_factor), float(cut), scene.integrator, scene.correction)


def unit_scene(**method):
    """The paper's scene at dx = 1 m with ``method``'s fields (kernel, h_factor, cutoff_factor, integrator, cfl)
    in a square wide enough for 3 cutoffs of any support: what depends on h/dx only (D dx, the stable CFL) is
    computed on it."""
    from solvers.scene import Scene

    reach = method.get("h_factor", 3.0) * max(method.get("cutoff_factor", 3.0), 2.0)
    half = 20.0 + 4.0 * reach  # m
    return Scene(dx=1.0, x_min=-half, x_max=half, y_min=-half, y_max=half, model="linear", **method)


@lru_cache(maxsize=1024)
def lattice_stable_cfl(
    kernel: str, h_factor: float, cutoff_factor: float, integrator: str, correction: str = "none"
) -> float:
    """:func:`predicted_stable_cfl` of one method, by its fields (cached: the same at every dx)."""
    unit = unit_scene(
        kernel=kernel, h_factor=h_factor, cutoff_factor=cutoff_factor, integrator=integrator, correction=correction
    )
    return largest_stable_z(integrator) / (unit.dx * largest_symbol(unit))


@dataclass(frozen=True)
class Prediction:
    """The predicted relative RMS error of the scene's primary field at the run's final time and the largest
    stable CFL."""

    predicted_error: float
    predicted_me: float
    stable_cfl: float
    t_end: float
    lattice_phase_error: float  # c0 D(k)/k - 1 at the pulse's wavenumber k = 1 / pulse width: the lattice's lag
    step_phase_error: float  # the same with the integrator's step: phase speed / c0 - 1 (lag + the step's lead)
    # along the lattice's diagonal (2D scenes; the two above are along its axis)
    lattice_phase_error_diagonal: float | None = None
    step_phase_error_diagonal: float | None = None
    measures: dict | None = None  # the scene's other error measures, predicted (2D scenes)

    def as_dict(self) -> dict:
        return dict(self.__dict__)


def predict(scene) -> Prediction:
    """The error of the scene's run predicted from the dispersion relation (linear part; see the module), by
    the scene kind's own prediction (solvers/scenes/). For a scene with open edges the prediction's lattice is
    unbounded (:func:`unbounded`): it is what a perfect absorber would give (its layer is not modelled)."""
    return scene.kind.predict(scene)


def predict_plane(scene) -> Prediction:
    """A plane scene's prediction: the lattice row's spectrum evolved mode by mode (waves along x), scored with
    the scene kind's own measures."""

    x, u, t = predicted_velocity(scene)
    zero = np.zeros_like(x)
    measures = scene.kind.errors(scene, Fields(x=x, y=zero, u=u, v=zero, drho=zero, t=t))
    k = 1.0 / scene.pulse_width
    d = float(symbol(scene, np.array([k]))[0][0])
    return Prediction(
        predicted_error=measures.pop("mse"),
        predicted_me=measures.pop("me"),
        stable_cfl=predicted_stable_cfl(scene),
        t_end=t,
        lattice_phase_error=d / k - 1.0,
        step_phase_error=step_phase_angle(scene.integrator, scene.c0 * d * scene.dt) / (scene.c0 * k * scene.dt) - 1.0,
        measures=measures or None,
    )


def step_phase_angle(integrator: str, z: float) -> float:
    """The phase a right-running mode turns through in one step, rad, for c0 D dt = z (leapfrog: 2 asin(z/2))."""
    eig = np.linalg.eigvals(step_matrices(integrator, [z], 1.0, 1.0, 1.0)[0])
    angles = np.abs(np.angle(eig[np.abs(eig) > 0.5]))  # the auxiliary rates' eigenvalues are 0
    return float(angles[np.argmin(np.abs(angles - z))])  # the physical mode: nearest the exact phase z


def phase_errors(scene, angle: float) -> tuple[float, float]:
    """(lattice, with the step) phase speed errors, c / c0 - 1, of the scene's method for a plane wave of
    wavenumber 1 / pulse width travelling at ``angle`` rad to the lattice's x axis."""
    k = 1.0 / scene.pulse_width
    dxs, dys = symbol(scene, np.array([k * math.cos(angle)]), np.array([k * math.sin(angle)]))
    d = float(math.hypot(dxs[0], dys[0]))
    step = step_phase_angle(scene.integrator, scene.c0 * d * scene.dt) / (scene.c0 * k * scene.dt)
    return d / k - 1.0, step - 1.0


def predicted_fields_2d(scene) -> tuple:
    """(x, y, drho, u, v, t) on the scene's periodic lattice (arrays (ny, nx)) at the run's final time, every
    lattice Fourier mode evolved by the integrator's own step matrix with the symbol D(k): the `linear`
    model's exact discrete solution (u's part along D(k) is the 1D problem with d = |D(k)|; the part across
    it has no rate and stays). With open edges: on the :func:`unbounded` lattice, cut to the scored domain."""
    if scene.open:
        closed, columns, rows = unbounded(scene)
        *fields, t = predicted_fields_2d(closed)
        return (*(a[rows, columns] for a in fields), t)
    xs = scene.x_lo + (np.arange(scene.nx) + 0.5) * scene.dx
    ys = scene.y_lo + (np.arange(scene.ny) + 0.5) * scene.dx
    x, y = np.meshgrid(xs, ys)
    u0, v0, drho0 = scene.kind.initial_fields(scene, x, y, np)
    u0, v0, drho0, keep = scene.kind.mirror_extension(scene, u0, v0, drho0)  # walls: the periodic extension
    kx, ky = np.meshgrid(
        2.0 * math.pi * np.fft.fftfreq(u0.shape[1], d=scene.dx), 2.0 * math.pi * np.fft.fftfreq(scene.ny, d=scene.dx)
    )
    dx_, dy_ = symbol(scene, kx, ky)
    d = np.hypot(dx_, dy_)
    safe = np.where(d > 0, d, 1.0)
    ex, ey = np.where(d > 0, dx_ / safe, 0.0), np.where(d > 0, dy_ / safe, 0.0)
    u_hat, v_hat = np.fft.fft2(u0), np.fft.fft2(v0)
    along, across = ex * u_hat + ey * v_hat, -ey * u_hat + ex * v_hat
    modes = ModeSolver(d.ravel(), np.fft.fft2(drho0).ravel(), along.ravel(), scene.rho0, scene.c0, scene.dt)
    evolve(modes, scene.integrator, scene.n_steps)
    along = modes.u.reshape(d.shape)
    u = np.fft.ifft2(ex * along - ey * across).real[:, keep]
    v = np.fft.ifft2(ey * along + ex * across).real[:, keep]
    return x, y, np.fft.ifft2(modes.drho.reshape(d.shape)).real[:, keep], u, v, modes.t


def predict_2d(scene, kind) -> Prediction:
    """The error of a periodic 2D scene's run predicted with no simulation (exact for `linear`), scored with
    the scene's own measures against its exact reference; phase errors along the axis and the diagonal."""

    x, y, drho, u, v, t = predicted_fields_2d(scene.replace(model="linear"))
    fields = Fields(x=x.ravel(), y=y.ravel(), u=u.ravel(), v=v.ravel(), drho=drho.ravel(), t=t)
    measures = kind.errors(scene.replace(model="linear"), fields)
    return scored_prediction(
        measures, predicted_stable_cfl(scene), t, phase_errors(scene, 0.0), phase_errors(scene, math.pi / 4)
    )


def scored_prediction(measures: dict, stable: float, t: float, axis: tuple, diagonal: tuple) -> Prediction:
    """A Prediction from a scene's error ``measures`` of the predicted fields (their ``mse`` and ``me`` the
    headline), its stable CFL and the (lattice, with the step) phase errors along the axis and the diagonal."""
    return Prediction(
        predicted_error=measures.pop("mse"),
        predicted_me=measures.pop("me"),
        stable_cfl=stable,
        t_end=t,
        lattice_phase_error=axis[0],
        step_phase_error=axis[1],
        lattice_phase_error_diagonal=diagonal[0],
        step_phase_error_diagonal=diagonal[1],
        measures=measures,
    )
