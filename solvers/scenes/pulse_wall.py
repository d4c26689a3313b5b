"""The CAA workshop's 2D acoustic pulse reflected by a rigid wall, in a duct.

The 2D acoustic pulse (drho = rho0 Ma exp(-ln2 r^2 / b^2), u = v = 0,
solvers/scenes/acoustic_pulse.py) starts two widths from a rigid wall, as in
the CAA problem's geometry: centre at ``--pulse-center`` (0 m), the wall at
the domain's right edge ``--wall-x`` (6 m), a second rigid wall at the left
edge x_min = -14 m, periodic in y over 20 m. Walls at both ends make the
problem's even extension across them periodic with period twice the width,
so the exact linear reference is the periodic FFT reference
(solvers/reference/pulse2d.py) of the pulse plus its mirror image across the wall on
that doubled lattice, cropped to the domain: exact at every time, the
reflections from both walls included. The initial field is that reference at
t = 0 (the image's tail is in it). The `linear` model's run is the same
problem on the doubled periodic lattice, so the dispersion prediction holds
for it exactly (solvers/reference/dispersion.py).

Scored like the free 2D pulse (drho, velocity, along axis and diagonal; not
the front's speed along a ray, which the reflections cross), and apart near
the walls (within a cutoff: the particles with mirror neighbours) and in the
bulk. No isothermal reference: the reflected wave is not the
radially symmetric one.
"""

from __future__ import annotations

import numpy as np

from solvers.fields import Fields
from solvers.scenes.acoustic_pulse import LN2, AcousticPulse, centre, measures
from solvers.scenes.base import wall_measures
from solvers.scenes.plane_wall import DEFAULT_WALL, SMALLEST_WALLED, wall_check


def _wrap(xp, d, period: float):
    """Offsets ``d`` to their minimum image in ``period``, m (as the periodic reference samples them)."""
    return d - period * xp.floor(d / period + 0.5)


class PulseWall(AcousticPulse):
    name = "pulse-wall"
    summary = "the 2D acoustic pulse two widths from a rigid wall at --wall-x, in a duct walled at both x ends"
    periodic = ("y",)
    images = ()  # its reference is the walls' mirror images on a periodic lattice: no edge opens
    smallest = SMALLEST_WALLED
    smallest_open = None
    card_open = None
    walls = ("x_min", "x_max")
    domain = {"x_min": -14.0, "x_max": DEFAULT_WALL, "y_min": -10.0, "y_max": 10.0}
    has_isothermal = False

    def image_centres(self, scene) -> tuple[float, float]:
        """x of the pulse's centre and of its mirror image across the right wall, m."""
        return scene.pulse_center, 2.0 * scene.walls["x_max"] - scene.pulse_center

    def initial_fields(self, scene, x, y, xp):
        _, yc = centre(scene)
        period = 2.0 * scene.width  # the doubled lattice's
        dy = _wrap(xp, y - yc, scene.height)
        drho = 0.0
        for xc in self.image_centres(scene):
            dx = _wrap(xp, x - xc, period)
            drho = drho + scene.rho0 * scene.mach * xp.exp(-LN2 * (dx * dx + dy * dy) / scene.pulse_width**2)
        zero = xp.zeros_like(drho)
        return zero, zero.copy(), drho

    def reference_lattice(self, scene) -> tuple[int, tuple]:
        """The doubled periodic lattice (2 nx columns from x_lo) and the pulse's mirror image across the wall."""
        return 2 * scene.nx, self.image_centres(scene)[1:]

    def exact_fields(self, scene, t: float):

        ref = self.reference(scene, t)
        x, y = np.meshgrid(ref.x[: scene.nx], ref.y)
        crop = (ref.drho[:, : scene.nx], ref.u[:, : scene.nx], ref.v[:, : scene.nx])
        return Fields(x=x.ravel(), y=y.ravel(), u=crop[1].ravel(), v=crop[2].ravel(), drho=crop[0].ravel(), t=t)

    def errors(self, scene, fields) -> dict:
        ref = self.reference(scene, fields.t)
        if scene.model == "lagrangian":  # particles moved: the reference at their positions
            values = ref.at(fields.x, fields.y, order=3)
        else:
            values = tuple(a[:, : scene.nx].ravel() for a in (ref.drho, ref.u, ref.v))
        out = measures(scene, fields.x, fields.y, fields.drho, fields.u, fields.v, values)
        for ray in ("front_axis", "front_diagonal"):  # the outgoing peak along a ray: the reflections cross it here
            out.pop(ray)
        return {
            **out,
            **wall_measures(
                scene, fields.x, np.asarray(fields.drho, float) - values[0], values[0], scene.rho0 * scene.mach
            ),
        }

    def isothermal_errors(self, scene, fields) -> float | None:
        return None

    def sized_domain(self, size: float) -> dict:
        raise ValueError(
            f"--domain-size: the {self.name} scene's domain is fixed (the wall at --wall-x, the left wall at "
            f"{self.domain['x_min']:g} m)"
        )

    def check(self, scene) -> list[str]:
        out = super(AcousticPulse, self).check(scene)  # the kind's common ranges (the free square's own do not apply)
        return out + wall_check(scene)
