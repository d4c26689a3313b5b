"""The dispersion prediction on the cubic lattice (a 3D scene's), with no simulation.

The 3D counterpart of solvers/reference/dispersion.py: the `linear` SPH sums act on a plane wave exp(i k.x) as
i D(k), with

    D(k) = -sum_j V sin(k.x_ij) x_ij G(r_ij)        (V = dx^3, G of the kernel normalised in 3D, r_ij < cutoff)

over the lattice neighbours; each Fourier mode of the cube's initial fields is evolved by the integrator's own
step matrices (dispersion.ModeSolver) with d = |D(k)|, the velocity's part along D(k) coupled to drho and the
rest at rest. On the periodic cube this is the `linear` run's exact discrete solution (a run equals it to
round-off: tests/test_three_d.py), and the largest |D| over the 3D Brillouin zone gives the stable CFL.
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from solvers.fields import Fields
from solvers.reference.dispersion import (
    ModeSolver,
    Prediction,
    evolve,
    largest_stable_z,
    scored_prediction,
    step_phase_angle,
)

SYMBOL_CHUNK = 1 << 21  # wavenumbers x neighbours evaluated at once
SPECTRUM_FLOOR = 1e-16  # modes of the initial fields below this fraction of the largest are not evolved


def lattice_offsets(scene) -> tuple:
    """(a, b, c, G): the cubic lattice neighbours' offsets in units of dx within the cutoff (the particle itself
    left out) and the 3D kernel's G(r) at each, 1/m^5."""
    reach = int(math.ceil(scene.cutoff / scene.dx))
    span = np.arange(-reach, reach + 1)
    a, b, c = np.meshgrid(span, span, span, indexing="ij")
    r = np.sqrt(a**2 + b**2 + c**2) * scene.dx
    keep = (r < scene.cutoff) & (r > 0)
    g = scene.sph_kernel.gradient(r[keep], scene.h, dims=3)
    return a[keep].astype(float), b[keep].astype(float), c[keep].astype(float), g


