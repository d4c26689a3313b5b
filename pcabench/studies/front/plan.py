"""The speed-accuracy fronts (``--front quick``, ``--front full``): time to solution against error at t = 10 s, on
the strip, a 2D scene or a 3D one."""

from __future__ import annotations

import itertools

from pcabench.spec import RunSpec
from pcabench.studies.preset import Preset, spec_of
from pcabench.studies.protocols import FRONT_T_END
from solvers import Scene, kernel_names, scene_kind
from solvers.scenes import DEFAULT_SCENE

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


# The paper's own scene (dx = 0.05, full domain, t = 10 s): its method, and the methods the prediction names as
# the cheapest to its accuracy (pcabench/predict/methods.py: one per kernel, CFL at most MARGIN of the predicted
# stable).
PAPER_SCENE_DX = 0.05


def fast_methods(model: str) -> tuple[dict, ...]:
    """The cheapest methods predicted to reach the paper's configuration's accuracy on its scene at t = 10 s
    (the prediction is of the linear part; a moving model keeps a wider stability margin)."""
    from pcabench.predict.methods import fastest
    from solvers.reference.dispersion import predict

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
# The 3D pulse's front (its 16 m triply periodic cube, t = 10 s, serial): the 2D pulse's axes at the cube's
# sizes (dx 1 and 0.5: 4,096 and 32,768 particles) and at the smaller h a 3D neighbourhood affords (h 1.6 dx
# holds 4 pi / 3 (3 h / dx)^3 = 463 neighbours for the Gaussian; the paper's h 2.13 dx, 1,093, and a 3 h cutoff
# 19 m across at dx 1: wider than the cube's 3 cutoffs allow), the paper's method at dx 0.5 beside them.
FRONT_3D = {
    "quick": dict(
        h_factor=(1.3, 1.6),
        cfl=(0.2, 1.0, 3.0),
        dx=(1.0, 0.5),
        precision=("float64",),
        model=("linear", "lagrangian"),
    ),
    "full": dict(
        h_factor=(1.0, 1.3, 1.6),
        cfl=(0.2, 0.5, 1.0, 2.0, 3.0, 4.0),
        dx=(1.0, 0.5, 0.25),
        precision=("float64", "float32"),
        model=("linear", "lagrangian"),
    ),
}
PAPER_METHOD_3D_DX = (0.5,)
# a scene with a body: its runs against dx are its own study's (its dx must resolve the body)
BODY_STUDIES = {
    "cylinder": "`pcabench study --cylinder` (kernels and boundary methods against dx at the workshop's probes)",
    "sphere": "`pcabench study --three-d` (the high-order method against dx at the probes; `--three-d fine` the "
    "issue's dx 0.05)",
}
# Which model a scene needs: the paper's method at these amplitudes, linear against lagrangian, scored against
# the isothermal physics (its error floor for `linear` grows with the amplitude).
MODEL_MACH = (0.005, 0.05, 0.15)
MODEL_DX = {DEFAULT_SCENE: (0.2, 0.1), "acoustic-pulse": (0.25,)}


def model_needs(scene: str) -> list[RunSpec]:
    """Linear against lagrangian at several amplitudes, the paper's method, t = 10 s (a strip where it serves)."""
    strip = scene == DEFAULT_SCENE
    return [
        spec_of(name=scene, dx=dx, t_end=FRONT_T_END, model=model, mach=mach, strip=strip)
        for dx in MODEL_DX.get(scene, (0.25,))
        for mach in MODEL_MACH
        for model in ("linear", "lagrangian")
    ]


def front_axes(size: str = "quick", scene: str = DEFAULT_SCENE) -> dict:
    """The front's axes on ``scene``: every registered kernel (solvers/kernels/), then FRONT's (a scene a strip
    serves: the plane pulses), FRONT_3D's (a 3D scene) or FRONT_2D's."""
    kind = scene_kind(scene)
    return {"kernel": kernel_names(), **(FRONT if kind.strip else FRONT_3D if kind.dims == 3 else FRONT_2D)[size]}


def front(size: str = "quick", scene: str = DEFAULT_SCENE, fast: bool = True) -> list[RunSpec]:
    """Time to solution against error at t = 10 s: the product of FRONT[size] on the strip, smallest N first;
    then the paper's scene with its method and (``fast``) the predicted fastest ones, serial, in the same sweep.
    Another scene a strip serves (plane-wall): the same product on its strip (the paper's method is in it). Any
    other: its own product (FRONT_2D) on its own domain and the paper's method beside it. Then, on a scene with
    an isothermal reference, which model it needs at several amplitudes."""
    kind = scene_kind(scene)
    if kind.body:  # its dx must resolve the body: its front is its own study's (with the advised method)
        from solvers import SceneError

        study = BODY_STUDIES.get(scene, "its own study")
        raise SceneError(f"--front: the {scene} scene's runs against dx are {study}; advise reads them")
    axes = front_axes(size, scene)
    names = [k for k in axes if k != "dx"]
    runs = [
        spec_of(name=scene, dx=dx, t_end=FRONT_T_END, strip=kind.strip, **dict(zip(names, values)))
        for dx in sorted(axes["dx"], reverse=True)
        for values in itertools.product(*(axes[k] for k in names))
    ]
    if scene == DEFAULT_SCENE:
        for model in ("linear", "lagrangian"):
            if fast:
                runs += [spec_of(t_end=FRONT_T_END, model=model, **method) for method in fast_methods(model)]
            runs.append(spec_of(dx=PAPER_SCENE_DX, t_end=FRONT_T_END, model=model))
    elif not kind.strip:
        runs += [
            spec_of(name=scene, dx=dx, t_end=FRONT_T_END, model=model)
            for model in ("linear", "lagrangian")
            for dx in (PAPER_METHOD_3D_DX if kind.dims == 3 else PAPER_METHOD_2D_DX)
        ]
    return runs + (model_needs(scene) if kind.has_isothermal else [])


def front_full(scene: str = DEFAULT_SCENE) -> list[RunSpec]:
    return front("full", scene)


def _count(size: str):
    """The run count of the front of ``size`` on a scene, counted from the plan without predicting its fastest
    methods (one per kernel and model at most)."""

    def count(scene: str = DEFAULT_SCENE) -> str:
        fixed = len(front(size, scene, fast=False))
        if scene != DEFAULT_SCENE:
            return f"{fixed} runs"
        return f"{fixed} runs and up to {2 * len(kernel_names())} predicted fastest"

    return count


FRONT_HELP = (
    "kernel x h/dx x CFL x dx x precision x model on the strip, and the paper's scene (dx 0.05, full domain) "
    "with its method and the predicted fastest, serial"
)
FRONT_QUICK = Preset(
    "front",
    front,
    300.0,
    scened=True,
    flag="front",
    choice="quick",
    help="time to solution against error at t = 10 s: " + FRONT_HELP + " ({size} on the paper's scene)",
    order=40,
    count=_count("quick"),
)
FRONT_FULL = Preset(
    "front-full",
    front_full,
    900.0,
    scened=True,
    flag="front",
    choice="full",
    help="the same over more of every axis ({size} on the paper's scene)",
    order=41,
    count=_count("full"),
)
