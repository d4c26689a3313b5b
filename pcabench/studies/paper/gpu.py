"""The paper study on a GPU: its scene against the CPU, its GPU sweep (plan.py's ``gpu`` preset: Table 6, Fig. 14,
the cards page), the step as a CUDA graph, and the GPU host's CPU peers (Table 6's same-machine column).

These are the check's own stages (pcabench/gpu/check.py runs them beside the profile, asv, the benchmarks, the
GPU tests and Nsight Compute; the command line hands them to it with the paper's plan, :data:`FULL` or
:data:`REHEARSAL`), kept in the paper's folder: :data:`PAPER_STAGES` is a tuple, not a registered
stage each, so that another study's gpu.py failing to load never costs the paper's measurement.
"""

from __future__ import annotations

import sys

from pcabench.gpu.agreement import agrees, compare_with_cpu
from pcabench.gpu.graph_timing import graph_vs_plain
from pcabench.gpu.plan import Plan
from pcabench.gpu.stage import Check, Stage
from pcabench.studies.paper.plan import CPU_DX, CPU_STEPS, GPU_DX, GPU_MODELS, GPU_STEPS
from pcabench.studies.paper.plan import cpu_peers as cpu_peers_specs
from pcabench.studies.paper.plan import gpu_sweep as gpu_sweep_specs
from solvers import PRECISIONS, solver_class
from solvers.gpu.device import device_backend


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


def compare(c: Check) -> bool:
    c.state["compare"] = compare_with_cpu(c.plan, c.out)
    return agrees(c.state["compare"])


def stored_sweep(c: Check, specs, spare_s: float) -> list[dict]:
    """``specs`` through the ordinary sweep into the check's store, within what is left of the budget less
    ``spare_s`` seconds kept for the stages after; the rows."""
    from pcabench.execute.sweep import sweep

    left = c.budget.left()
    return sweep(specs, c.store_path, run_budget=left, sweep_budget=left - spare_s, runner=run_and_release)


def gpu_sweep(c: Check) -> bool:
    c.state["gpu_rows"] = stored_sweep(
        c, gpu_sweep_specs(c.plan.gpu_dx, c.plan.models, c.plan.scene, (c.plan.min_steps, c.plan.max_steps)), spare_s=60
    )
    return all(r["status"] == "ok" for r in c.state["gpu_rows"])


def graph(c: Check) -> bool:
    plan = c.plan
    if c.cupy is None:
        c.state["graph"] = [
            {"dx": dx, "precision": p, "error": "needs a real GPU (no streams in the simulator)"}
            for dx in plan.graph_dx
            for p in PRECISIONS
        ]
        return True
    c.state["graph"] = []
    for dx in plan.graph_dx:
        for precision in PRECISIONS:
            if c.budget.left() < 30:
                break
            try:
                row = graph_vs_plain(dx, precision, plan.graph_steps, plan.graph_rounds, plan.scene)
            except Exception as exc:  # noqa: BLE001
                row = {"dx": dx, "precision": precision, "error": f"{type(exc).__name__}: {str(exc)[:300]}"}
            c.state["graph"].append(row)
            c.budget.say(f"graph dx {dx} {precision}: {row}")
            c.cupy.get_default_memory_pool().free_all_blocks()
    return all("error" not in r for r in c.state["graph"])


def cpu_peers(c: Check) -> bool:
    c.state["cpu_rows"] = stored_sweep(c, cpu_peers_specs(c.plan.cpu_dx, c.plan.cpu_steps, c.plan.scene), spare_s=30)
    return all(r["status"] == "ok" for r in c.state["cpu_rows"])


# each one's seconds to start, its work and its place among the check's stages (pcabench/gpu/check.py: OWN)
PAPER_STAGES = (
    Stage("compare", 40, compare, order=10),
    Stage("sweep", 60, gpu_sweep, order=30),
    Stage("graph", 40, graph, order=70),
    Stage("cpu", 40, cpu_peers, order=80),
)

# What the check runs on a card (sized on the H100 run) and in its rehearsal (numba's simulator, a few hundred
# particles); the command line hands them and PAPER_STAGES to pcabench/gpu/check.py.
FULL = Plan(GPU_DX, GPU_MODELS, GPU_STEPS[0], GPU_STEPS[1], CPU_DX, CPU_STEPS)
REHEARSAL = Plan(
    gpu_dx=(1.0, 0.5),
    models=GPU_MODELS,
    min_steps=2,
    max_steps=2,
    cpu_dx=(1.0,),
    cpu_steps=2,
    compare_dx=1.0,
    compare_steps=3,
    graph_dx=(1.0,),
    graph_steps=2,
    graph_rounds=1,
    scene={"x_min": -8.0, "x_max": 8.0},
    asv_bench="TimeGPUStep",
    ncu_dx=1.0,
)
