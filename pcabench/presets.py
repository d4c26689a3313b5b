"""Study matrices: the presets and the matrix built from command-line options.

Each preset lists the runs (:class:`~pcabench.spec.RunSpec`) its tables and
figures need, smallest first, so that a sweep can predict the cost of a large
run from the smaller ones before it. Scene defaults (h/dx, CFL, cutoff, integrator, the strip
rule) come from :class:`solvers.Scene`, never from here.
"""

from __future__ import annotations

import dataclasses
import itertools
from typing import Callable

from solvers import DEFAULT_SCENE, DEFAULT_SOLVER, Scene, kernel_names, scene_kind, solver_class

from .spec import ALL_CORES, SERIAL, RunSpec

MATRIX_BUDGET = 900.0  # s per run of a matrix of options (--dx ...), not a preset (--run-budget overrides)


# The stability preset's scene: the design's dx = 0.25 on a strip, the linear model
# (exactly the linear wave equation, so growth is the integrator's, not the physics').
STABILITY_DX = 0.25
STABILITY_CFL = (0.1, 0.2, 0.5, 1.0, 2.0, 2.5, 3.0, 4.0, 4.5, 5.0, 5.5, 6.0, 7.0)
STABILITY_H = (1.0, 1.3)  # h/dx beside Scene's default
# Above this relative RMS error a run that stayed bounded is classed inaccurate: twice the
# error of Verlet at CFL 0.2 on the stability scene (10 % at dx = 0.25, t = 10 s).
INACCURATE_ABOVE = 0.20
QUICK_CFL = (0.2, 2.0, 5.0, 7.0)  # the quick map: stable, stable, just past the predicted 4.97, far past it

# The long-run stability preset: the moving models' own limit, where their nonlinear terms (and, with free ends,
# the particles at the edges) can grow what the linear part keeps bounded, measured over runs long enough for
# round-off to grow. Two scenes: the paper's pulse on the stability strip, free ends in x (at Mach 0.01, so that it
# does not break before t = 300 s: 350 s; the pulse leaves by the free end long before, so that the run then tests
# the edges); and the 2D acoustic pulse in a 20 m periodic square, where the sound never leaves and never breaks.
# The linear model runs beside the moving ones on each: the control whose limit the prediction knows exactly.
LONG_SCENES = {
    "plane-pulse": dict(strip=True, mach=0.01),
    "acoustic-pulse": dict(x_min=-10.0, x_max=10.0, y_min=-10.0, y_max=10.0),
}
LONG_T_END = 300.0  # s: about 250 steps at CFL 4.7, dx 0.25
LONG_CFL = (4.4, 4.5, 4.6, 4.7, 4.75, 4.8, 4.9, 5.0)
LONG_MODELS = ("linear", "fixed", "lagrangian")


def _spec(solver=DEFAULT_SOLVER, threads=SERIAL, strip=False, pair_loop="auto", **scene) -> RunSpec:
    """One run; ``strip`` puts it on the thinnest y-periodic strip Scene accepts."""
    if strip:
        scene["strip_height"] = Scene.thinnest_strip(
            scene["dx"], scene.get("cutoff_factor"), scene.get("h_factor"), scene.get("kernel")
        )
    return RunSpec(solver, Scene(**scene), threads, pair_loop=pair_loop)


def quick() -> list[RunSpec]:
    """A few minutes on a laptop CPU: every table and figure at small N."""
    runs = []
    # Table 4/5, Figs. 10, 11, 13: the paper's scene (lagrangian, full domain)
    runs += [_spec(dx=dx, steps=20) for dx in (1.0, 0.5, 0.25)]
    # Fig. 9: all-pair against linked list (0.125 is predicted past the budget and skipped)
    runs += [_spec("allpair-cpu", dx=dx, steps=20) for dx in (1.0, 0.5, 0.25, 0.125)]
    # Fig. 8 at a fixed physical time and at the paper's 100 steps, on the strip
    for model in ("linear", "lagrangian"):
        for dx in (0.4, 0.2, 0.1) + ((0.05,) if model == "linear" else ()):
            runs.append(_spec(dx=dx, t_end=10.0, model=model, strip=True))
        for dx in (0.4, 0.2, 0.1):
            runs.append(_spec(dx=dx, steps=100, model=model, strip=True))
    # The cost of each simplification: fixed particles, float32, and the full domain
    for dx in (0.2, 0.1):
        runs.append(_spec(dx=dx, t_end=10.0, model="fixed", strip=True))
        runs.append(_spec(dx=dx, t_end=10.0, model="linear", precision="float32", strip=True))
    runs.append(_spec(dx=0.2, t_end=10.0, model="linear"))
    runs.append(_spec(dx=0.2, t_end=10.0, model="lagrangian"))
    # The stability map: Verlet on the stability scene at a few CFLs, up to past its limit
    runs += [_spec(dx=STABILITY_DX, t_end=10.0, model="linear", strip=True, cfl=cfl) for cfl in QUICK_CFL]
    # Another scene: the 2D acoustic pulse, linear and lagrangian, at the default amplitude and a small one
    runs += [
        _spec(name="acoustic-pulse", dx=0.5, t_end=10.0, model=model, mach=mach)
        for mach in (Scene.default("mach"), 0.005)
        for model in ("linear", "lagrangian")
    ]
    return runs


