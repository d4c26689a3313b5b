"""The problem's and the method's parameters, declared once.

Each :class:`Parameter` ties a :class:`solvers.Scene` field (which is also
the stored record's column: a record stores its scene's parameters) to its
command-line option, its help and its allowed values. The default, the
allowed range and the value a row stored before the parameter existed reads
as are Scene's (``Scene.default``; Scene checks every value in one line;
:func:`pcabench.spec.stored_parameters` brings an old row up to the current
fields when the store loads it). The command line builds its options from
this table, advise writes its commands with it, and the error messages name
the option a user typed through it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from solvers import INTEGRATORS, MODELS, PRECISIONS, Scene, kernel_named, kernel_names, scene_names, scenes
from solvers.boundaries.absorbers import absorber_named, absorber_names
from solvers.boundaries.bodies import CORRECTED_BOUNDARY_METHOD, DEFAULT_BOUNDARY_METHOD, boundary_method_names
from solvers.corrections import correction_named, correction_names
from solvers.edges import OPEN_EDGES


@dataclass(frozen=True)
class Parameter:
    """One parameter: its Scene field (= record column), its option and what it is (with units)."""

    field: str
    option: str
    help: str | Callable[[], str]  # without the default, which Scene states
    choices: Callable[[], tuple] | None = None  # the allowed values (read at call: the registries grow)
    numeric: bool = False  # a number checked by Scene (its range there)
    per_scene: bool = False  # its default is the scene kind's (solvers/scenes/), stated in ``help``

    @property
    def dest(self) -> str:
        """The argparse destination of :attr:`option`."""
        return self.option[2:].replace("-", "_")

    def default(self):
        return Scene.default(self.field)

    def describe(self) -> str:
        """The option's help: what it is and its default."""
        text = self.help() if callable(self.help) else self.help
        if self.per_scene:
            return text
        value = self.default()
        return f"{text} (default {value:g})" if isinstance(value, float) else f"{text} (default {value})"

    def words(self, value) -> list[str]:
        """``[option, value]`` as a command line writes them (a number in its shortest exact form)."""
        return [self.option, number_word(value) if self.numeric or isinstance(value, float) else str(value)]


def number_word(value) -> str:
    """A number as a command line writes it: ``%g`` where that is exact, else every digit (``repr``)."""
    return f"{value:g}" if float(value) == float(f"{value:g}") else repr(float(value))


def _kernel_help() -> str:
    compact = "; ".join(
        f"{k} is cut at its compact support {kernel_named(k).support:g}h"
        for k in kernel_names()
        if kernel_named(k).support is not None
    )
    return "SPH kernel, truncated at --cutoff" + (f" ({compact})" if compact else "")


def _wall_help() -> str:
    walled = [
        f"{name} {kind.domain.get('x_max', Scene.default('x_max')):g}" for name, kind in scenes().items() if kind.walls
    ]
    return (
        "the rigid wall's x, m: the domain's right edge, in the scenes with walls (default " + ", ".join(walled) + ")"
    )


def _per_scene(text: str, field: str) -> str:
    """``text`` with its default: the paper's, and the scene kinds' that differ."""
    paper = Scene.default(field)
    own = [f"{name} {kind.defaults[field]:g}" for name, kind in scenes().items() if field in kind.defaults]
    head = f"default {paper:g}" if paper is not None else "default"
    return f"{text} ({head}" + ("; " if paper is not None and own else " ") + ", ".join(own) + ")"


def _scene_help() -> str:
    return "the problem: " + "; ".join(f"{name}: {kind.summary}" for name, kind in scenes().items())


