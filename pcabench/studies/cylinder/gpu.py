"""The cylinder study on a GPU: linkedlist-gpu against linkedlist-cpu on every scene kind with a body (the
workshop's cylinder), each ghost-particle boundary method, model and precision."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from pcabench.conformance import SCENES
from pcabench.gpu.agreement import agrees, gpu_against_cpu
from pcabench.gpu.plan import card_cases
from pcabench.gpu.stage import Check, Stage
from pcabench.gpu.tables import scene_agreement
from solvers import Scene

TITLE = "A rigid cylinder (ghost particles)"


@dataclass(frozen=True)
class Cases:
    """Every scene kind with a body at its card size (the workshop's cylinder at 5 particles a pulse width:
    102,400 particles), each boundary method (its ghosts filled from the fluid on the host), model and
    precision."""

    scenes: tuple = field(default_factory=lambda: card_cases(lambda kind: kind.body))
    methods: tuple = ("lattice", "rings")
    models: tuple = ("linear", "lagrangian")
    precisions: tuple = ("float64", "float32")


def cases(rehearse: bool) -> Cases:
    """A card's cases, or the rehearsal's: check-solver's cylinder (1,376 particles), one run a side."""
    return Cases((SCENES["cylinder"],), ("rings",), ("lagrangian",), ("float32",)) if rehearse else Cases()


def against_cpu(cases: Cases, steps: int, out: Path) -> list[dict]:
    """Each scene with a body ``steps`` steps on the GPU and the CPU, each boundary method, model and precision."""
    return [
        gpu_against_cpu(
            Scene(**{**scene, "steps": steps, "boundary_method": method, "model": model, "precision": precision}),
            out,
        )
        for scene in cases.scenes
        for method in cases.methods
        for model in cases.models
        for precision in cases.precisions
    ]


def check(c: Check) -> bool:
    c.state["body"] = against_cpu(cases(c.rehearse), c.plan.compare_steps, c.out)
    return agrees(c.state["body"])


def report(results: dict) -> list[str]:
    return scene_agreement(TITLE, results["body"]) if results.get("body") else []


STAGE = Stage("body", 40, check, order=50, report=report)
