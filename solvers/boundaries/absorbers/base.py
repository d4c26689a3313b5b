"""What an absorber is: a damping rate sigma (1/s) across an open edge's layer of particles, one file each.

An open edge (``Scene.open``) grows the lattice by a layer of ``Scene.layer_width`` beyond the scored domain.
The damping is a term of each update: around every update of a field over a time h (a kick of u and v, an
advance of drho), before it and after it, the solver computes for each particle the half-update factors of the
two axes, fx = exp(-sigma(depth_x) h / 2) and fy = exp(-sigma(depth_y) h / 2) (depth: how far the particle is
beyond the domain's x or y edge, 0 inside; sigma from the absorber's profile and strength, its own default
unless ``Scene.absorber_strength`` says otherwise; 1 on a closed axis), and the absorber applies them to the
fields of that update (:meth:`Absorber.damp`): a sponge multiplies them by fx fy (fz); a split-field PML damps
each field by its own axis's factor and needs the continuity rate split by axis (``split``: the solver then also
computes the x part of d(drho)/dt, ``ddx``, and carries the x part of drho, ``drho_x``, as particle arrays; in 3D
the y parts too, ``ddy`` and ``drho_y``, the z part being what is left).

Why around each update and not after the step: an update damped symmetrically, f (u + h a) f, reads
s (u' - u) + d (u' + u) = h a with s = cosh(sigma h / 2) >= 1 and d = sinh(sigma h / 2) >= 0 per particle, the
undamped update with a dissipative term and a heavier particle, so the leapfrog's discrete energy still only
falls and the scheme keeps the closed scene's stable CFL for any profile and strength. Damping every field once
after the whole step, the earlier way, does not commute with the pair sums where sigma varies: measured, the
default layers then blew up from CFL 4.0 where the closed scenes hold to 4.9 (docs/accuracy.md "Open edges").
What a profile decides is how much of the sound the layer's onset reflects and how much it lets through to the
outer (free) end and back.
"""

from __future__ import annotations


def product(factors: tuple):
    """fx (fy fz): the per-axis factors' product, in one order for every solver (a closed axis's is a scalar 1)."""
    out = factors[-1]
    for f in reversed(factors[:-1]):
        out = f * out
    return out


FIELDS = {"velocity": ("u", "v", "w"), "density": ("drho",)}  # what each update changes (w: a 3D scene's)


class Absorber:
    """An absorbing layer: ``sigma(depth, width, strength, xp)`` in 1/s, ``depth`` and ``width`` in m (arrays of
    the solver's module: numpy or CuPy), 0 at depth 0; ``default_strength(scene)``: the strength (1/s) a scene
    gets when it names none; ``damp(arrays, factors, fields)``: ``fields`` ("velocity": u, v (and w); "density":
    drho) damped by the factors, one per axis (fx, fy, and fz in 3D), in place (a GPU solver's arrays are views of
    one block). The base class damps like a sponge."""

    name: str = ""
    summary: str = ""
    split: bool = False  # whether it needs the continuity rate split by axis (ddx) and drho's x part (drho_x)
    default_widths: float = 2.0  # the layer's width a scene gets when it names none, in pulse widths

    def default_width(self, scene) -> float:
        """The layer's width (m) a scene gets when it names none: ``default_widths`` of its pulse widths. (An
        override must not read ``scene.layer`` or ``scene.strength``: they are computed from it.)"""
        return self.default_widths * scene.pulse_width

    def default_strength(self, scene) -> float:
        raise NotImplementedError

    def sigma(self, depth, width: float, strength: float, xp):
        raise NotImplementedError

    def damp(self, arrays, factors: tuple, fields: str) -> None:
        """The fields times fx fy (fz): every field damped at the rate of every axis together."""
        factor = product(factors)
        for name in FIELDS[fields]:
            if name in arrays:
                arrays[name] *= factor