PROBLEM = (
    Parameter("name", "--scene", _scene_help, scene_names),
    Parameter("mach", "--mach", "the pulse's amplitude as a Mach number", numeric=True),
    Parameter(
        "pulse_width",
        "--pulse-width",
        lambda: _per_scene("the pulse's width, m", "pulse_width"),
        numeric=True,
        per_scene=True,
    ),
    Parameter(
        "pulse_center",
        "--pulse-center",
        lambda: _per_scene("the pulse's centre x at t = 0, m", "pulse_center"),
        numeric=True,
        per_scene=True,
    ),
    Parameter(
        "cylinder_radius",
        "--cylinder-radius",
        lambda: _per_scene("the rigid cylinder's radius, m, in the scenes with a body", "cylinder_radius"),
        numeric=True,
        per_scene=True,
    ),
    Parameter(
        "sphere_radius",
        "--sphere-radius",
        lambda: _per_scene("the rigid sphere's radius, m, in the 3D scenes with a body", "sphere_radius"),
        numeric=True,
        per_scene=True,
    ),
    Parameter("x_max", "--wall-x", _wall_help, numeric=True, per_scene=True),
)
BOUNDARY = (
    Parameter(
        "open",
        "--open",
        "open edges: x opens both x edges, y both y edges, xy all four, by an absorbing layer of particles "
        "beyond the domain, which stays the scored one (default: closed, as the scene is)",
        lambda: tuple(e for e in OPEN_EDGES if e),
        per_scene=True,
    ),
    Parameter(
        "layer_width",
        "--layer-width",
        lambda: (
            "the absorbing layer's width, m, in whole columns of dx (default: the absorber's, in pulse widths: "
            + ", ".join(f"{n} {absorber_named(n).default_widths:g}" for n in absorber_names())
            + ")"
        ),
        numeric=True,
        per_scene=True,
    ),
    Parameter(
        "absorber",
        "--absorber",
        "what damps an open edge's layer (solvers/boundaries/absorbers/; default: pml, the sponge on a plane "
        "pulse's strip)",
        absorber_names,
        per_scene=True,
    ),
    Parameter(
        "absorber_strength",
        "--absorber-strength",
        "the absorber's strength, 1/s (default: the absorber's for the layer, 12 c0 / width)",
        numeric=True,
        per_scene=True,
    ),
)
BODY = (
    Parameter(
        "boundary_method",
        "--boundary-method",
        "how a body's curved wall is modelled (solvers/boundaries/bodies/: ghost particles on rings fitted to "
        "its surface, "
        "on the lattice inside it, or none, the corrected operators making the wall; default "
        f"{DEFAULT_BOUNDARY_METHOD}, with --correction {CORRECTED_BOUNDARY_METHOD})",
        boundary_method_names,
        per_scene=True,
    ),
)
PRECISION_MODEL = (
    Parameter("precision", "--precision", "floating-point precision", lambda: PRECISIONS),
    Parameter("model", "--model", "the physics model", lambda: MODELS),
)
METHOD = (
    Parameter("integrator", "--integrator", "time integrator", lambda: INTEGRATORS),
    Parameter("kernel", "--kernel", _kernel_help, kernel_names),
    Parameter(
        "correction",
        "--correction",
        lambda: (
            "kernel correction (solvers/corrections/): "
            + "; ".join(f"{n}: {correction_named(n).summary}" for n in correction_names())
        ),
        correction_names,
    ),
    Parameter(
        "cutoff_factor",
        "--cutoff",
        "where a truncated kernel (one without a compact support: gaussian, laguerre-gauss) is cut, in units of h "
        "(the Gaussian's default 3; 4 keeps laguerre-gauss fourth order); a compact kernel is cut at its support",
        numeric=True,
    ),
    Parameter("h_factor", "--h-factor", "h / dx", numeric=True),
    Parameter("cfl", "--cfl", "dt * c0 / dx", numeric=True),
)
PARAMETERS = PROBLEM + BOUNDARY + BODY + PRECISION_MODEL + METHOD


def parameter(field: str) -> Parameter:
    """The parameter of Scene field ``field``."""
    return next(p for p in PARAMETERS if p.field == field)
