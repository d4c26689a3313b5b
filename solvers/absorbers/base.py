"""What an absorber is: a damping rate sigma (1/s) across an open edge's layer of particles, one file each.

An open edge (``Scene.open``) grows the lattice by a layer of ``Scene.layer_width`` beyond the scored domain;
after every step each particle in it has u, v and drho multiplied by exp(-sigma dt), sigma from its depth into
the layer (0 at the domain's edge, the layer's width at its outer end) and the absorber's strength (its own
default unless ``Scene.absorber_strength`` says otherwise). The damping is exact for its own term (operator
splitting), so it is stable at any strength and step; what a profile decides is how much of the sound the
layer's onset reflects and how much it lets through to the outer (free) end and back.
"""

from __future__ import annotations


class Absorber:
    """An absorbing layer's profile: ``sigma(depth, width, strength)`` in 1/s, ``depth`` and ``width`` in m
    (arrays of the solver's module: numpy or CuPy), 0 at depth 0. ``default_strength(scene)``: the strength
    (1/s) a scene gets when it names none."""

    name: str = ""
    summary: str = ""

    def default_strength(self, scene) -> float:
        raise NotImplementedError

    def sigma(self, depth, width: float, strength: float, xp):
        raise NotImplementedError
