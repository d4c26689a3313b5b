"""The edges of a scene, as one value: which are open, and the absorbing layer beyond them.

An :class:`Edges` is what a Scene's edge options are (``Scene.edges``): the edges an absorbing layer lies beyond
(``open``: "", "x", "y" or "xy"), the layer's width, what damps it and how strongly; each left unset ("" or None)
takes the absorber's default for the scene (solvers/boundaries/absorbers/). The layer's geometry follows from these
given the scene (its dx, pulse width and kind): :meth:`n_layer` columns of dx beyond each open edge, its
:meth:`strength`, and the :meth:`problems` of a value that cannot be built. Its defaults (closed, nothing set)
are the fields' own, which Scene reads (``Scene.default``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

from solvers.method import is_finite_number

OPEN_EDGES = ("", "x", "y", "xy", "xyz")  # none, the x edges, the y edges, all four; a 3D scene's six faces


def default_absorber(kind) -> str:
    """The absorber a scene of ``kind`` gets when it names none: the split-field PML (2D and 3D), except on a strip
    (a plane wave along x), where the sponge gives the PML's answer (measured: the same to three digits; there is
    no y part to split) for less work and a thinner default layer (docs/accuracy.md). 3D scenes took the sponge
    until 2026-12-07 (the PML's parts then cost a sweep each: twice PI; now summed in the rate's pass); a stored
    row says which it ran (its ``absorber_used``; pcabench.spec.stored_parameters reads older ones)."""
    return "sponge" if kind.strip else "pml"


@dataclass(frozen=True)
class Edges:
    """The open edges and their layer: ``open`` ("" closed; a Scene resolves "" to its kind's), ``layer_width``
    (m, whole columns of dx; None: the absorber's default), ``absorber`` (solvers/boundaries/absorbers/; "": the
    scene's, :meth:`absorber_used`) and ``absorber_strength`` (1/s; None: the absorber's default for the scene)."""

    open: str = ""
    layer_width: float | None = None
    absorber: str = ""
    absorber_strength: float | None = None

    @classmethod
    def names(cls) -> tuple:
        """The fields' names: a Scene's keywords, record columns and options of its edges."""
        return tuple(f.name for f in fields(cls))

    @classmethod
    def layer_unset(cls) -> dict:
        """The layer's options unset (a closed scene's: it takes none of them)."""
        closed = cls()
        return {name: getattr(closed, name) for name in cls.names() if name != "open"}

    @property
    def open_x(self) -> bool:
        """Whether the x edges are open: the lattice holds an absorbing layer beyond each."""
        return "x" in self.open

    @property
    def open_z(self) -> bool:
        """Whether a 3D scene's z faces are open."""
        return "z" in self.open

    @property
    def open_y(self) -> bool:
        """Whether the y edges are open: the lattice holds an absorbing layer beyond each."""
        return "y" in self.open

    def absorber_used(self, scene) -> str:
        """The absorber that damps the layer: ``absorber``, or the scene kind's default (:func:`default_absorber`)."""
        if self.absorber:
            return self.absorber
        return default_absorber(scene.kind)

    def absorber_model(self, scene):
        """The absorber of :meth:`absorber_used` (solvers/boundaries/absorbers/); ValueError naming --absorber and the
        choices if it is unknown."""
        from solvers.boundaries.absorbers import absorber_named

        return absorber_named(self.absorber_used(scene))

    def width_asked(self, scene) -> float:
        """The layer's width asked for, m: ``layer_width``, or the absorber's default (in pulse widths)."""
        return self.layer_width if self.layer_width is not None else self.absorber_model(scene).default_width(scene)

    def n_layer(self, scene) -> int:
        """Columns (rows) of dx of the layer beyond each open edge (0 where none is open)."""
        return max(int(round(self.width_asked(scene) / scene.dx)), 0) if self.open else 0

    def strength(self, scene) -> float:
        """The absorber's strength, 1/s: ``absorber_strength``, or the absorber's default for the scene."""
        if self.absorber_strength is not None:
            return float(self.absorber_strength)
        return self.absorber_model(scene).default_strength(scene)

    def problems(self, scene):
        """Why these edges do not fit ``scene`` (one line each, naming the option; none where they do): edges the
        scene can open, a known absorber, a layer of positive width holding a column of dx and no wider than the
        domain, a positive strength; none of the layer's options on a closed scene."""
        if self.open not in OPEN_EDGES:
            yield f"--open must be one of {', '.join(e for e in OPEN_EDGES if e)} (got {self.open!r})"
            return
        if (self.open == "xyz") != (scene.kind.dims == 3 and bool(self.open)):
            yield (
                f"--open {self.open}: the {scene.name} scene is {scene.kind.dims}D, whose edges open as "
                + ("xyz (its six faces)" if scene.kind.dims == 3 else "x, y or xy")
            )
            return
        openable = scene.kind.openable_edges()
        for axis in ("x", "y", "z")[: scene.kind.dims]:
            if axis in self.open and axis not in openable:
                yield f"--open {axis}: {scene.kind.closed_reason(axis)}"
                return
        if not self.open:  # a closed scene has no layer: its options would be stored as if they did something
            for name, unset in self.layer_unset().items():
                if getattr(self, name) != unset:
                    yield f"--{name.replace('_', '-')}: the scene's edges are closed (add --open x, y or xy)"
                    return
            return
        try:
            self.absorber_model(scene)  # first: a known absorber (the default layer is the absorber's)
        except ValueError as exc:
            yield str(exc)
            return
        for name in ("layer_width", "absorber_strength"):
            value = getattr(self, name)
            if value is None:
                continue
            if not is_finite_number(value):
                yield f"{name} must be a finite number (got {value!r})"
                return
            if not value > 0:
                yield f"--{name.replace('_', '-')} must be > 0 (got {value:g})"
                return
        width = scene.x_max - scene.x_min
        span = min(width if self.open_x else math.inf, scene.height_span if self.open_y else math.inf)
        layer = self.n_layer(scene) * scene.dx
        if not layer <= span:
            yield (
                f"--layer-width must be at most the domain's {'width' if span == width else 'height'} {span:g} m "
                f"(got {layer:g} m)"
            )
        elif self.n_layer(scene) < 1:
            yield f"--layer-width must hold one column of dx = {scene.dx:g} m (got {self.width_asked(scene):g} m)"
