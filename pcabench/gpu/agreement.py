"""The GPU solver against the CPU one on the same scenes, every model and precision, walls and open edges included
(stage 2), and the open layer's cost on the GPU."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from pcabench.execute.run import run
from pcabench.gpu.plan import GPU_SOLVER, Plan
from pcabench.spec import RunSpec
from pcabench.store.safeio import fresh
from solvers import DEFAULT_SOLVER, MODELS, PRECISIONS, Scene

# ---------------------------------------------------------------- 2. GPU against CPU
AGREEMENT = {"float64": 1e-12, "float32": 1e-4}  # the largest relative difference of u GPU vs CPU that passes


def gpu_against_cpu(scene: Scene, out: Path) -> dict:
    """``scene`` run by linkedlist-gpu and linkedlist-cpu: its row, with the max relative difference of the final
    u and drho (each over the CPU field's max)."""
    fields = {}
    for solver in (DEFAULT_SOLVER, GPU_SOLVER):
        path = fresh(out / f"compare_{solver}.npz")
        rec = run(RunSpec(solver, scene), fields_path=path)
        if rec.status != "ok":
            raise RuntimeError(f"{solver} {scene.name} {scene.model} {scene.precision}: {rec.status} {rec.message}")
        fields[solver] = dict(np.load(path))
        path.unlink()
    diff = {
        name: float(
            np.max(np.abs(fields[GPU_SOLVER][name] - fields[DEFAULT_SOLVER][name]))
            / np.max(np.abs(fields[DEFAULT_SOLVER][name]))
        )
        for name in ("u", "drho")
    }
    print(
        f"compare {scene.name} {scene.precision} {scene.model}: u {diff['u']:.2e}, drho {diff['drho']:.2e}",
        file=sys.stderr,
        flush=True,
    )
    method = (
        f", {scene.sph_kernel.name} {scene.correction}-corrected {scene.integrator}"
        if scene.correction != "none"
        else ""
    )
    return {
        "scene": scene.name + (f" ({scene.boundary_method_used})" if scene.body is not None else "") + method,
        "N": scene.n_particles,
        "precision": scene.precision,
        "model": scene.model,
        "dx": scene.dx,
        "steps": scene.n_steps,
        "max_rel_diff_u": diff["u"],
        "max_rel_diff_drho": diff["drho"],
    }


def agrees(rows: list[dict]) -> bool:
    """Whether every row's u agrees within its precision's :data:`AGREEMENT` (and there is a row)."""
    return bool(rows) and all(r["max_rel_diff_u"] < AGREEMENT[r["precision"]] for r in rows)


def compare_with_cpu(plan: Plan, out: Path) -> list[dict]:
    """Max relative difference GPU vs CPU of the final u and drho, every model and precision."""
    return [
        gpu_against_cpu(
            Scene(dx=plan.compare_dx, steps=plan.compare_steps, model=model, precision=precision, **plan.scene), out
        )
        for precision in PRECISIONS
        for model in MODELS
    ]


def walls_against_cpu(plan: Plan, out: Path) -> list[dict]:
    """The same on each walled scene of the plan (mirror particles), each wall model and precision."""
    return [
        gpu_against_cpu(Scene(**{**walled, "steps": plan.compare_steps, "model": model, "precision": precision}), out)
        for walled in plan.wall_scenes
        for precision in PRECISIONS
        for model in plan.wall_models
    ]


def body_against_cpu(plan: Plan, out: Path) -> list[dict]:
    """The same on each scene of the plan with a body (the cylinder), each boundary method, model and precision."""
    return [
        gpu_against_cpu(
            Scene(
                **{
                    **scene,
                    "steps": plan.compare_steps,
                    "boundary_method": method,
                    "model": model,
                    "precision": precision,
                }
            ),
            out,
        )
        for scene in plan.body_scenes
        for method in plan.body_methods
        for model in plan.body_models
        for precision in plan.body_precisions
    ]


def high_order_against_cpu(plan: Plan, out: Path) -> list[dict]:
    """The same on each high-order scene of the plan (the kernel gradient correction's moments sweep and passes,
    RK4's sums, the weak wall), each model and precision."""
    return [
        gpu_against_cpu(Scene(**{**scene, "steps": plan.compare_steps, "model": model, "precision": precision}), out)
        for scene in plan.high_order_scenes
        for model in plan.high_order_models
        for precision in plan.high_order_precisions
    ]


def open_against_cpu(plan: Plan, out: Path) -> list[dict]:
    """The same on each open-edge scene of the plan (an absorbing layer: free y edges, the PML, the sponge),
    lagrangian (the layer's particles moving), both precisions."""
    return [
        gpu_against_cpu(Scene(**{**scene, "steps": plan.compare_steps, "model": "lagrangian", "precision": p}), out)
        for scene in plan.open_scenes
        for p in PRECISIONS
    ]


def open_cost(plan: Plan) -> list[dict]:
    """linkedlist-gpu's time per step (SNP + PI + SU, s) of each ``plan.open_cost`` scene closed and open, float32,
    lagrangian, in rounds that alternate which goes first; per scene the best of each side and their ratio."""
    from pcabench.store.record import STEP_STAGES

    best: dict = {}
    for i in range(plan.open_cost_rounds):
        for setting in plan.open_cost:
            pair = [{**setting, "open": ""}, setting][:: 1 if i % 2 == 0 else -1]
            for scene_args in pair:
                scene = Scene(**scene_args, steps=plan.open_cost_steps, precision="float32")
                rec = run(RunSpec(GPU_SOLVER, scene))
                if rec.status != "ok":
                    raise RuntimeError(f"{GPU_SOLVER} {scene.describe()}: {rec.status} {rec.message}")
                t = sum(rec.stages[s] for s in STEP_STAGES) / rec.steps
                key = (scene.name, scene.dx, scene.open, scene.absorber_used if scene.open else "")
                best[key] = min(best.get(key, (np.inf, 0)), (t, scene.n_particles))
    rows = []
    for (name, dx, edges, absorber), (t, n) in sorted(best.items()):
        closed = best[(name, dx, "", "")]
        if edges:
            rows.append(
                {"scene": name, "dx": dx, "open": edges, "absorber": absorber, "N": n, "closed_N": closed[1],
                 "step_ms": 1e3 * t, "closed_ms": 1e3 * closed[0], "ratio": t / closed[0]}
            )  # fmt: skip
    return rows
