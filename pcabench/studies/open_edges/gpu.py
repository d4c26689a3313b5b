"""The open-edges study on a GPU: linkedlist-gpu against linkedlist-cpu on every scene kind's open edges (free y
edges, the PML, the sponge), lagrangian, both precisions; then the layer's cost, the time per step closed and
open, alternating."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from pcabench.conformance import SCENES
from pcabench.execute.run import run
from pcabench.gpu.agreement import agrees, compare_cases
from pcabench.gpu.plan import card_cases
from pcabench.gpu.stage import Check, Stage
from pcabench.gpu.tables import scene_agreement
from pcabench.spec import RunSpec
from pcabench.store.record import STEP_STAGES
from solvers import GPU_SOLVER, PRECISIONS, Scene

TITLE = "Open edges (an absorbing layer)"


@dataclass(frozen=True)
class Cases:
    """Every scene kind's open card (SceneKind.card_open: the 2D pulse in a 24 m open square, the paper's pulse
    with open x edges) against the CPU; the cost's scenes (Scene fields), each closed and open, in ``rounds``
    of ``steps`` steps."""

    scenes: tuple = field(default_factory=lambda: card_cases(lambda kind: kind.card_open is not None, True))
    cost: tuple = ({"dx": 0.025, "open": "x"}, {"name": "acoustic-pulse", "dx": 0.05, "open": "xy"})
    cost_steps: int = 50
    cost_rounds: int = 3


def cases(rehearse: bool) -> Cases:
    """A card's cases, or the rehearsal's: check-solver's open square (free y edges and the PML), one small
    open strip's cost in one round."""
    if not rehearse:
        return Cases()
    return Cases((SCENES["acoustic-pulse-open"],), ({"dx": 1.0, "x_min": -8.0, "x_max": 8.0, "open": "x"},), 2, 1)


def against_cpu(cases: Cases, steps: int, out: Path) -> list[dict]:
    """Each open scene ``steps`` steps on the GPU and the CPU, lagrangian (the layer's particles moving), both
    precisions: their rows."""
    return compare_cases(cases.scenes, steps, out, model=("lagrangian",), precision=PRECISIONS)


def open_cost(cases: Cases) -> list[dict]:
    """linkedlist-gpu's time per step (SNP + PI + SU, s) of each cost scene closed and open, float32,
    lagrangian, in rounds that alternate which goes first; per scene the best of each side and their ratio."""
    best: dict = {}
    for i in range(cases.cost_rounds):
        for setting in cases.cost:
            pair = [{**setting, "open": ""}, setting][:: 1 if i % 2 == 0 else -1]
            for scene_args in pair:
                scene = Scene(**scene_args, steps=cases.cost_steps, precision="float32")
                rec = run(RunSpec(GPU_SOLVER, scene))
                if rec.status != "ok":
                    raise RuntimeError(f"{GPU_SOLVER} {scene.describe()}: {rec.status} {rec.message}")
                t = sum(rec.stages[s] for s in STEP_STAGES) / rec.steps
                key = (scene.name, scene.dx, scene.open, scene.absorber_used if scene.open else "")
                best[key] = min(best.get(key, (np.inf, 0)), (t, scene.n_particles))
    rows = []
    for (name, dx, edges, absorber), (t, n) in sorted(best.items()):
        closed = best[(name, dx, "", "")]
        if edges:
            rows.append(
                {"scene": name, "dx": dx, "open": edges, "absorber": absorber, "N": n, "closed_N": closed[1],
                 "step_ms": 1e3 * t, "closed_ms": 1e3 * closed[0], "ratio": t / closed[0]}
            )  # fmt: skip
    return rows


def check(c: Check) -> bool:
    mine = cases(c.rehearse)
    c.state["open"] = against_cpu(mine, c.plan.compare_steps, c.out)
    c.state["open_cost"] = open_cost(mine)
    return agrees(c.state["open"])


def report(results: dict) -> list[str]:
    lines = scene_agreement(TITLE, results["open"]) if results.get("open") else []
    if results.get("open_cost"):
        lines += [
            "",
            "## The open layer's cost on the GPU (linkedlist-gpu, float32, lagrangian; best of alternating rounds)",
            "",
            "| scene | dx | open | absorber | N closed | N open | ms / step closed | ms / step open | open / closed |",
            "|---|---|---|---|---|---|---|---|---|",
        ]
        lines += [
            f"| {r['scene']} | {r['dx']} | {r['open']} | {r['absorber']} | {r['closed_N']:,} | {r['N']:,} | "
            f"{r['closed_ms']:.4g} | {r['step_ms']:.4g} | {r['ratio']:.3f} |"
            for r in results["open_cost"]
        ]
    return lines


STAGE = Stage("open", 40, check, order=40, report=report)