def paper() -> list[RunSpec]:
    """The paper's CPU matrix (Tables 4-6, Figs. 8-14), as far as the budgets allow."""
    runs = []
    for dx in (1.0, 0.5, 0.25, 0.2, 0.1, 0.05, 0.025):  # 1K .. 1.6M; Table 6 at 25K/100K/400K
        runs.append(_spec(dx=dx, steps=100))
        runs.append(_spec(dx=dx, steps=100, threads=ALL_CORES))
        runs.append(_spec(dx=dx, steps=20, pair_loop="gather"))  # the paper's loop, for Table 4
    # Fig. 9 (the paper's 10th step, 1K .. 256K)
    for dx in (1.0, 0.5, 0.25, 0.125, 0.0625):
        runs.append(_spec(dx=dx, steps=10))
        runs.append(_spec("allpair-cpu", dx=dx, steps=10))
    for model in ("linear", "fixed", "lagrangian"):
        for precision in ("float64", "float32"):
            for dx in (0.4, 0.2, 0.1, 0.05, 0.025):
                runs.append(_spec(threads=ALL_CORES, dx=dx, t_end=10.0, model=model, precision=precision, strip=True))
            for dx in (0.1, 0.05, 0.01, 0.004):
                runs.append(_spec(threads=ALL_CORES, dx=dx, steps=100, model=model, precision=precision, strip=True))
        for dx in (0.2, 0.1):
            runs.append(_spec(threads=ALL_CORES, dx=dx, t_end=10.0, model=model))
    return runs


def stability() -> list[RunSpec]:
    """Where methods fail: CFL x integrator, CFL x h/dx, run length, float32 at small dx."""
    runs = []
    base = dict(dx=STABILITY_DX, model="linear", strip=True)
    for integrator in ("verlet", "rk2", "kdk1", "euler"):
        for cfl in STABILITY_CFL:
            runs.append(_spec(t_end=10.0, integrator=integrator, cfl=cfl, **base))
    for h_factor in STABILITY_H:
        for cfl in STABILITY_CFL:
            runs.append(_spec(t_end=10.0, cfl=cfl, h_factor=h_factor, **base))
    for cfl in (0.2, 1.0, 4.0):
        runs.append(_spec(t_end=10.0, cfl=cfl, precision="float32", **base))
    # run length: to t = 30 s (the pulse is then 10 m short of the free right edge)
    for integrator in ("verlet", "rk2", "kdk1", "euler"):
        runs.append(_spec(t_end=30.0, integrator=integrator, cfl=0.2, **base))
    runs.append(_spec(t_end=30.0, cfl=4.0, **base))
    # float32 against float64 at the paper's protocol down to its smallest dx
    for dx in (0.04, 0.01, 0.004):
        for precision in ("float64", "float32"):
            runs.append(_spec(threads=ALL_CORES, dx=dx, steps=100, model="lagrangian", precision=precision, strip=True))
    return runs


def stability_long() -> list[RunSpec]:
    """Each model of the paper's method at the CFLs around its predicted limit, to t = 300 s (dx = 0.25), on
    each scene of LONG_SCENES."""
    return [
        _spec(name=scene, dx=STABILITY_DX, t_end=LONG_T_END, model=model, cfl=cfl, **setting)
        for scene, setting in LONG_SCENES.items()
        for model in LONG_MODELS
        for cfl in LONG_CFL
    ]


