"""Sound in the open (``--open``): what an open edge leaves behind, what its layer costs, whether it is stable."""

from __future__ import annotations

import dataclasses

from pcabench.studies.preset import Preset, spec_of
from pcabench.studies.protocols import LONG_SCENES, LONG_T_END, STABILITY_DX
from solvers import Scene

# The open-edges preset (issue 41, ``pcabench study --open``), in four parts.
OPEN = "open"
# 1. What the edges leave behind once the pulse has gone, against the open problem's exact solution, for each
# absorber, layer width (in pulse widths) and strength (in c0 / L), linear at 12 particles a pulse width:
# normal incidence (the plane pulse on the thinnest strip, both x edges open, t = 64 s: it left x = 40 m at
# t ~ 45 s and what the layer's outer end sends back is in the domain) and oblique incidence (the 2D pulse in a
# 24 m square, all four edges open, t = 28 s: its front has passed the corners by three pulse widths). The closed
# scenes for contrast: the plane pulse's free end, the 2D pulse's periodic square (its images come back).
OPEN_SCENES = {
    "plane-pulse": dict(open="x", strip=True, t_end=64.0),
    "acoustic-pulse": dict(open="xy", x_min=-12.0, x_max=12.0, y_min=-12.0, y_max=12.0, t_end=28.0),
}
OPEN_DX = 0.25
OPEN_ABSORBERS = ("sponge", "pml")
LAYER_PULSE_WIDTHS = (1.0, 1.5, 2.0, 3.0)  # 1.5: the sponge's default, 2: the PML's
LAYER_STRENGTHS = (8.0, 12.0, 24.0)  # c0 / L
# 2. Resolution: each absorber's default layer at half and twice the particles a pulse width (the 2D pulse).
OPEN_RESOLUTION_DX = (0.5, 0.125)
# 3. Cost: time per step of the paper's scene (full domain, dx 0.1, lagrangian, serial) closed and with its x
# edges open by each absorber's default layer, and of the 2D pulse's 40 m square closed and open (the PML), in
# rounds that alternate the order; each round's runs carry their own preset tag (``open-cost-<round>``) so that
# the store keeps every repeat and the report takes the best of each. OPEN_COST_STEPS steps: a timing.
OPEN_COST = {"plane-pulse": (0.1, "x", OPEN_ABSORBERS), "acoustic-pulse": (0.2, "xy", ("pml",))}
OPEN_COST_ROUNDS = 3
OPEN_COST_STEPS = 40
OPEN_COST_TAG = OPEN + "-cost-"
# 4. Stability: the long runs of ``--stability long`` (LONG_SCENES, t = 300 s, dx 0.25) with the edges open, the
# paper's method in the linear and lagrangian models from CFL 3 past the closed scenes' limit (4.75-4.9) to the
# prediction's (4.97): the layer's damping, a term of each update (solvers/boundaries/absorbers/base.py), keeps the
# closed scene's limit (the damping after the step, before 2026-12-05, blew up from 4).
OPEN_LONG_CFL = (3.0, 3.25, 3.5, 3.75, 4.0, 4.4, 4.6, 4.75, 4.8, 4.9, 5.0)
OPEN_LONG_MODELS = ("linear", "lagrangian")
OPEN_LONG_EDGES = {"plane-pulse": "x", "acoustic-pulse": "xy"}


def open_cost_round(preset_name: str) -> int | None:
    """The round of an open-edges cost run from its preset tag (``open-cost-2`` -> 2), None for any other."""
    tail = str(preset_name).removeprefix(OPEN_COST_TAG)
    return int(tail) if tail != str(preset_name) and tail.isdigit() else None


def open_edges() -> list:
    """What the open edges leave, cost and hold (OPEN_*), smallest runs first within each part."""
    runs = []
    for name, setting in OPEN_SCENES.items():
        base = dict(name=name, dx=OPEN_DX, model="linear", **setting)
        closed = {k: v for k, v in base.items() if k != "open"}
        runs.append(spec_of(**closed))
        width = Scene.default("pulse_width")
        for absorber in OPEN_ABSORBERS:
            for n in LAYER_PULSE_WIDTHS:
                for c in LAYER_STRENGTHS:
                    layer = n * width
                    runs.append(spec_of(absorber=absorber, layer_width=layer, absorber_strength=c / layer, **base))
    square = dict(name="acoustic-pulse", model="linear", **OPEN_SCENES["acoustic-pulse"])
    for dx in OPEN_RESOLUTION_DX:
        runs += [spec_of(dx=dx, absorber=absorber, **square) for absorber in OPEN_ABSORBERS]
    for i in range(1, OPEN_COST_ROUNDS + 1):
        rounds = []
        for name, (dx, edges, absorbers) in OPEN_COST.items():
            rounds.append(spec_of(name=name, dx=dx, steps=OPEN_COST_STEPS))
            rounds += [spec_of(name=name, dx=dx, steps=OPEN_COST_STEPS, open=edges, absorber=a) for a in absorbers]
        runs += [dataclasses.replace(s, preset=f"{OPEN_COST_TAG}{i}") for s in rounds[:: 1 if i % 2 else -1]]
    for name, setting in LONG_SCENES.items():
        for model in OPEN_LONG_MODELS:
            runs += [
                spec_of(
                    name=name,
                    dx=STABILITY_DX,
                    t_end=LONG_T_END,
                    model=model,
                    cfl=cfl,
                    open=OPEN_LONG_EDGES[name],
                    **setting,
                )
                for cfl in OPEN_LONG_CFL
            ]
    return runs


OPEN_PRESET = Preset(
    OPEN,
    open_edges,
    300.0,
    flag="open",
    help="sound in the open: what open edges (each absorber, layer width and strength) leave behind at normal "
    "and oblique incidence, the layer's cost per step and its stable CFL over long runs ({size})",
    order=55,
)
