"""The runs the GPU check sweeps into the store: the GPU's sizes and its host's CPU peers (stages 3 and 5)."""

from __future__ import annotations

import sys

from pcabench.gpu.plan import GPU_SOLVER, Plan
from pcabench.spec import ALL_CORES, SERIAL, RunSpec
from solvers import DEFAULT_SOLVER, PRECISIONS, Scene, solver_class
from solvers.gpu.device import device_backend


# ---------------------------------------------------------------- 3 and 5. the sweeps
def gpu_specs(plan: Plan) -> list[RunSpec]:
    """The GPU timing sweep: linkedlist-gpu on the paper's full domain, every size, precision and model."""
    return [
        RunSpec(
            GPU_SOLVER,
            Scene(
                dx=dx,
                steps=plan.gpu_steps(dx),
                model=model,
                precision=precision,
                memory_limit_bytes=2**40,
                **plan.scene,
            ),
            preset="gpu",
        )
        for dx in plan.gpu_dx
        for precision in PRECISIONS
        for model in plan.models
    ]  # the GPU checks its memory


def cpu_peer_specs(plan: Plan) -> list[RunSpec]:
    """linkedlist-cpu, lagrangian float64, one thread and every core, on this GPU's host: Table 6's CPU column."""
    return [
        RunSpec(DEFAULT_SOLVER, Scene(dx=dx, steps=plan.cpu_steps, **plan.scene), threads, preset="gpu")
        for dx in plan.cpu_dx
        for threads in (SERIAL, ALL_CORES)
    ]


def run_and_release(spec, timeout, commit, machine, stream=sys.stderr) -> dict:
    """One run in this process, then CuPy's cached blocks back to the card (the next run's fit check reads
    the card's free memory)."""
    from pcabench.execute.sweep import run_here

    try:
        return run_here(spec, timeout, commit, machine, stream)
    finally:
        _cuda, cupy = device_backend() if solver_class(spec.solver).device == "gpu" else (None, None)
        if cupy is not None:
            cupy.get_default_memory_pool().free_all_blocks()
