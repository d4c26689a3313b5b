"""What a stage of the GPU check is, what the stages share, and the registry of the studies' stages.

The check's own stages (the profile, the paper's scene against the CPU, the sweep, the CUDA graph, the CPU
peers, asv, the benchmarks, the GPU tests, Nsight Compute) are in check.py. A study checks its own scenes on a
GPU with a stage in its folder, ``pcabench/studies/<study>/gpu.py`` (found by :data:`STAGES`): the walled scene
kinds, the open edges, the cylinder, high-order SPH. A stage's ``order`` places it among all of them, in order
of value; its ``report`` writes its part of the check's Markdown from the check's results.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Callable

from pcabench.gpu.plan import Budget, Plan
from solvers.plugins import Registry


@dataclass
class Check:
    """What the stages share: the plan, where they write, the budget, and the results so far (``state``)."""

    plan: Plan
    out: Path
    budget: Budget
    state: dict
    profile: dict
    cupy: object  # CuPy on a GPU, None in the simulator
    store_path: Path
    rehearse: bool  # the simulator's few hundred particles: each study's stage takes its rehearsal's cases
    env: dict  # the environment of the stages' child processes


@dataclass(frozen=True)
class Stage:
    """One stage of the check: it runs if ``need_s`` seconds are left; ``work(check)`` returns False when it
    failed (an exception fails it too, and the next stage still runs); ``order`` its place in the check (the
    check's own: 0 to 120, by tens); ``report(results)`` its Markdown lines ([] when it has nothing)."""

    name: str
    need_s: float
    work: Callable[[Check], object]
    order: float = 1000.0
    report: Callable[[dict], list[str]] | None = None


def _problem(stage: Stage) -> str | None:
    if not (callable(stage.work) and stage.need_s >= 0):
        return "a GPU stage needs a callable work and need_s >= 0 s"
    return None


STAGES = Registry(
    "GPU stage",
    "pcabench.studies",  # each study's gpu.py
    Stage,
    order=lambda s: (s.order, s.name),
    problem=_problem,
    role="gpu",
)
