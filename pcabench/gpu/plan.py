"""What the GPU check's stages run and within what time: a :class:`Plan` (the paper study's full plan, sized on
the H100 run, and its rehearsal's are in pcabench/studies/paper/gpu.py, which the command line hands the check),
and the budget each stage is given. A study's stage sizes its own cases in its folder
(``pcabench/studies/<study>/gpu.py``), from the scene kinds' card sizes (:func:`card_cases`)."""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass, field

RESERVE_S = 25.0  # kept back from every stage for the reports and the tarball


def card_cases(which, open_edges: bool = False) -> tuple:
    """The GPU check's cases on a card (Scene fields, name included): each registered scene kind ``which``
    selects, at its card size (SceneKind.card, or with open edges SceneKind.card_open)."""
    from solvers import scenes

    return tuple(
        {"name": name, **(kind.card_open if open_edges else kind.card)}
        for name, kind in scenes().items()
        if which(kind)
    )


@dataclass(frozen=True)
class Plan:
    """What the check runs and at what size: the GPU sweep's sizes, models and steps and its CPU peers' (the
    paper study's, pcabench/studies/paper/gpu.py), the rest the check's own."""

    gpu_dx: tuple
    models: tuple
    min_steps: int  # steps of the biggest runs; smaller ones take up to max_steps (see gpu_steps)
    max_steps: int
    cpu_dx: tuple
    cpu_steps: int
    compare_dx: float = 0.5
    compare_steps: int = 20
    graph_dx: tuple = (0.1, 0.025, 0.01)  # 100K, 1.6M, 10M
    graph_steps: int = 50
    graph_rounds: int = 5
    scene: dict = field(default_factory=dict)  # Scene overrides (the rehearsal's small domain)
    asv_bench: str = "TimeGPUStep"
    ncu_dx: float = 0.01


class Budget:
    """Seconds left of the check's budget, with progress lines that say where it stands."""

    def __init__(self, seconds: float):
        self.seconds, self.t0 = seconds, time.perf_counter()

    def elapsed(self) -> float:
        return time.perf_counter() - self.t0

    def left(self) -> float:
        return self.seconds - self.elapsed() - RESERVE_S

    def say(self, text: str) -> None:
        print(f"[gpu-check {self.elapsed():6.1f} s of {self.seconds:.0f}] {text}", file=sys.stderr, flush=True)
