"""The split-field perfectly matched layer (Berenger's, for the linear acoustic equations): each field damped
at its own axis's rate, drho split into its parts along each axis (x and y; x, y and z in 3D)."""

from __future__ import annotations

from solvers.boundaries.absorbers.base import Absorber
from solvers.boundaries.absorbers.sponge import Sponge

VELOCITY = ("u", "v", "w")  # each axis's velocity component
PARTS = ("drho_x", "drho_y")  # the parts of drho carried (the last axis's is what is left)
DEFAULT_STRENGTH = 12.0  # c0 / L: the sponge's profile and default, compared at equal strength (docs/accuracy.md)


class PML(Absorber):
    """Berenger's split-field PML for d(drho)/dt = -rho0 div u, du/dt = -(c0^2 / rho0) grad drho:

        d(drho_x)/dt = -rho0 du/dx - sigma_x drho_x,   d(drho_y)/dt = -rho0 dv/dy - sigma_y drho_y,
        du/dt = -(c0^2 / rho0) d(drho)/dx - sigma_x u,  dv/dt = -(c0^2 / rho0) d(drho)/dy - sigma_y v,

    drho = drho_x + drho_y; in 3D the same with w, sigma_z and drho_z, drho_x and drho_y carried and drho_z the rest
    (the 3D faces' PML: the sweep's x and y parts, two sweeps with the other components zero). In the continuum a
    wave enters it without reflection at any angle and frequency and decays as exp(-int sigma_x dx / (c0 cos
    theta)); the sponge damps every field at sigma_x + sigma_y, which reflects at the onset and at low frequency
    (the 2D pulse's wake). The x part of the SPH continuity sum is the same sweep with v = 0 (the rate is linear in
    the velocities), computed by the solver (``split``) and carried in ``drho_x`` through the integrator's updates;
    each field is damped around its own updates (solvers/boundaries/absorbers/base.py). The profile is the sponge's,
    sigma = strength (depth / width)^2."""

    name = "pml"
    summary = "split-field perfectly matched layer: u, drho_x damped by sigma_x, v, drho_y by sigma_y"
    split = True

    def default_strength(self, scene) -> float:
        return DEFAULT_STRENGTH * scene.c0 / scene.layer

    def sigma(self, depth, width: float, strength: float, xp):
        return Sponge().sigma(depth, width, strength, xp)

    def damp(self, arrays, factors: tuple, fields: str) -> None:
        if fields == "velocity":
            for name, f in zip(VELOCITY, factors):
                arrays[name] *= f
            return
        drho, parts = arrays["drho"], [arrays[name] for name in PARTS[: len(factors) - 1]]
        for part in parts:
            drho -= part  # drho's last axis's part
        drho *= factors[-1]
        for part, f in zip(parts, factors):
            part *= f
            drho += part
