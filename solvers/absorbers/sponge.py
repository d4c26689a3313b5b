"""The sponge: a damping rate rising smoothly from 0 at the domain's edge, sigma = strength (depth / width)^2."""

from __future__ import annotations

from solvers.absorbers.base import Absorber

DEFAULT_STRENGTH = 12.0  # c0 / L: the scan's best (docs/accuracy.md)


class Sponge(Absorber):
    """sigma(d) = strength (d / L)^2 across a layer of width L: zero with a zero slope at the domain's edge, so
    the onset reflects little, and strong at the outer end. Along a crossing the layer damps the sound by
    exp(-strength L / (3 c0)) each way, and what is left reflects from the lattice's free outer end and crosses
    again. The default strength, 12 c0 / L (1/s), is the best of a scan (docs/accuracy.md "Open edges": the
    plane pulse, linear, dx 0.25, L = 6 m: 4 to 32 c0 / L), where the onset's reflection and the outer end's
    balance: the least departure from the open domain's answer, 1.8e-3 of the amplitude at t = 64 s."""

    name = "sponge"
    summary = "damping of u, v and drho rising as (depth / width)^2 across the layer"

    def default_strength(self, scene) -> float:
        return DEFAULT_STRENGTH * scene.c0 / scene.layer

    def sigma(self, depth, width: float, strength: float, xp):
        q = xp.clip(depth / width, 0.0, 1.0)
        return strength * q * q