def symbol(scene, kx, ky, kz) -> tuple:
    """(D_x, D_y, D_z) at wavenumbers (kx, ky, kz), 1/m (arrays broadcast together), in chunks."""
    a, b, c, g = lattice_offsets(scene)
    kx, ky, kz = np.broadcast_arrays(*(np.asarray(k, float) for k in (kx, ky, kz)))
    shape = kx.shape
    kx, ky, kz = kx.ravel(), ky.ravel(), kz.ravel()
    out = np.empty((3, kx.size))
    step = max(1, SYMBOL_CHUNK // max(a.size, 1))
    for lo in range(0, kx.size, step):
        part = slice(lo, lo + step)
        phase = sum(np.multiply.outer(k[part], o * scene.dx) for k, o in ((kx, a), (ky, b), (kz, c)))
        weight = -(scene.dx**3) * np.sin(phase) * g
        for i, o in enumerate((a, b, c)):
            out[i, part] = weight @ (o * scene.dx)
    scale = scene.sph_correction.lattice_factor(scene)  # a correction's factor in the lattice's interior
    return tuple(scale * row.reshape(shape) for row in out)


def largest_symbol(scene, points: int = 33) -> float:
    """max |D(k)| over the 3D Brillouin zone [0, pi/dx]^3 (the lattice's symmetry covers the rest), 1/m."""
    k = np.linspace(0.0, math.pi / scene.dx, points)
    kx, ky, kz = np.meshgrid(k, k, k, indexing="ij")
    d = symbol(scene, kx.ravel(), ky.ravel(), kz.ravel())
    return float(np.sqrt(sum(part**2 for part in d)).max())


@lru_cache(maxsize=256)
def unit_cube(kernel: str, h_factor: float, cutoff_factor: float, integrator: str, correction: str):
    """The 3D pulse's periodic cube at dx = 1 m with a method's fields, wide enough for its stencil: what depends on
    h/dx only (dx |D|, the stable CFL) is computed on it."""
    from solvers.scene import Scene

    reach = h_factor * max(cutoff_factor, 2.0)
    half = math.ceil(1.5 * reach) + 1.0
    cube = {f"{axis}_{end}": sign * half for axis in "xyz" for end, sign in (("min", -1), ("max", 1))}
    return Scene(
        1.0, "acoustic-pulse-3d", pulse_width=0.1, model="linear", kernel=kernel, h_factor=h_factor,
        cutoff_factor=cutoff_factor, integrator=integrator, correction=correction, **cube,
    )  # fmt: skip


@lru_cache(maxsize=256)
def largest_unit_symbol(kernel: str, h_factor: float, cutoff_factor: float, integrator: str, correction: str) -> float:
    """dx max |D| of a method on the cubic lattice (:func:`largest_symbol` on :func:`unit_cube`; the same at every
    dx): c0 |D| dt per unit CFL."""
    unit = unit_cube(kernel, h_factor, cutoff_factor, integrator, correction)
    return unit.dx * largest_symbol(unit)


def lattice_stable_cfl(kernel: str, h_factor: float, cutoff_factor: float, integrator: str, correction: str) -> float:
    """The largest stable CFL of a method on the periodic cubic lattice (the same at every dx: D scales as 1/dx)."""
    return largest_stable_z(integrator) / largest_unit_symbol(kernel, h_factor, cutoff_factor, integrator, correction)


def predicted_stable_cfl(scene) -> float:
    """:func:`lattice_stable_cfl` of a 3D scene's method."""
    cut = scene.cutoff_factor
    return lattice_stable_cfl(scene.kernel, float(scene.h_factor), float(cut), scene.integrator, scene.correction)


def predicted_fields(scene) -> tuple:
    """(drho, u, v, w, t) on the 3D scene's periodic lattice (arrays (nz, ny, nx)) at the run's final time: every
    lattice Fourier mode of the initial fields evolved by the integrator's step matrices with d = |D(k)|. Only the
    modes holding more than :data:`SPECTRUM_FLOOR` of the largest are evolved (the pulse's spectrum is a Gaussian:
    a ball of a few thousand modes whatever dx, where the symbol at every mode of a fine lattice took minutes);
    the others, below it, stay as they are, unless the step is past the stable one: then every mode is evolved,
    so that the ones that grow are in the prediction as in a run."""
    axes = [lo + (np.arange(n) + 0.5) * scene.dx for lo, n in ((scene.x_lo, scene.nx), (scene.y_lo, scene.ny),
                                                                 (scene.z_lo, scene.nz))]  # fmt: skip
    z, y, x = np.meshgrid(axes[2], axes[1], axes[0], indexing="ij")
    u0, v0, w0, drho0 = scene.kind.initial_fields(scene, x, y, np, z=z)
    del x, y, z
    hats = [np.fft.fftn(f) for f in (u0, v0, w0)]
    drho_hat = np.fft.fftn(drho0)
    size = max(float(np.abs(h).max()) for h in (*hats, drho_hat))
    keep = np.abs(drho_hat) > SPECTRUM_FLOOR * size
    for h in hats:
        keep |= np.abs(h) > SPECTRUM_FLOOR * size
    if scene.cfl > predicted_stable_cfl(scene):  # the round-off's modes grow past the stable step: every one evolved
        keep[...] = True
    kz, ky, kx = (
        2.0 * math.pi * np.fft.fftfreq(n, d=scene.dx)[index]
        for n, index in zip((scene.nz, scene.ny, scene.nx), np.nonzero(keep))
    )
    d3 = symbol(scene, kx, ky, kz)  # at the kept modes
    d = np.sqrt(sum(part**2 for part in d3))
    safe = np.where(d > 0, d, 1.0)
    e = [np.where(d > 0, part / safe, 0.0) for part in d3]
    along = sum(ei * h[keep] for ei, h in zip(e, hats))
    modes = ModeSolver(d, drho_hat[keep], along, scene.rho0, scene.c0, scene.dt)
    evolve(modes, scene.integrator, scene.n_steps)
    drho_hat[keep] = modes.drho
    for ei, h in zip(e, hats):  # the part across D(k) has no rate: it stays; the part along it is the evolved one
        h[keep] += ei * (modes.u - along)
    u, v, w = (np.fft.ifftn(h).real for h in hats)
    return np.fft.ifftn(drho_hat).real, u, v, w, modes.t


def predict(scene, kind) -> Prediction:
    """The error of a periodic 3D scene's `linear` run predicted with no simulation (exact), scored with the
    scene's own measures; the phase errors along the lattice's axis and its body diagonal."""

    linear = scene.replace(model="linear")
    drho, u, v, w, t = predicted_fields(linear)
    exact = kind.exact_fields(linear, t)
    fields = Fields(x=exact.x, y=exact.y, z=exact.z, u=u.ravel(), v=v.ravel(), w=w.ravel(), drho=drho.ravel(), t=t)
    measures = kind.errors(linear, fields)
    axis, diagonal = phase_errors(scene, (1.0, 0.0, 0.0)), phase_errors(scene, (1.0, 1.0, 1.0))
    return scored_prediction(measures, predicted_stable_cfl(scene), t, axis, diagonal)


def phase_errors(scene, direction: tuple) -> tuple[float, float]:
    """(lattice, with the step) phase speed errors, c / c0 - 1, for a plane wave of wavenumber 1 / pulse width
    along ``direction``."""
    k = 1.0 / scene.pulse_width
    n = np.asarray(direction, float) / np.linalg.norm(direction)
    parts = symbol(scene, *(np.array([k * c]) for c in n))
    d = float(math.sqrt(sum(float(p[0]) ** 2 for p in parts)))
    step = step_phase_angle(scene.integrator, scene.c0 * d * scene.dt) / (scene.c0 * k * scene.dt)
    return d / k - 1.0, step - 1.0
