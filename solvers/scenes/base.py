"""What a scene is: the problem, its boundaries, its initial fields and what it is scored against.

A scene kind is one class (one file in solvers/scenes/, or a plug-in through
the entry-point group ``pcabench.scenes``) with a ``name``. It states

* ``summary``: one line for --help;
* ``periodic``: the axes that are periodic ("x", "y"); the others have free
  edges. :meth:`boundaries` turns them into the boundary kinds a solver must
  support (``free-x``, ``periodic-x``, ``periodic-y``);
* ``domain``: its default domain (x_min, x_max, y_min, y_max, m), where it
  differs from the paper's;
* ``fields``: the fields its error measures name; ``primary`` the one the
  headline error (a record's ``mse`` and ``me``) measures;
* its initial fields (:meth:`initial_fields`), its exact linear reference
  and error measures (:meth:`errors`), the isothermal reference where it has
  one (:meth:`isothermal_errors`), the linear prediction (:meth:`predict`),
  and its own parameter checks (:meth:`check`, one line each).

The numerical method (kernel, h/dx, CFL, integrator, precision, model) is
the Scene's, not the kind's: every kind runs with every method.
"""

from __future__ import annotations

import math

BOUNDARY_KINDS = ("free-x", "periodic-x", "periodic-y")
MACH_RANGE = (1e-6, 0.3)  # amplitudes a scene accepts: acoustic (linear) to weakly nonlinear
PULSE_WIDTH_RANGE = (0.1, 20.0)  # m


class SceneKind:
    """Base class of the scene kinds: a problem with an exact reference. Subclasses set ``name``."""

    name: str = ""
    summary: str = ""
    periodic: tuple = ("y",)
    domain: dict = {}  # {x_min, x_max, y_min, y_max}: where the kind's default domain differs from Scene's
    fields: tuple = ("u",)
    primary: str = "u"
    has_isothermal: bool = False  # scored against the isothermal solution too (the lagrangian model's physics)
    strip: bool = False  # whether a y-periodic strip gives the same answer (the fields do not depend on y)

    def boundaries(self, scene=None) -> frozenset:
        """The boundary kinds this scene needs of a solver."""
        return frozenset(
            ("periodic-x" if "x" in self.periodic else "free-x", "periodic-y" if "y" in self.periodic else "free-y")
        )

    def check(self, scene) -> list[str]:
        """Problems with ``scene``'s parameters for this kind, one line each naming the option and range."""
        out = []
        lo, hi = MACH_RANGE
        if not lo <= scene.mach <= hi:
            out.append(f"--mach must be in [{lo:g}, {hi:g}] (got {scene.mach:g})")
        lo, hi = PULSE_WIDTH_RANGE
        if not lo <= scene.pulse_width <= hi:
            out.append(f"--pulse-width must be in [{lo:g}, {hi:g}] m (got {scene.pulse_width:g})")
        if scene.strip_height is not None and not self.strip:
            out.append(f"--strip-height: the {self.name} scene depends on y, a strip would change it")
        return out

    def initial_fields(self, scene, x, y, xp):
        """(u, v, drho) at the lattice positions ``x``, ``y`` (m, float64 arrays of module ``xp``) at t = 0."""
        raise NotImplementedError

    def errors(self, scene, fields) -> dict:
        """Error measures of ``fields`` (solvers.interface.Fields) against the exact linear solution:
        ``mse`` (relative RMS of the primary field) and ``me`` (its max error) at least."""
        raise NotImplementedError

    def isothermal_errors(self, scene, fields) -> float | None:
        """Relative RMS error of the primary field against the isothermal (nonlinear) solution, or None."""
        return None

    def exact_fields(self, scene, t: float):
        """The exact linear solution on the scene's lattice at ``t`` as solvers.interface.Fields."""
        raise NotImplementedError

    def linear_floor(self, scene) -> float | None:
        """The `linear` model's error against the isothermal physics as dx -> 0, at the scene's amplitude and
        end: the relative RMS distance between the exact linear and the isothermal solutions (None where the
        scene has no isothermal reference)."""
        if not self.has_isothermal:
            return None
        return self.isothermal_errors(scene, self.exact_fields(scene, scene.t_final))

    def predict(self, scene):
        """The linear model's predicted errors from the dispersion relation (solvers/dispersion.py)."""
        raise NotImplementedError

    def sized_domain(self, size: float) -> dict:
        """The domain of side ``size`` (m) for ``--domain-size``; ValueError where the kind's domain is fixed."""
        raise ValueError(f"--domain-size: the {self.name} scene's domain is fixed (it applies to square scenes)")

    def breaking_time(self, scene) -> float:
        """When the pulse steepens into a shock under the isothermal equations, s (inf: never)."""
        return math.inf
