"""What the GPU check runs and within what time: the full plan (sized on the H100 run), the rehearsal's, and
the budget each stage is given."""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass, field

from pcabench.conformance import SCENES
from solvers import Scene

GPU_SOLVER = "linkedlist-gpu"  # the solver this check measures (its CUDA graph path, its kernels under ncu)
GPU_DX = (0.1, 0.05, 0.025, 0.01, 0.005, 0.004)  # 100K .. 62.5M particles on the paper's domain
CPU_DX = (0.1, 0.05, 0.025)  # 100K .. 1.6M: Table 6's CPU column on the GPU's host

# The high-order method (solvers/corrections/gradient.py): Laguerre-Gauss at h 1.5 dx cut at 4 h, corrected.
HIGH_ORDER = {"kernel": "laguerre-gauss", "h_factor": 1.5, "cutoff_factor": 4.0, "correction": "gradient"}

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
    """What the check runs and at what size."""

    gpu_dx: tuple = GPU_DX
    models: tuple = ("lagrangian",)
    min_steps: int = 10  # steps of the biggest runs; smaller ones take up to max_steps (see gpu_steps)
    max_steps: int = 100
    compare_dx: float = 0.5
    compare_steps: int = 20
    # the walled scenes (Scene fields, name included), run compare_steps steps: every scene kind with walls at
    # its card size (SceneKind.card: a new walled kind is checked with no list to edit)
    wall_scenes: tuple = field(default_factory=lambda: card_cases(lambda kind: bool(kind.walls)))
    wall_models: tuple = ("linear", "lagrangian")  # mirrors set once; mirrors following the particles
    # open edges (issue 41): the 2D pulse in a 24 m open square (free y edges, the PML) and the paper's pulse with
    # open x edges (the sponge), against the CPU solver; then the time per step closed and open, alternating
    open_scenes: tuple = field(default_factory=lambda: card_cases(lambda kind: kind.card_open is not None, True))
    # a body (issue 42): the workshop's cylinder at 5 particles a pulse width (102,400 particles), each boundary
    # method (its ghosts filled from the fluid on the host), linear and lagrangian, against the CPU solver
    body_scenes: tuple = field(default_factory=lambda: card_cases(lambda kind: kind.body))
    body_methods: tuple = ("lattice", "rings")
    body_models: tuple = ("linear", "lagrangian")
    body_precisions: tuple = ("float64", "float32")
    # high-order SPH (issue 56): the kernel gradient correction with the Laguerre-Gauss kernel, on the plane pulse
    # with RK4 and on the cylinder with its weak wall (no ghosts), each model and precision, against the CPU solver
    high_order_scenes: tuple = (
        {"dx": 0.25, "integrator": "rk4", "cfl": 1.0, **HIGH_ORDER},
        {"name": "cylinder", "dx": 0.04, "boundary_method": "weak", "cfl": 0.5, **HIGH_ORDER},
    )
    high_order_models: tuple = ("linear", "lagrangian")
    high_order_precisions: tuple = ("float64", "float32")
    open_cost: tuple = ({"dx": 0.025, "open": "x"}, {"name": "acoustic-pulse", "dx": 0.05, "open": "xy"})
    open_cost_steps: int = 50
    open_cost_rounds: int = 3
    graph_dx: tuple = (0.1, 0.025, 0.01)  # 100K, 1.6M, 10M
    graph_steps: int = 50
    graph_rounds: int = 5
    cpu_dx: tuple = CPU_DX
    cpu_steps: int = 5
    scene: dict = field(default_factory=dict)  # Scene overrides (the rehearsal's small domain)
    asv_bench: str = "TimeGPUStep"
    ncu_dx: float = 0.01

    def gpu_steps(self, dx: float) -> int:
        """100 steps up to 2M particles, then 2e8 particle-steps per run, but at least ``min_steps``."""
        n = Scene(dx=dx, **self.scene).n_particles
        return max(self.min_steps, min(self.max_steps, int(2e8 // max(n, 1))))


FULL = Plan()
REHEARSAL = Plan(
    gpu_dx=(1.0, 0.5),
    min_steps=2,
    max_steps=2,
    compare_dx=1.0,
    compare_steps=3,
    # check-solver's 182-particle duct walled at both ends (both mirror branches), its mirrors following the
    # particles: 2 runs, not 8 (~20 s each in the simulator); check-solver runs every walled case there
    wall_scenes=(SCENES["pulse-wall"],),
    wall_models=("lagrangian",),
    open_scenes=(SCENES["acoustic-pulse-open"],),  # check-solver's open square: free y edges and the PML
    body_scenes=(SCENES["cylinder"],),  # check-solver's cylinder (1,376 particles): one run a side in the simulator
    body_methods=("rings",),
    body_models=("lagrangian",),
    body_precisions=("float32",),
    # check-solver's cylinder with the weak wall: the correction's moments and passes, one run a side (RK4 in the
    # simulator: tests/test_high_order.py)
    high_order_scenes=({**SCENES["cylinder"], "boundary_method": "weak", "cfl": 0.5, **HIGH_ORDER},),
    high_order_models=("linear",),  # its moments once: a minute in the simulator (lagrangian: twice that)
    high_order_precisions=("float64",),
    open_cost=({"dx": 1.0, "x_min": -8.0, "x_max": 8.0, "open": "x"},),
    open_cost_steps=2,
    open_cost_rounds=1,
    graph_dx=(1.0,),
    graph_steps=2,
    graph_rounds=1,
    cpu_dx=(1.0,),
    cpu_steps=2,
    scene={"x_min": -8.0, "x_max": 8.0},
    asv_bench="TimeGPUStep",
    ncu_dx=1.0,
)


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
