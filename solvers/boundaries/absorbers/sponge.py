"""The sponge: a damping rate rising smoothly from 0 at the domain's edge, sigma = strength (depth / width)^2."""

from __future__ import annotations

from solvers.boundaries.absorbers.base import Absorber

DEFAULT_STRENGTH = 12.0  # c0 / L: the scan's best (docs/accuracy.md)
DEFAULT_WIDTHS = 1.5  # pulse widths: the thinnest layer of the scan inside the targets with room


class Sponge(Absorber):
    """sigma(d) = strength (d / L)^2 across a layer of width L: zero with a zero slope at the domain's edge, so
    the onset reflects little, and strong at the outer end. Along a crossing the layer damps the sound by
    exp(-strength L / (3 c0)) each way, and what is left reflects from the lattice's free outer end and crosses
    again. The defaults come from a scan (docs/accuracy.md "Open edges": the plane pulse, linear, dx 0.25, L = 3 to
    6 m, 4 to 32 c0 / L): 12 c0 / L (1/s) is where the onset's reflection and the outer end's balance (the least
    energy left at every width), and 1.5 pulse widths (4.5 m) the thinnest layer that leaves the plane pulse
    well inside the issue's 1 % of its amplitude and 1e-4 of its energy (3.3e-3 and 9.5e-6 at t = 64 s; two
    pulse widths 1.3e-3 and 1.8e-6, one 2.4e-2 and 2.8e-4), for 18 % more particles on the paper's domain
    instead of 24 %."""

    name = "sponge"
    summary = "damping of u, v and drho rising as (depth / width)^2 across the layer"
    default_widths = DEFAULT_WIDTHS

    def default_strength(self, scene) -> float:
        return DEFAULT_STRENGTH * scene.c0 / scene.layer

    def sigma(self, depth, width: float, strength: float, xp):
        q = xp.clip(depth / width, 0.0, 1.0)
        return strength * q * q
