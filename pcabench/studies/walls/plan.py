"""Sound at a rigid wall (``--walls``): accuracy, stability and cost at a wall."""

from __future__ import annotations

import dataclasses

from pcabench.spec import RunSpec
from pcabench.studies.preset import Preset, spec_of
from pcabench.studies.protocols import FRONT_T_END, LONG_MODELS, LONG_T_END, STABILITY_DX
from solvers import Scene

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
WALL_LINEAR_METHODS = (
    ("gaussian", 1.3),
    ("laguerre-gauss", 1.5),
    ("laguerre-gauss-6", 1.5),
    ("wendland-c2", 2.13),
    ("wendland-c4", 2.13),
)  # (kernel, h/dx)
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
    """Accuracy, stability and cost at a rigid wall (WALL_*): 68 runs, 34 min on one busy core of the reference
    machine (about 30 s of each run is its JIT compilation)."""
    from solvers.reference.dispersion import predicted_stable_cfl

    runs = [
        spec_of(name=name, dx=dx, t_end=FRONT_T_END, model=model, strip=WALL_STRIP[name])
        for name, dxs in WALL_ACCURACY_DX.items()
        for model in ("linear", "lagrangian")
        for dx in dxs
    ]
    for name, mach in WALL_STABILITY_MACH.items():
        base = dict(name=name, dx=STABILITY_DX, t_end=LONG_T_END, strip=WALL_STRIP[name])
        if mach is not None:
            base["mach"] = mach
        for kernel, h in WALL_LINEAR_METHODS:
            limit = predicted_stable_cfl(Scene(dx=1.0, kernel=kernel, h_factor=h, model="linear"))
            runs += [
                spec_of(kernel=kernel, h_factor=h, model="linear", cfl=round(f * limit, 2), **base)
                for f in WALL_BRACKET
            ]
        runs += [spec_of(model=model, cfl=cfl, **base) for model in LONG_MODELS for cfl in WALL_PAPER_CFL]
    for i in range(1, WALL_COST_ROUNDS + 1):
        for name, dxs in WALL_COST_DX.items():
            free = FREE_COUNTERPART[name]
            for dx in dxs:
                wall = Scene(dx=dx, name=name)
                box = dict(x_min=wall.x_min, x_max=wall.x_max, y_min=wall.y_min, y_max=wall.y_max)
                steps = int(round(WALL_COST_TIME / (Scene.default("cfl") * dx)))
                pair = [
                    spec_of(name=name, dx=dx, steps=steps, strip=WALL_STRIP[name]),
                    spec_of(name=free, dx=dx, steps=steps, strip=WALL_STRIP[name], **box),
                ]
                runs += [dataclasses.replace(s, preset=f"{WALL_COST_TAG}{i}") for s in pair[:: 1 if i % 2 else -1]]
    return runs


WALLS_PRESET = Preset(
    WALLS,
    walls,
    300.0,
    flag="walls",
    help="sound at a rigid wall (plane-wall, pulse-wall): accuracy at t = 10 s against the prediction, the "
    "stable CFL per kernel over long runs, and the time per step with and without the wall ({size})",
    order=50,
)
