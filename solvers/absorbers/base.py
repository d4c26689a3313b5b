"""What an absorber is: a damping rate sigma (1/s) across an open edge's layer of particles, one file each.

An open edge (``Scene.open``) grows the lattice by a layer of ``Scene.layer_width`` beyond the scored domain.
After every step the solver computes, for each particle, the damping factors of the two axes,
fx = exp(-sigma(depth_x) dt) and fy = exp(-sigma(depth_y) dt) (depth: how far the particle is beyond the
domain's x or y edge, 0 inside; sigma from the absorber's profile and strength, its own default unless
``Scene.absorber_strength`` says otherwise; 1 on a closed axis), and the absorber applies them to the state
(:meth:`Absorber.damp`): a sponge multiplies u, v and drho by fx fy; a split-field PML damps each field by its
own axis's factor and needs the continuity rate split by axis (``split``: the solver then also computes the
x part of d(drho)/dt, ``ddx``, and carries the x part of drho, ``drho_x``, as particle arrays). Each damping is
exact for its own term (operator splitting), so it is stable at any strength and step; what a profile decides
is how much of the sound the layer's onset reflects and how much it lets through to the outer (free) end and
back.
"""

from __future__ import annotations


class Absorber:
    """An absorbing layer: ``sigma(depth, width, strength, xp)`` in 1/s, ``depth`` and ``width`` in m (arrays of
    the solver's module: numpy or CuPy), 0 at depth 0; ``default_strength(scene)``: the strength (1/s) a scene
    gets when it names none; ``damp(arrays, fx, fy)``: the state after the step's damping (in place: a GPU
    solver's arrays are views of one block). The base class damps like a sponge."""

    name: str = ""
    summary: str = ""
    split: bool = False  # whether it needs the continuity rate split by axis (ddx) and drho's x part (drho_x)

    def default_strength(self, scene) -> float:
        raise NotImplementedError

    def sigma(self, depth, width: float, strength: float, xp):
        raise NotImplementedError

    def damp(self, arrays, fx, fy) -> None:
        """u, v and drho times fx fy: every field damped at the rate of both axes together."""
        factor = fx * fy
        for name in ("u", "v", "drho"):
            arrays[name] *= factor
