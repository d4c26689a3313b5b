"""The 3D study on a GPU: linkedlist-gpu against linkedlist-cpu on the 3D scenes (the periodic cube with standard
SPH, its six open faces, the high-order method, the rigid sphere's weak wall), each model and precision; then the
3D pulse's time per step on the card from 1 to 27 million particles, standard SPH and the high-order method; then
PI beside TrixiParticles' published H100 figure in its own case (:data:`ANCHOR`)."""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path

from pcabench.conformance import SCENES
from pcabench.execute.run import run
from pcabench.gpu.agreement import agrees, compare_cases
from pcabench.gpu.stage import Check, Stage
from pcabench.gpu.tables import scene_agreement
from pcabench.reports.md import md_table
from pcabench.spec import RunSpec
from pcabench.store.record import STEP_STAGES
from pcabench.studies.three_d.plan import HIGH_ORDER, STANDARD  # the study's methods: 80 and 894 neighbours
from solvers import GPU_SOLVER, PRECISIONS, Scene

TITLE = "Sound in three dimensions (the trimmed stencil's kernels)"

CORRECTED = {**STANDARD, "correction": "gradient"}  # the weak wall's at 80 neighbours
PULSE = {"name": "acoustic-pulse-3d"}  # the 16 m periodic cube
# The anchor: TrixiParticles' published H100 figure, one force computation (`interact!`: continuity and momentum,
# the neighbour search built before) of 3D WCSPH on 1,030,301 particles (101^3, randomized positions sorted by
# cell), Wendland C2 at h 1.5 dx (search radius 3 dx): FP32 3.407714 ms, FP64 6.047292 ms. Source:
# trixi-framework/PointNeighbors.jl benchmarks/plot_benchmarks.jl, commit 10a389dceeda71ba976db72c6d32926f7ddaae78
# (PR #169), the "Nvidia H100" rows. Ours beside it: PI (continuity and momentum) on the 3D pulse's lattice of
# the same count and kernel, lagrangian.
ANCHOR = {
    "what": "TrixiParticles (PointNeighbors.jl benchmarks/plot_benchmarks.jl @ 10a389d), one interact! on an H100",
    "N": 1_030_301,
    "method": {"kernel": "wendland-c2", "h_factor": 1.5},
    "ms": {"float32": 3.407714, "float64": 6.047292},
}


@dataclass(frozen=True)
class Cases:
    """The 3D scenes against the CPU, each (Scene fields, models, precisions), ``steps`` steps; the scale runs: the
    3D pulse at each of ``scale_dx`` (the 16 m cube: 1, 8 and 27 million particles) with each of
    ``scale_methods``, float32, lagrangian, ``scale_steps`` steps, smallest first, while ``scale_floor_s`` seconds of
    the check are left and for ``scale_most_s`` seconds at most."""

    scenes: tuple = (
        ({**PULSE, "dx": 0.5, **STANDARD}, ("lagrangian", "linear"), PRECISIONS),  # 32,768 particles
        (
            {**PULSE, "dx": 0.5, "open": "xyz", "layer_width": 2.0, "absorber": "sponge", **STANDARD},
            ("lagrangian",),
            ("float64",),
        ),
        (
            {**PULSE, "dx": 0.5, "open": "xyz", "layer_width": 2.0, "absorber": "pml", **STANDARD},
            ("linear",),
            ("float64",),
        ),  # the PML's parts of the rate
        ({**PULSE, "dx": 0.5, **HIGH_ORDER}, ("linear",), PRECISIONS),  # 32,768 particles, 894 neighbours
        # 110,592 with the PML's layer
        ({"name": "sphere", "dx": 0.125, "boundary_method": "weak", **CORRECTED}, ("linear",), ("float64",)),
        ({"name": "sphere", "dx": 0.125, "boundary_method": "cut", **CORRECTED}, ("linear",), ("float64",)),
    )
    steps: int = 5
    scale_dx: tuple = (0.16, 0.08, 16.0 / 300)
    scale_methods: tuple = (("standard", STANDARD), ("high-order", HIGH_ORDER))
    scale_steps: int = 10
    scale_floor_s: float = 60.0
    scale_most_s: float = 150.0  # the scale runs' own time at most: the check's later stages keep theirs
    scale_domain: dict | None = None  # the cube and its pulse (None: the scene's 16 m)
    anchor_dx: float = 16.0 / 101  # the anchor's count on the 16 m cube: 101^3 = 1,030,301 particles
    anchor_steps: int = 5
    anchor_precisions: tuple = ("float32", "float64")


def cases(rehearse: bool) -> Cases:
    """A card's cases, or the rehearsal's: the smallest cube (729 particles) against the CPU, one scale run."""
    if not rehearse:
        return Cases()
    tiny = SCENES["acoustic-pulse-3d"]  # check-solver's: 729 particles, every seam acting from the first step
    domain = {key: value for key, value in tiny.items() if key not in ("name", "dx", "h_factor")}
    return Cases(
        scenes=(({**tiny, **STANDARD}, ("lagrangian",), ("float64",)),),
        steps=2,
        scale_dx=(1.0,),
        scale_methods=(("standard", STANDARD),),
        scale_steps=2,
        scale_floor_s=0.0,
        scale_domain=domain,
        anchor_dx=1.0,
        anchor_steps=2,
        anchor_precisions=("float32",),
    )


