"""The high-order study on a GPU: linkedlist-gpu against linkedlist-cpu with the kernel gradient correction and
the Laguerre-Gauss kernel, on the plane pulse with RK4 and on the cylinder with its weak wall (no ghosts), each
model and precision."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from pcabench.conformance import SCENES
from pcabench.gpu.agreement import agreement_stage, compare_cases

TITLE = "High-order SPH (the gradient correction, Laguerre-Gauss, RK4; the weak wall)"

# The high-order method (solvers/corrections/gradient.py): Laguerre-Gauss at h 1.5 dx cut at 4 h, corrected.
HIGH_ORDER = {"kernel": "laguerre-gauss", "h_factor": 1.5, "cutoff_factor": 4.0, "correction": "gradient"}


@dataclass(frozen=True)
class Cases:
    """The corrected scenes (Scene fields): the correction's moments sweep and passes, RK4's sums, the weak
    wall's staircase and its cut cells; each model and precision."""

    scenes: tuple = (
        {"dx": 0.25, "integrator": "rk4", "cfl": 1.0, **HIGH_ORDER},
        {"name": "cylinder", "dx": 0.04, "boundary_method": "weak", "cfl": 0.5, **HIGH_ORDER},
        {"name": "cylinder", "dx": 0.04, "boundary_method": "cut", "cfl": 0.5, **HIGH_ORDER},  # cut cells' volumes
    )
    models: tuple = ("linear", "lagrangian")
    precisions: tuple = ("float64", "float32")


def cases(rehearse: bool) -> Cases:
    """A card's cases, or the rehearsal's: check-solver's cylinder with the weak wall, its moments once (RK4 in
    the simulator: tests/test_high_order.py; lagrangian takes twice the minute)."""
    if not rehearse:
        return Cases()
    return Cases(
        ({**SCENES["cylinder"], "boundary_method": "weak", "cfl": 0.5, **HIGH_ORDER},), ("linear",), ("float64",)
    )


def against_cpu(cases: Cases, steps: int, out: Path) -> list[dict]:
    """Each corrected scene ``steps`` steps on the GPU and the CPU, each model and precision: their rows."""
    return compare_cases(cases.scenes, steps, out, model=cases.models, precision=cases.precisions)


STAGE = agreement_stage("high-order", TITLE, 60, lambda c: against_cpu(cases(c.rehearse), c.plan.compare_steps, c.out))
