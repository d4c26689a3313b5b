"""The cylinder study on a GPU: linkedlist-gpu against linkedlist-cpu on every scene kind with a body (the
workshop's cylinder), each ghost-particle boundary method, model and precision."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from pcabench.conformance import SCENES
from pcabench.gpu.agreement import agreement_stage, compare_cases
from pcabench.gpu.plan import card_cases

TITLE = "A rigid cylinder (ghost particles)"


@dataclass(frozen=True)
class Cases:
    """Every 2D scene kind with a body (the sphere's is the three-d stage's) at its card size (the workshop's cylinder
    at 5 particles a pulse width: 102,400 particles), each boundary method (its ghosts filled from the fluid on the
    host), model and precision."""

    scenes: tuple = field(default_factory=lambda: card_cases(lambda kind: kind.body and kind.dims == 2))
    methods: tuple = ("lattice", "rings")
    models: tuple = ("linear", "lagrangian")
    precisions: tuple = ("float64", "float32")


def cases(rehearse: bool) -> Cases:
    """A card's cases, or the rehearsal's: check-solver's cylinder (1,376 particles), one run a side."""
    return Cases((SCENES["cylinder"],), ("rings",), ("lagrangian",), ("float32",)) if rehearse else Cases()


def against_cpu(cases: Cases, steps: int, out: Path) -> list[dict]:
    """Each scene with a body ``steps`` steps on the GPU and the CPU, each boundary method, model and precision."""
    return compare_cases(
        cases.scenes, steps, out, boundary_method=cases.methods, model=cases.models, precision=cases.precisions
    )


STAGE = agreement_stage("body", TITLE, 50, lambda c: against_cpu(cases(c.rehearse), c.plan.compare_steps, c.out))
