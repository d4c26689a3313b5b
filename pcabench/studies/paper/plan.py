"""The paper's runs: its CPU matrix (Tables 4-6, Figs. 8-14), as far as the budgets allow, and its GPU sweep with
the GPU host's CPU peers (Table 6's same-machine columns, Fig. 14, the cards page), which ``pcabench gpu-check``
runs on a lent card (its stages: gpu.py) and ``pcabench study --paper gpu`` lists or runs anywhere."""

from __future__ import annotations

from pcabench.spec import ALL_CORES, SERIAL, RunSpec
from pcabench.studies.preset import Preset, spec_of
from solvers import DEFAULT_SOLVER, GPU_SOLVER, PRECISIONS, Scene

GPU_PRESET = "gpu"  # the GPU sweep's and its CPU peers' rows carry it
GPU_DX = (0.1, 0.05, 0.025, 0.01, 0.005, 0.004)  # 100K .. 62.5M particles on the paper's domain
GPU_MODELS = ("lagrangian",)
GPU_STEPS = (10, 100)  # (fewest, most) steps of a GPU run: gpu_steps
CPU_DX = (0.1, 0.05, 0.025)  # 100K .. 1.6M: Table 6's CPU column on the GPU's host
CPU_STEPS = 5


def paper() -> list[RunSpec]:
    """The paper's CPU matrix (Tables 4-6, Figs. 8-14), as far as the budgets allow."""
    runs = []
    for dx in (1.0, 0.5, 0.25, 0.2, 0.1, 0.05, 0.025):  # 1K .. 1.6M; Table 6 at 25K/100K/400K
        runs.append(spec_of(dx=dx, steps=100))
        runs.append(spec_of(dx=dx, steps=100, threads=ALL_CORES))
        runs.append(spec_of(dx=dx, steps=20, pair_loop="gather"))  # the paper's loop, for Table 4
    # Fig. 9 (the paper's 10th step, 1K .. 256K)
    for dx in (1.0, 0.5, 0.25, 0.125, 0.0625):
        runs.append(spec_of(dx=dx, steps=10))
        runs.append(spec_of("allpair-cpu", dx=dx, steps=10))
    for model in ("linear", "fixed", "lagrangian"):
        for precision in ("float64", "float32"):
            for dx in (0.4, 0.2, 0.1, 0.05, 0.025):
                runs.append(spec_of(threads=ALL_CORES, dx=dx, t_end=10.0, model=model, precision=precision, strip=True))
            for dx in (0.1, 0.05, 0.01, 0.004):
                runs.append(spec_of(threads=ALL_CORES, dx=dx, steps=100, model=model, precision=precision, strip=True))
        for dx in (0.2, 0.1):
            runs.append(spec_of(threads=ALL_CORES, dx=dx, t_end=10.0, model=model))
    return runs


def gpu_steps(dx: float, scene: dict | None = None, steps: tuple = GPU_STEPS) -> int:
    """A GPU run's steps at ``dx`` (``scene``: Scene overrides): the most up to 2M particles, then 2e8
    particle-steps per run, but at least the fewest (``steps``)."""
    n = Scene(dx=dx, **(scene or {})).n_particles
    return max(steps[0], min(steps[1], int(2e8 // max(n, 1))))


def gpu_sweep(gpu_dx=GPU_DX, models=GPU_MODELS, scene: dict | None = None, steps: tuple = GPU_STEPS) -> list:
    """The GPU timing sweep: linkedlist-gpu on the paper's full domain, every size, precision and model (the card
    checks its own memory)."""
    scene = scene or {}
    return [
        RunSpec(
            GPU_SOLVER,
            Scene(
                dx=dx,
                steps=gpu_steps(dx, scene, steps),
                model=model,
                precision=precision,
                memory_limit_bytes=2**40,
                **scene,
            ),
            preset=GPU_PRESET,
        )
        for dx in gpu_dx
        for precision in PRECISIONS
        for model in models
    ]


def cpu_peers(cpu_dx=CPU_DX, steps: int = CPU_STEPS, scene: dict | None = None) -> list:
    """linkedlist-cpu, lagrangian float64, one thread and every core, on the GPU's host: Table 6's CPU column."""
    return [
        RunSpec(DEFAULT_SOLVER, Scene(dx=dx, steps=steps, **(scene or {})), threads, preset=GPU_PRESET)
        for dx in cpu_dx
        for threads in (SERIAL, ALL_CORES)
    ]


PAPER = Preset(
    "paper",
    paper,
    900.0,
    flag="paper",
    choice="cpu",
    help="the paper's CPU matrix, within the budgets ({size})",
    order=20,
)
PAPER_GPU = Preset(
    GPU_PRESET,
    lambda: gpu_sweep() + cpu_peers(),
    900.0,
    flag="paper",
    choice="gpu",
    help="the paper's GPU sweep and its host's CPU peers, on a GPU machine (`pcabench gpu-check` runs them) ({size})",
    order=21,
)