# The walls preset (issue 34, ``pcabench study --walls``): sound at a rigid wall, in three parts.
WALLS = "walls"
# 1. Accuracy at t = 10 s, the paper's method, linear (where the prediction on the mirror extension holds) and
# lagrangian; plane-wall on the thinnest strip as the paper's scene's accuracy runs.
WALL_ACCURACY_DX = {"plane-wall": (0.5, 0.25, 0.125), "pulse-wall": (0.5, 0.25)}
WALL_STRIP = {"plane-wall": True, "pulse-wall": False}  # the plane scene's fields do not depend on y
# 2. Stability at the wall, as the long-run preset measures it (LONG_T_END, STABILITY_DX: long enough for round-off
# to grow): the linear model of every registered kernel at an h the front uses, at CFLs bracketing its predicted
# limit, and the paper's method in every model at the long runs' CFLs either side of the free ends' limit (4.8 on
# the plane strip) and the prediction (4.97), so that each compares one to one with the free and periodic long runs.
# plane-wall at Mach 0.01 (as LONG_SCENES: it must not break before t = 300 s); pulse-wall never breaks.
WALL_STABILITY_MACH = {"plane-wall": 0.01, "pulse-wall": None}
WALL_LINEAR_METHODS = (("gaussian", 1.3), ("wendland-c2", 2.13), ("wendland-c4", 2.13))  # (kernel, h/dx)
WALL_BRACKET = (0.95, 1.02)  # CFLs as fractions of the method's predicted stable CFL, rounded to 0.01
WALL_PAPER_CFL = (4.75, 4.9, 5.0)
# 3. Cost: time per step with and without the wall at the same N, the paper's timing model (lagrangian) on the
# default CPU solver, serially: each wall scene against its free counterpart on the same box, in rounds that
# alternate which goes first; each round's runs carry their own preset tag (``walls-cost-<round>``) so that the
# store keeps every repeat, and the report takes the best of each side. Runs of WALL_COST_TIME of physical time
# (the pulse still inside the box), as a step count: a timing, not an accuracy run.
FREE_COUNTERPART = {"pulse-wall": "acoustic-pulse", "plane-wall": "plane-pulse"}  # the same pulse without walls
WALL_COST_DX = {"pulse-wall": (0.25, 0.125), "plane-wall": (0.125, 0.0625)}
WALL_COST_ROUNDS = 3
WALL_COST_TIME = 5.0  # s
WALL_COST_TAG = WALLS + "-cost-"


def cost_round(preset_name: str) -> int | None:
    """The round of a walls cost run from its preset tag (``walls-cost-2`` -> 2), None for any other preset."""
    tail = str(preset_name).removeprefix(WALL_COST_TAG)
    return int(tail) if tail != str(preset_name) and tail.isdigit() else None


def walls() -> list[RunSpec]:
    """Accuracy, stability and cost at a rigid wall (WALL_*): 64 runs, 34 min on one busy core of the reference
    machine (about 30 s of each run is its JIT compilation)."""
    from solvers.dispersion import stable_cfl

    runs = [
        _spec(name=name, dx=dx, t_end=FRONT_T_END, model=model, strip=WALL_STRIP[name])
        for name, dxs in WALL_ACCURACY_DX.items()
        for model in ("linear", "lagrangian")
        for dx in dxs
    ]
    for name, mach in WALL_STABILITY_MACH.items():
        base = dict(name=name, dx=STABILITY_DX, t_end=LONG_T_END, strip=WALL_STRIP[name])
        if mach is not None:
            base["mach"] = mach
        for kernel, h in WALL_LINEAR_METHODS:
            limit = stable_cfl(Scene(dx=1.0, kernel=kernel, h_factor=h, model="linear"))
            runs += [
                _spec(kernel=kernel, h_factor=h, model="linear", cfl=round(f * limit, 2), **base) for f in WALL_BRACKET
            ]
        runs += [_spec(model=model, cfl=cfl, **base) for model in LONG_MODELS for cfl in WALL_PAPER_CFL]
    for i in range(1, WALL_COST_ROUNDS + 1):
        for name, dxs in WALL_COST_DX.items():
            free = FREE_COUNTERPART[name]
            for dx in dxs:
                wall = Scene(dx=dx, name=name)
                box = dict(x_min=wall.x_min, x_max=wall.x_max, y_min=wall.y_min, y_max=wall.y_max)
                steps = int(round(WALL_COST_TIME / (Scene.default("cfl") * dx)))
                pair = [
                    _spec(name=name, dx=dx, steps=steps, strip=WALL_STRIP[name]),
                    _spec(name=free, dx=dx, steps=steps, strip=WALL_STRIP[name], **box),
                ]
                runs += [dataclasses.replace(s, preset=f"{WALL_COST_TAG}{i}") for s in pair[:: 1 if i % 2 else -1]]
    return runs


