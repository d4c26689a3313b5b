"""The walls study on a GPU: linkedlist-gpu against linkedlist-cpu on every walled scene kind (mirror
particles), each wall model and precision."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from pcabench.conformance import SCENES
from pcabench.gpu.agreement import agrees, gpu_against_cpu
from pcabench.gpu.plan import card_cases
from pcabench.gpu.stage import Check, Stage
from pcabench.gpu.tables import scene_agreement
from solvers import PRECISIONS, Scene

TITLE = "Rigid walls (mirror particles)"


@dataclass(frozen=True)
class Cases:
    """The walled scenes (Scene fields, name included): every scene kind with walls at its card size
    (SceneKind.card: a new walled kind is checked with no list to edit), each wall model: mirrors set once,
    mirrors following the particles."""

    scenes: tuple = field(default_factory=lambda: card_cases(lambda kind: bool(kind.walls)))
    models: tuple = ("linear", "lagrangian")


def cases(rehearse: bool) -> Cases:
    """A card's cases, or the rehearsal's: check-solver's 182-particle duct walled at both ends (both mirror
    branches), its mirrors following the particles: 2 runs, not 8 (~20 s each in the simulator)."""
    return Cases((SCENES["pulse-wall"],), ("lagrangian",)) if rehearse else Cases()


def against_cpu(cases: Cases, steps: int, out: Path) -> list[dict]:
    """Each walled scene ``steps`` steps on the GPU and the CPU, each wall model and precision: their rows."""
    return [
        gpu_against_cpu(Scene(**{**walled, "steps": steps, "model": model, "precision": precision}), out)
        for walled in cases.scenes
        for precision in PRECISIONS
        for model in cases.models
    ]


def check(c: Check) -> bool:
    c.state["walls"] = against_cpu(cases(c.rehearse), c.plan.compare_steps, c.out)
    return agrees(c.state["walls"])


def report(results: dict) -> list[str]:
    return scene_agreement(TITLE, results["walls"]) if results.get("walls") else []


STAGE = Stage("walls", 40, check, order=20, report=report)