def against_cpu(mine: Cases, out: Path) -> list[dict]:
    """Each 3D scene ``mine.steps`` steps on the GPU and the CPU, with its models and precisions: their rows."""
    rows = []
    for scene, models, precisions in mine.scenes:
        rows += compare_cases((scene,), mine.steps, out, model=models, precision=precisions)
    return rows


def scale(mine: Cases, c: Check) -> list[dict]:
    """The 3D pulse's time per step (SNP + PI + SU) on the GPU, float32, lagrangian, at each dx and method while the
    check has time: N, neighbours, ms a step, ns a particle-step and ns a particle-neighbour-step."""
    rows, t0 = [], time.perf_counter()
    for dx in mine.scale_dx:
        for label, method in mine.scale_methods:
            if c.budget.left() < mine.scale_floor_s or time.perf_counter() - t0 > mine.scale_most_s:
                c.budget.say(
                    f"three-d scale: {label} at dx {dx:.4g} left out (the stage's or the check's time is spent)"
                )
                continue
            scene = Scene(**{**PULSE, **(mine.scale_domain or {}), "dx": dx, **method}, steps=mine.scale_steps,
                          precision="float32", model="lagrangian")  # fmt: skip
            rec = run(RunSpec(GPU_SOLVER, scene))
            if rec.status != "ok":
                rows.append(
                    {"method": label, "dx": dx, "N": scene.n_particles, "status": f"{rec.status} {rec.message}"}
                )
                continue
            t = sum(rec.stages[s] for s in STEP_STAGES) / rec.steps
            n, nb = scene.n_particles, rec.mean_neighbours
            rows.append({"method": label, "dx": dx, "N": n, "neighbours": nb, "status": "ok", "step_ms": 1e3 * t,
                         "ns_particle_step": 1e9 * t / n, "ns_pair": 1e9 * t / (n * nb)})  # fmt: skip
            c.budget.say(f"three-d scale: {label} N = {n:,}: {1e3 * t:.4g} ms a step")
    return rows


def anchor(mine: Cases, c: Check) -> list[dict]:
    """PI's time a step (continuity and momentum) in the anchor's case (:data:`ANCHOR`), each precision, while the
    check has time: beside the published figure."""
    rows = []
    for precision in mine.anchor_precisions:
        if c.budget.left() < mine.scale_floor_s:
            c.budget.say(f"three-d anchor: {precision} left out (the check's time is spent)")
            continue
        scene = Scene(**{**PULSE, **(mine.scale_domain or {}), "dx": mine.anchor_dx, **ANCHOR["method"]},
                      steps=mine.anchor_steps, precision=precision, model="lagrangian")  # fmt: skip
        rec = run(RunSpec(GPU_SOLVER, scene))
        row = {"precision": precision, "N": scene.n_particles, "status": rec.status}
        if rec.status == "ok":
            row.update(neighbours=rec.mean_neighbours, pi_ms=1e3 * rec.stages["pi"] / rec.steps)
            c.budget.say(f"three-d anchor: {precision} N = {scene.n_particles:,}: PI {row['pi_ms']:.4g} ms a step")
        else:
            row["status"] = f"{rec.status} {rec.message}"
        rows.append(row)
    return rows


def check(c: Check) -> bool:
    mine = cases(c.rehearse)
    c.state["three_d"] = against_cpu(mine, c.out)
    c.state["three_d_scale"] = scale(mine, c)
    c.state["three_d_anchor"] = anchor(mine, c)
    runs = c.state["three_d_scale"] + c.state["three_d_anchor"]
    return agrees(c.state["three_d"]) and all(r["status"] == "ok" for r in runs)


def report(results: dict) -> list[str]:
    lines = scene_agreement(TITLE, results["three_d"]) if results.get("three_d") else []
    rows = results.get("three_d_scale") or []
    if rows:
        table = [
            [r["method"], f"{r['dx']:.4g}", f"{r['N']:,}", f"{r.get('neighbours', 0):.0f}",
             *(f"{r[k]:.4g}" if r["status"] == "ok" else r["status"] for k in ("step_ms", "ns_particle_step",
                                                                               "ns_pair"))]
            for r in rows
        ]  # fmt: skip
        lines += [
            "",
            "## The 3D pulse on the GPU (linkedlist-gpu, float32, lagrangian; SNP + PI + SU a step)",
            "",
            md_table(["method", "dx", "N", "neighbours", "ms / step", "ns / particle-step", "ns / pair"], table),
        ]
    anchors = results.get("three_d_anchor") or []
    if anchors:
        table = [
            [r["precision"], f"{r['N']:,}", f"{r.get('neighbours', 0):.0f}",
             f"{r['pi_ms']:.4g}" if r["status"] == "ok" else r["status"],
             f"{ANCHOR['ms'][r['precision']]:.4g}" if r["N"] == ANCHOR["N"] else "- (not its count)"]
            for r in anchors
        ]  # fmt: skip
        lines += [
            "",
            f"## Beside the anchor: {ANCHOR['what']}",
            "",
            "Wendland C2 at h 1.5 dx, 3D, lagrangian; ours PI (continuity and momentum) a step on the cube's lattice, "
            "theirs one force computation on randomized positions sorted by cell (the neighbour search built before "
            "in both). A different card's figure is read as a scale, not a race.",
            "",
            md_table(["precision", "N", "neighbours", "PI ms / step (this card)", "published ms (H100)"], table),
        ]
    return lines


STAGE = Stage("three-d", 90, check, order=35, report=report)