# The speed-accuracy front at t = 10 s on the strip, serial: kernel x h/dx x CFL x dx x precision x model, the
# kernels every registered one (:func:`front_axes`). CFL 6 is past every configuration's predicted stable step:
# the front shows where methods fail.
FRONT = {
    "quick": dict(
        h_factor=(1.3, 2.13),
        cfl=(0.2, 1.0, 3.0, 6.0),
        dx=(0.4, 0.2, 0.1),
        precision=("float64", "float32"),
        model=("linear", "lagrangian"),
    ),
    "full": dict(
        h_factor=(1.0, 1.3, 1.6, 2.13, 2.6),
        cfl=(0.2, 0.5, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0),
        dx=(0.4, 0.2, 0.1, 0.05, 0.025),
        precision=("float64", "float32"),
        model=("linear", "lagrangian"),
    ),
}
FRONT_T_END = 10.0


# The paper's own scene (dx = 0.05, full domain, t = 10 s): its method, and the methods the prediction names as
# the cheapest to its accuracy (pcabench/methods.py: one per kernel, CFL at most MARGIN of the predicted stable).
PAPER_SCENE_DX = 0.05


def fast_methods(model: str) -> tuple[dict, ...]:
    """The cheapest methods predicted to reach the paper's configuration's accuracy on its scene at t = 10 s
    (the prediction is of the linear part; a moving model keeps a wider stability margin)."""
    from solvers.dispersion import predict

    from .methods import fastest

    paper = predict(Scene(dx=PAPER_SCENE_DX, t_end=FRONT_T_END, model="linear"))
    return tuple(
        {k: m[k] for k in ("kernel", "h_factor", "cfl", "dx")}
        for m in fastest(paper.predicted_error, FRONT_T_END, model)
    )


# The 2D acoustic pulse's front (40 m periodic square, t = 10 s, serial): no strip (the pulse spreads in y), so
# fewer and coarser runs; the paper's method at dx 0.1 beside them. CFL 3 is past the stable step of h = 1.3 dx.
# The kernels: every registered one, as on the strip.
FRONT_2D = {
    "quick": dict(
        h_factor=(1.3, 2.13),
        cfl=(0.2, 1.0, 3.0),
        dx=(0.5, 0.25, 0.125),
        precision=("float64",),
        model=("linear", "lagrangian"),
    ),
    "full": dict(
        h_factor=(1.0, 1.3, 1.6, 2.13),
        cfl=(0.2, 0.5, 1.0, 2.0, 3.0, 4.0),
        dx=(0.5, 0.25, 0.125, 0.1),
        precision=("float64", "float32"),
        model=("linear", "lagrangian"),
    ),
}
PAPER_METHOD_2D_DX = (0.2, 0.1)
# Which model a scene needs: the paper's method at these amplitudes, linear against lagrangian, scored against
# the isothermal physics (its error floor for `linear` grows with the amplitude).
MODEL_MACH = (0.005, 0.05, 0.15)
MODEL_DX = {DEFAULT_SCENE: (0.2, 0.1), "acoustic-pulse": (0.25,)}


def model_needs(scene: str) -> list[RunSpec]:
    """Linear against lagrangian at several amplitudes, the paper's method, t = 10 s (a strip where it serves)."""
    strip = scene == DEFAULT_SCENE
    return [
        _spec(name=scene, dx=dx, t_end=FRONT_T_END, model=model, mach=mach, strip=strip)
        for dx in MODEL_DX.get(scene, (0.25,))
        for mach in MODEL_MACH
        for model in ("linear", "lagrangian")
    ]


def front_axes(size: str = "quick", scene: str = DEFAULT_SCENE) -> dict:
    """The front's axes on ``scene``: every registered kernel (solvers/kernels/), then FRONT's (a scene a strip
    serves: the plane pulses) or FRONT_2D's."""
    return {"kernel": kernel_names(), **(FRONT if scene_kind(scene).strip else FRONT_2D)[size]}


