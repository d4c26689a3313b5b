"""The GPU solver against the CPU one on the same scene (stage 2: the paper's scene, every model and precision);
the studies' stages (pcabench/studies/<study>/gpu.py) compare their own scenes with the same row and test."""

from __future__ import annotations

import itertools
import sys
from pathlib import Path
from typing import Callable

import numpy as np

from pcabench.execute.run import run
from pcabench.gpu.plan import Plan
from pcabench.gpu.stage import Check, Stage
from pcabench.gpu.tables import scene_agreement
from pcabench.spec import RunSpec
from pcabench.store.safeio import fresh
from solvers import DEFAULT_SOLVER, GPU_SOLVER, MODELS, PRECISIONS, Scene

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
    """Max relative difference GPU vs CPU of the final u and drho on the paper's scene, every precision and model."""
    return compare_cases(
        [{"dx": plan.compare_dx, **plan.scene}], plan.compare_steps, out, precision=PRECISIONS, model=MODELS
    )


def compare_cases(scenes, steps: int, out: Path, **axes) -> list[dict]:
    """:func:`gpu_against_cpu` on each of ``scenes`` (Scene fields) run ``steps`` steps, for every combination of
    ``axes`` (a Scene field -> its values, the last varying fastest): a study's cases on a card."""
    names = list(axes)
    return [
        gpu_against_cpu(Scene(**{**scene, "steps": steps, **dict(zip(names, values))}), out)
        for scene in scenes
        for values in itertools.product(*axes.values())
    ]


def agreement_stage(name: str, title: str, order: float, rows: Callable[[Check], list[dict]], need_s=40.0) -> Stage:
    """A study's stage that runs its cases on the GPU and the CPU (``rows(check)``: their rows), passes when every
    row agrees (:func:`agrees`) and reports them as a table titled ``title``; its rows are ``results[name]``."""

    def work(c: Check) -> bool:
        c.state[name] = rows(c)
        return agrees(c.state[name])

    def report(results: dict) -> list[str]:
        return scene_agreement(title, results[name]) if results.get(name) else []

    return Stage(name, need_s, work, order=order, report=report)
