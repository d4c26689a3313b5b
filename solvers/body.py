"""A scene's rigid body, as one value: its size and how its wall is modelled.

A :class:`BodyOptions` is what a Scene's body options are (``Scene.body_options``, beside ``Scene.edges``): the
radius of a cylinder (a 2D kind with a body) or of a sphere (a 3D one), each None until the Scene resolves it
to its kind's (``SceneKind.defaults``), and the boundary method of its wall (solvers/boundaries/bodies/; "": the
default for the scene's correction, :meth:`boundary_method_used`). Where the body is and what it holds is the
scene kind's (``SceneKind.body_of``, ``Scene.body``); :meth:`problems` says why a value does not fit a scene.
"""

from __future__ import annotations

from dataclasses import dataclass, fields

from solvers.corrections import DEFAULT_CORRECTION


@dataclass(frozen=True)
class BodyOptions:
    """A rigid body's options: ``cylinder_radius`` (m; a 2D kind's body), ``sphere_radius`` (m; a 3D kind's),
    None: the kind's; ``boundary_method`` (solvers/boundaries/bodies/; "": :meth:`boundary_method_used`)."""

    cylinder_radius: float | None = None
    sphere_radius: float | None = None
    boundary_method: str = ""

    @classmethod
    def names(cls) -> tuple:
        """The fields' names: a Scene's keywords, record columns and options of its body."""
        return tuple(f.name for f in fields(cls))

    def boundary_method_used(self, correction: str) -> str:
        """How the wall is modelled: ``boundary_method``, or the default (solvers/boundaries/bodies/): standard
        SPH's (rings), or with a kernel ``correction`` the one whose wall holds with it (the weak wall's cut
        cells)."""
        from solvers.boundaries.bodies import CORRECTED_BOUNDARY_METHOD, DEFAULT_BOUNDARY_METHOD

        if self.boundary_method:
            return self.boundary_method
        return DEFAULT_BOUNDARY_METHOD if correction == DEFAULT_CORRECTION else CORRECTED_BOUNDARY_METHOD

    def problems(self, scene):
        """Why these options do not fit ``scene`` (one line each, naming the option; none where they do): a
        radius only of the shape the kind's body has (its own checks are the kind's), a boundary method only
        where there is a body, a known one, in 3D a wall that holds there, and a kernel correction where the
        method's wall needs one."""
        kind = scene.kind
        if not (kind.body and kind.dims == 2) and self.cylinder_radius is not None:
            yield f"--cylinder-radius: the {scene.name} scene has no body of that shape (use --scene cylinder)"
        if not (kind.body and kind.dims == 3) and self.sphere_radius is not None:
            yield f"--sphere-radius: the {scene.name} scene has no body of that shape (use --scene sphere)"
        if not kind.body:
            if self.boundary_method:
                yield f"--boundary-method: the {scene.name} scene has no body (use --scene cylinder)"
            return
        from solvers.boundaries.bodies import boundary_method_named, boundary_method_names

        try:
            method = boundary_method_named(self.boundary_method_used(scene.correction))
        except ValueError as exc:
            yield str(exc)
            return
        if kind.dims == 3 and 3 not in getattr(method, "dims", (2,)):
            # a body in 3D: the weak walls alone (the ghost bodies place particles in a plane)
            walls = [name for name in boundary_method_names() if 3 in getattr(boundary_method_named(name), "dims", ())]
            yield (
                ("" if self.boundary_method else "standard SPH's body, ")
                + f"--boundary-method {method.name}: the {scene.name} scene's body is 3D, whose wall is "
                f"--boundary-method {' or '.join(walls)} alone (the ghost bodies are 2D's); it needs a kernel "
                "correction: add --correction gradient (the high-order method: --kernel laguerre-gauss --cutoff 4 "
                "--h-factor 1.5 --correction gradient)"
            )
            return
        if getattr(method, "needs_correction", False) and scene.correction == DEFAULT_CORRECTION:
            yield (
                f"--boundary-method {method.name} makes a wall only with a kernel correction: add --correction "
                f"gradient (got --correction {scene.correction})"
            )