def front(size: str = "quick", scene: str = DEFAULT_SCENE, fast: bool = True) -> list[RunSpec]:
    """Time to solution against error at t = 10 s: the product of FRONT[size] on the strip, smallest N first;
    then the paper's scene with its method and (``fast``) the predicted fastest ones, serial, in the same sweep.
    Another scene a strip serves (plane-wall): the same product on its strip (the paper's method is in it). Any
    other: its own product (FRONT_2D) on its own domain and the paper's method beside it. Then, on a scene with
    an isothermal reference, which model it needs at several amplitudes."""
    kind = scene_kind(scene)
    axes = front_axes(size, scene)
    names = [k for k in axes if k != "dx"]
    runs = [
        _spec(name=scene, dx=dx, t_end=FRONT_T_END, strip=kind.strip, **dict(zip(names, values)))
        for dx in sorted(axes["dx"], reverse=True)
        for values in itertools.product(*(axes[k] for k in names))
    ]
    if scene == DEFAULT_SCENE:
        for model in ("linear", "lagrangian"):
            if fast:
                runs += [_spec(t_end=FRONT_T_END, model=model, **method) for method in fast_methods(model)]
            runs.append(_spec(dx=PAPER_SCENE_DX, t_end=FRONT_T_END, model=model))
    elif not kind.strip:
        runs += [
            _spec(name=scene, dx=dx, t_end=FRONT_T_END, model=model)
            for model in ("linear", "lagrangian")
            for dx in PAPER_METHOD_2D_DX
        ]
    return runs + (model_needs(scene) if kind.has_isothermal else [])


def size_text(name: str, scene: str = DEFAULT_SCENE) -> str:
    """How many runs preset ``name`` makes on ``scene``, as its help says it: counted from the plan itself (the
    fronts' predicted fastest methods, one per kernel and model at most, without predicting them)."""
    if name.startswith("front"):
        size = "full" if name == "front-full" else "quick"
        fixed = len(front(size, scene, fast=False))
        if scene != DEFAULT_SCENE:
            return f"{fixed} runs"
        return f"{fixed} runs and up to {2 * len(kernel_names())} predicted fastest"
    return f"{len(PRESETS[name].specs(scene))} runs"


def front_full(scene: str = DEFAULT_SCENE) -> list[RunSpec]:
    return front("full", scene)


@dataclasses.dataclass(frozen=True)
class Preset:
    """A named study: ``plan`` makes its runs (RunSpecs, smallest first, so that a sweep predicts a large run from
    the smaller ones before it; a front's takes ``scene=``), ``budget`` is the seconds a run may take before it is
    a timeout (``--run-budget`` overrides). Its run count is counted from the plan (:func:`size_text`)."""

    name: str
    plan: Callable[..., list]
    budget: float
    scened: bool = False  # whether the plan takes the scene it runs on (the fronts)

    def specs(self, scene: str = DEFAULT_SCENE) -> list:
        return self.plan(scene=scene) if self.scened else self.plan()


PRESETS = {  # what `pcabench study` offers; a preset of one's own: PRESETS[p.name] = p (CONTRIBUTING.md)
    p.name: p
    for p in (
        Preset("quick", quick, 120.0),
        Preset("paper", paper, 900.0),
        Preset("stability", stability, 120.0),
        Preset("stability-long", stability_long, 300.0),
        Preset("front", front, 300.0, scened=True),
        Preset("front-full", front_full, 900.0, scened=True),
        Preset(WALLS, walls, 300.0),
    )
}


def budget(name: str) -> float:
    """The run budget of preset ``name`` (s), or a matrix's (``name`` "matrix")."""
    return MATRIX_BUDGET if name == "matrix" else PRESETS[name].budget


def preset(name: str, scene: str = DEFAULT_SCENE) -> list[RunSpec]:
    """The run matrix of preset ``name`` (the fronts on ``scene``), each spec carrying the preset's name (or its
    own tag, where the preset names its repeats: ``walls-cost-<round>``)."""
    if name not in PRESETS:
        raise ValueError(f"preset must be one of {', '.join(PRESETS)} (got {name!r})")
    specs = PRESETS[name].specs(scene)
    return [RunSpec(s.solver, s.scene, s.threads, s.preset or name, s.pair_loop) for s in specs]


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
        spec = _spec(solver, threads=nthreads, strip=strip, pair_loop=loop, **scene)
        runs.append(RunSpec(spec.solver, spec.scene, spec.threads, "matrix", spec.pair_loop))
    return list(dict.fromkeys(runs))
