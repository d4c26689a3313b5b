"""What a preset is, the preset registry, and the matrix built from command-line options.

A preset is one :class:`Preset` object in a study's ``plan.py`` (``pcabench/studies/<study>/plan.py``, found by
the registry :data:`PRESETS`; a plug-in through the entry-point group ``pcabench.presets``): its plan lists the
runs (:class:`~pcabench.spec.RunSpec`) its tables and figures need, smallest first, so that a sweep can predict
the cost of a large run from the smaller ones before it; its flag and help make its option of ``pcabench study``.
Scene defaults (h/dx, CFL, cutoff, integrator, the strip rule) come from :class:`solvers.Scene`, never from here.
"""

from __future__ import annotations

import dataclasses
import itertools
from typing import Callable

from pcabench.spec import SERIAL, RunSpec
from solvers import DEFAULT_SOLVER, Scene, solver_class
from solvers.plugins import Registry
from solvers.scenes import DEFAULT_SCENE

MATRIX_BUDGET = 900.0  # s per run of a matrix of options (--dx ...), not a preset (--run-budget overrides)
DEFAULT_PRESET = "quick"  # what `pcabench study` runs with no preset flag and no matrix
ENTRY_POINT_GROUP = "pcabench.presets"


def spec_of(solver=DEFAULT_SOLVER, threads=SERIAL, strip=False, pair_loop="auto", **scene) -> RunSpec:
    """One run; ``strip`` puts it on the thinnest y-periodic strip Scene accepts."""
    if strip:
        scene["strip_height"] = Scene.thinnest_strip(
            scene["dx"], scene.get("cutoff_factor"), scene.get("h_factor"), scene.get("kernel")
        )
    return RunSpec(solver, Scene(**scene), threads, pair_loop=pair_loop)


@dataclasses.dataclass(frozen=True)
class Preset:
    """A named study. ``plan`` makes its runs (RunSpecs, smallest first; a ``scened`` plan takes ``scene=``, the
    scene it runs on: the fronts); ``budget`` is the seconds a run may take before it is a timeout
    (``--run-budget`` overrides). On the command line it is ``--<flag>``, or ``--<flag> <choice>`` where
    several presets share a flag (the first listed is the flag's value when none is given); ``help`` says
    what it measures, its run count ``{size}`` counted from the plan (or by ``count(scene)``, where a plan
    predicts some of its runs); ``order`` places it in the help. ``scored`` False: its runs measure something
    other than accuracy (a stable step over a long run), so no front or accuracy table takes their errors."""

    name: str
    plan: Callable[..., list]
    budget: float
    scened: bool = False
    flag: str = ""
    choice: str | None = None
    help: str = ""
    order: float = 100.0
    count: Callable[[str], str] | None = None
    scored: bool = True

    def specs(self, scene: str = DEFAULT_SCENE) -> list:
        return self.plan(scene=scene) if self.scened else self.plan()

    def size(self, scene: str = DEFAULT_SCENE) -> str:
        """How many runs it makes on ``scene``, as its help says it."""
        return self.count(scene) if self.count else f"{len(self.specs(scene))} runs"

    @property
    def option(self) -> str:
        """Its words on the command line: ``--walls``, ``--stability long``."""
        return f"--{self.flag}" + (f" {self.choice}" if self.choice else "")


def _problem(preset: Preset) -> str | None:
    if not (callable(preset.plan) and preset.budget > 0 and preset.flag):
        return "a preset needs a plan, a budget > 0 s and a flag"
    return None


PRESETS = Registry(
    "preset",
    __package__,  # pcabench.studies: each study's plan.py
    Preset,
    group=ENTRY_POINT_GROUP,
    order=lambda p: (p.order, p.name),
    problem=_problem,
    role="plan",
    option="preset",
)


def size_text(name: str, scene: str = DEFAULT_SCENE) -> str:
    """How many runs preset ``name`` makes on ``scene``, as its help says it."""
    return PRESETS.get(name).size(scene)


def unscored() -> tuple[str, ...]:
    """The presets whose runs' errors are not accuracy results (:attr:`Preset.scored` False)."""
    return tuple(p.name for p in PRESETS.all().values() if not p.scored)


def budget(name: str) -> float:
    """The run budget of preset ``name`` (s), or a matrix's (``name`` "matrix")."""
    return MATRIX_BUDGET if name == "matrix" else PRESETS.get(name).budget


def preset(name: str, scene: str = DEFAULT_SCENE) -> list[RunSpec]:
    """The run matrix of preset ``name`` (the fronts on ``scene``), each spec carrying the preset's name (or its
    own tag, where the preset names its repeats: ``walls-cost-<round>``)."""
    specs = PRESETS.get(name).specs(scene)
    return [RunSpec(s.solver, s.scene, s.threads, s.preset or name, s.pair_loop) for s in specs]


def flags() -> dict[str, list[Preset]]:
    """{flag: its presets, in order}: the options ``pcabench study`` offers."""
    out: dict[str, list[Preset]] = {}
    for p in PRESETS.all().values():
        out.setdefault(p.flag, []).append(p)
    return out


def named_by(flag: str, value) -> str | None:
    """The preset ``--<flag> [value]`` names (``value`` True for a flag given alone), None if it names none."""
    for p in flags().get(flag, ()):
        if value is True or value == p.choice:
            return p.name
    return None


def matrix(
    solvers=(DEFAULT_SOLVER,),
    dxs=(),
    threads=(SERIAL,),
    steps=(None,),
    t_ends=(None,),
    strip=False,
    pair_loops=("auto",),
    **scene_lists,
) -> list[RunSpec]:
    """The product of the option lists, smallest N first, as run specs of preset ``matrix``.

    ``scene_lists`` maps Scene parameters (precision, model, integrator, cfl,
    h_factor, cutoff_factor, kernel) to lists; a parameter not given keeps Scene's
    default. ``steps`` and ``t_ends`` are lists too (give one of them; neither means the paper's 100
    steps). A pair loop or thread count that some solver of the matrix has is given to those that have it
    (the others run their own loop, serially); one that none has is bad input, named by the solver's
    check. A run the product names twice is listed once.
    """
    names = sorted(scene_lists)
    ends = [{"steps": n} for n in steps if n is not None] + [{"t_end": t} for t in t_ends if t is not None] or [{}]
    classes = [solver_class(name) for name in solvers]
    offered_loops = {loop for cls in classes for loop in cls.pair_loops}
    any_threaded = any(cls.threaded for cls in classes)
    runs = []
    for solver, dx, nthreads, loop, end, *values in itertools.product(
        solvers, sorted(dxs, reverse=True), threads, pair_loops, ends, *(scene_lists[k] for k in names)
    ):
        scene = dict(zip(names, values), dx=dx, **end)
        cls = solver_class(solver)
        if loop not in cls.pair_loops and loop in offered_loops:
            loop = "auto"  # a loop another solver of the matrix has: this one runs its own
        if nthreads != SERIAL and not cls.threaded and any_threaded:
            nthreads = SERIAL  # threads another solver of the matrix uses: this one runs serially
        spec = spec_of(solver, threads=nthreads, strip=strip, pair_loop=loop, **scene)
        runs.append(RunSpec(spec.solver, spec.scene, spec.threads, "matrix", spec.pair_loop))
    return list(dict.fromkeys(runs))
