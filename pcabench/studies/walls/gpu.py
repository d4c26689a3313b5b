"""The walls study on a GPU: linkedlist-gpu against linkedlist-cpu on every walled scene kind (mirror
particles), each wall model and precision."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from pcabench.conformance import SCENES
from pcabench.gpu.agreement import agreement_stage, compare_cases
from pcabench.gpu.plan import card_cases
from solvers import PRECISIONS

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
    """Each walled scene ``steps`` steps on the GPU and the CPU, each precision and wall model: their rows."""
    return compare_cases(cases.scenes, steps, out, precision=PRECISIONS, model=cases.models)


STAGE = agreement_stage("walls", TITLE, 20, lambda c: against_cpu(cases(c.rehearse), c.plan.compare_steps, c.out))
