"""All of the GPU work in one command, within one time budget, rehearsed where there is no GPU.

    pcabench gpu-check --out DIR [--budget SECONDS]      # on a GPU machine
    pcabench gpu-check --rehearse --out DIR              # anywhere: the same script in numba's simulator

A GPU machine is lent rarely and briefly, so the first real run has to work
and bring everything back from one call. The check runs these stages
(:data:`STAGES`, a registry like the report's sections: a stage is one
function of the shared :class:`Check` and one entry) in order of value, each
given what is left of the budget, and stops cleanly when the budget is
spent, keeping what it has:

1. ``profile``: the hardware profile, with the card's measured ceilings
   (device copy bandwidth, FP32 and FP64 FMA rates, the SM clock);
2. ``compare``: linkedlist-gpu against linkedlist-cpu, every model and precision;
   ``walls``: the same on the scenes with rigid walls (plane-wall, pulse-wall:
   mirror particles), linear and lagrangian, both precisions;
3. ``sweep``: linkedlist-gpu, lagrangian Verlet, both precisions, 100K to 62.5M
   particles on the paper's domain, steps sized to the budget; runs go to the
   results store (preset ``gpu``) through the ordinary sweep, in this process
   so that kernels compile once;
4. ``graph``: the step captured as a CUDA graph against plain launches, in the
   same process, alternating, best of several rounds, and their fields compared;
5. ``cpu``: linkedlist-cpu on this host (one thread and every core): Table 6's
   same-machine CPU column;
6. ``asv``: asv's GPU benchmarks at HEAD and at the H100's commit, when asv
   and the history were brought along (pcabench/gpu/payload.py);
7. ``bench``: the pytest-benchmark suite's JSON; ``pytest-gpu``: the GPU tests;
8. ``ncu``: Nsight Compute's speed-of-light section of one step's kernels;
9. the reports, regenerated from the store.

Everything to bring back ends up in DIR: ``gpu_check.md`` (tables),
``gpu_check.log`` is the caller's, and ``gpu_check.tar.gz`` (store, profile,
reports, JSON and logs), at most a few files of a few MiB.

The full plan was sized from the H100 run at bf587a5 (one lagrangian step at
62.5M particles: 98 ms float32, 170 ms float64; 5-8 s to copy the fields back
and sort them on the host at that size; about 20 s of compilation per
process) to take about 6 minutes of an H200, leaving a default budget of
8 minutes some slack. The rehearsal runs every stage end to end at a few
hundred particles in the simulator (the graph and the ceilings need a GPU
and say so), which is what CI runs so that the script cannot rot.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tarfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np

from pcabench.conformance import SCENES
from pcabench.execute.run import run
from pcabench.spec import ALL_CORES, SERIAL, RunSpec
from pcabench.store import store_name
from pcabench.store.record import STEP_STAGES, step_seconds
from pcabench.store.safeio import fresh, own_folder, write_file
from solvers import DEFAULT_SOLVER, MODELS, PRECISIONS, Scene, make_solver, solver_class
from solvers.gpu.device import device_backend, simulated
from solvers.physics.integrators import step_program

GPU_SOLVER = "linkedlist-gpu"  # the solver this check measures (its CUDA graph path, its kernels under ncu)

H100_COMMIT = "bf587a5"  # the commit the H100 was measured at: asv compares the cards there
GPU_DX = (0.1, 0.05, 0.025, 0.01, 0.005, 0.004)  # 100K .. 62.5M particles on the paper's domain
CPU_DX = (0.1, 0.05, 0.025)  # 100K .. 1.6M: Table 6's CPU column on the GPU's host
RESERVE_S = 25.0  # kept back from every stage for the reports and the tarball


@dataclass(frozen=True)
class Plan:
    """What the check runs and at what size."""

    gpu_dx: tuple = GPU_DX
    models: tuple = ("lagrangian",)
    min_steps: int = 10  # steps of the biggest runs; smaller ones take up to max_steps (see gpu_steps)
    max_steps: int = 100
    compare_dx: float = 0.5
    compare_steps: int = 20
    # the walled scenes (Scene fields, name included), run compare_steps steps; their default domains here
    wall_scenes: tuple = ({"name": "plane-wall", "dx": 0.5}, {"name": "pulse-wall", "dx": 0.5})
    wall_models: tuple = ("linear", "lagrangian")  # mirrors set once; mirrors following the particles
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


# ---------------------------------------------------------------- 1. the card's ceilings
def measure_ceilings(cupy) -> dict:
    """Device-to-device copy bandwidth (bytes read + written), FP32/FP64 FMA rates, and the SM clock."""
    cuda, _ = device_backend()
    out = {}
    n = 512 * 2**20 // 4  # 512 MiB per buffer
    a = cupy.random.random(n, dtype=cupy.float32)
    b = cupy.empty_like(a)
    for _ in range(3):
        b[...] = a
    start, end = cupy.cuda.Event(), cupy.cuda.Event()
    times = []
    for _ in range(10):
        start.record()
        b[...] = a
        end.record()
        end.synchronize()
        times.append(cupy.cuda.get_elapsed_time(start, end) / 1e3)
    out["copy_bandwidth_tbs"] = round(2 * a.nbytes / float(np.median(times)) / 1e12, 3)
    del a, b

    def fma_kernel():
        @cuda.jit
        def k(x, iters, m, c):
            i = cuda.grid(1)
            a0 = x[i]
            a1 = a0 + 1
            a2 = a0 + 2
            a3 = a0 + 3
            a4 = a0 + 4
            a5 = a0 + 5
            a6 = a0 + 6
            a7 = a0 + 7
            for _ in range(iters):
                a0 = a0 * m + c
                a1 = a1 * m + c
                a2 = a2 * m + c
                a3 = a3 * m + c
                a4 = a4 * m + c
                a5 = a5 * m + c
                a6 = a6 * m + c
                a7 = a7 * m + c
            x[i] = a0 + a1 + a2 + a3 + a4 + a5 + a6 + a7

        return k

    for dtype, key in ((np.float32, "fp32_fma_tflops"), (np.float64, "fp64_fma_tflops")):
        threads, iters = 132 * 2048 * 4, 2048
        x = cupy.ones(threads, dtype=dtype)
        k = fma_kernel()
        m, c = dtype(0.999), dtype(0.001)  # typed constants keep the chain in dtype
        k[threads // 256, 256](x, iters, m, c)
        cupy.cuda.runtime.deviceSynchronize()
        start.record()
        k[threads // 256, 256](x, iters, m, c)
        end.record()
        end.synchronize()
        seconds = cupy.cuda.get_elapsed_time(start, end) / 1e3
        out[key] = round(2 * 8 * iters * threads / seconds / 1e12, 2)
    out["sm_clock_mhz_under_load"] = _smi_clock()
    out["note"] = "measured by pcabench gpu-check (median of 10 copies; one FMA-chain kernel each)"
    return out


def _smi_clock():
    """The SM clock nvidia-smi reports right after the FMA kernels, MHz (None without nvidia-smi)."""
    try:
        text = (
            subprocess.run(
                ["nvidia-smi", "--query-gpu=clocks.sm,clocks.max.sm", "--format=csv,noheader,nounits"],
                capture_output=True,
                text=True,
                timeout=20,
            )
            .stdout.strip()
            .splitlines()[0]
        )
        now, most = (int(v) for v in text.split(","))
        return {"now": now, "max": most}
    except (OSError, ValueError, IndexError, subprocess.SubprocessError):
        return None


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
    return {
        "scene": scene.name,
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


# ---------------------------------------------------------------- 4. the graph path
def graph_vs_plain(dx: float, precision: str, steps: int, rounds: int, scene_overrides: dict) -> dict:
    """ms per lagrangian Verlet step, plain launches against the captured graph, alternating in one process
    (best round of each), and the largest relative difference of u after ``steps`` steps of each from one state."""
    from solvers.gpu.graph import CapturedSteps

    scene = Scene(dx=dx, precision=precision, model="lagrangian", memory_limit_bytes=2**40, **scene_overrides)
    solver = make_solver(GPU_SOLVER)
    solver.input(scene)
    solver.warmup()
    solver.init()
    for _stage, op in step_program("verlet", solver, first=True):
        op()
    plain_step = step_program("verlet", solver, first=False)
    graph = CapturedSteps(solver, "verlet")
    cupy, stream = solver.cupy, solver.stream

    def timed(one_step) -> float:
        start, end = cupy.cuda.Event(), cupy.cuda.Event()
        start.record(stream)
        for _ in range(steps):
            one_step()
        end.record(stream)
        end.synchronize()
        return cupy.cuda.get_elapsed_time(start, end) / steps

    def plain():
        for _stage, op in plain_step:
            op()

    best = {"plain": float("inf"), "graph": float("inf")}
    for _ in range(rounds):
        for name, one_step in (("plain", plain), ("graph", graph.step)):
            best[name] = min(best[name], timed(one_step))
    # the same steps from one state by each path: the state is the current block, its cells and cellBegin
    current = solver.state()
    block, cells = (a.copy() for a in solver.blocks_of[current])
    begin, t0 = solver.begin.copy(), solver.t
    u = {}
    for name, one_step in (("plain", plain), ("graph", graph.step)):
        solver.set_state(current)
        solver.blocks_of[current][0][...] = block
        solver.blocks_of[current][1][...] = cells
        solver.begin[...] = begin
        solver.t = t0
        for _ in range(steps):
            one_step()
        u[name] = solver.output().u  # particle-id order
    diff = float(np.max(np.abs(u["graph"] - u["plain"])) / np.max(np.abs(u["plain"])))
    return {
        "dx": dx,
        "N": scene.n_particles,
        "precision": precision,
        "steps": steps,
        "rounds": rounds,
        "plain_ms": best["plain"],
        "graph_ms": best["graph"],
        "speedup": best["plain"] / best["graph"],
        "max_rel_diff_u": diff,
    }


# ---------------------------------------------------------------- 6-8. subprocess stages
def run_logged(cmd: list[str], log: Path, timeout: float, env=None) -> dict:
    """``cmd`` with its output in ``log``; its exit code (124 past ``timeout``) and seconds."""
    t0 = time.perf_counter()
    with open(fresh(log), "w") as f:
        try:
            rc = subprocess.run(cmd, stdout=f, stderr=subprocess.STDOUT, timeout=max(timeout, 1.0), env=env).returncode
        except subprocess.TimeoutExpired:
            rc = 124
            f.write(f"\n[gpu-check: stopped at the stage's share of the budget, {timeout:.0f} s]\n")
        except OSError as exc:
            rc = 127
            f.write(f"\n[gpu-check: could not start {cmd[0]}: {exc}]\n")
    return {"command": " ".join(cmd), "exit": rc, "seconds": round(time.perf_counter() - t0, 1), "log": log.name}


def ncu_command(plan: Plan, out: Path) -> list[str]:
    """Nsight Compute on one short lagrangian run: the speed-of-light and memory sections of each kernel once."""
    return [
        "ncu",
        "--clock-control",
        "none",
        "--section",
        "SpeedOfLight",
        "--section",
        "MemoryWorkloadAnalysis",
        "--kernel-name",
        "regex:kick|continuity|advance|cell_count|cell_begin|scatter|momentum",
        "--launch-skip",
        "40",
        "--launch-count",
        "8",
        "-o",
        str(out / "ncu_step"),
        "-f",
        sys.executable,
        "-m",
        "pcabench.cli",
        "run",
        "--solver",
        GPU_SOLVER,
        "--dx",
        str(plan.ncu_dx),
        "--precision",
        "float32",
        "--steps",
        "8",
        "--quiet",
    ]


# ---------------------------------------------------------------- the tables
def timing_row(row: dict) -> dict:
    """One stored GPU run as the check's table row: step time, stage shares, ns per particle-step, ps per pair."""
    st, steps, n = row["stages"], max(row["steps"] or 0, 1), row["n_particles"]
    step = step_seconds(st, steps)
    loop = step * steps
    pairs = 2 * n * (row.get("mean_neighbours") or 0)  # both sweeps of a Verlet step
    share = {s: 100 * st[s] / loop if loop else float("nan") for s in STEP_STAGES}
    return {
        "dx": row["dx"],
        "N": n,
        "precision": row["precision"],
        "model": row["model"],
        "status": row["status"],
        "steps": steps,
        "step_ms": 1e3 * step,
        **{f"{s}_pct": share[s] for s in STEP_STAGES},
        "ns_per_particle_step": 1e9 * step / n,
        "ps_per_pair": 1e12 * step / pairs if pairs else float("nan"),
        "neighbours": row.get("mean_neighbours") or float("nan"),
        "mse": row.get("mse") if row.get("mse") is not None else float("nan"),
        "init_ms": 1e3 * st["init"],
        "output_ms": 1e3 * st["output"],
    }


def markdown(profile: dict, results: dict) -> str:
    """The check's tables: stages run, ceilings, agreement, sweep, graph path, CPU peers."""
    g = profile.get("gpu") or {}
    lines = [
        f"# GPU check: {g.get('name', 'no GPU (rehearsal)')} ({profile['id']})",
        "",
        f"Commit {results.get('commit', '?')}; budget {results['budget_s']:.0f} s, used {results['elapsed_s']:.0f} s.",
        "",
        "| stage | status | seconds |",
        "|---|---|---|",
    ]
    lines += [f"| {s['stage']} | {s['status']} | {s['seconds']:.1f} |" for s in results["stages"]]
    lines += ["", f"Measured ceilings: {json.dumps(profile.get('measured', {}))}", ""]
    if results.get("compare"):
        lines += [
            "## GPU vs linkedlist-cpu (max relative difference after the steps shown)",
            "",
            "| precision | model | dx | steps | u | drho |",
            "|---|---|---|---|---|---|",
        ]
        lines += [
            f"| {r['precision']} | {r['model']} | {r['dx']} | {r['steps']} | {r['max_rel_diff_u']:.2e} | "
            f"{r['max_rel_diff_drho']:.2e} |"
            for r in results["compare"]
        ]
    if results.get("walls"):
        lines += [
            "",
            "## Rigid walls (mirror particles): GPU vs linkedlist-cpu (max relative difference after the steps shown)",
            "",
            "| scene | N | precision | model | dx | steps | u | drho |",
            "|---|---|---|---|---|---|---|---|",
        ]
        lines += [
            f"| {r['scene']} | {r['N']:,} | {r['precision']} | {r['model']} | {r['dx']} | {r['steps']} | "
            f"{r['max_rel_diff_u']:.2e} | {r['max_rel_diff_drho']:.2e} |"
            for r in results["walls"]
        ]
    if results.get("gpu_rows"):
        lines += [
            "",
            "## linkedlist-gpu, paper domain, Verlet, cutoff 3h (stage clock: events around each operation)",
            "",
            "| dx | N | precision | model | status | steps | step (ms) | SNP % | PI % | SU % | ns/particle-step "
            "| ps/pair | neighbours | MSE | init (ms) | output (ms) |",
            "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
        ]
        for r in map(timing_row, results["gpu_rows"]):
            lines.append(
                f"| {r['dx']} | {r['N']:,} | {r['precision']} | {r['model']} | {r['status']} | {r['steps']} | "
                f"{r['step_ms']:.3f} | {r['snp_pct']:.1f} | {r['pi_pct']:.1f} | {r['su_pct']:.1f} | "
                f"{r['ns_per_particle_step']:.3f} | {r['ps_per_pair']:.2f} | {r['neighbours']:.1f} | "
                f"{r['mse']:.3g} | {r['init_ms']:.1f} | {r['output_ms']:.1f} |"
            )
        lines += ["", "ps/pair counts both sweeps of a Verlet step (2 x N x mean neighbours pairs)."]
    if results.get("graph"):
        lines += [
            "",
            "## The step as a CUDA graph against plain launches (same process, alternating, best round)",
            "",
            "| dx | N | precision | steps x rounds | plain (ms/step) | graph (ms/step) | plain / graph | "
            "u: graph vs plain |",
            "|---|---|---|---|---|---|---|---|",
        ]
        lines += [
            f"| {r['dx']} | {r['N']:,} | {r['precision']} | {r['steps']} x {r['rounds']} | {r['plain_ms']:.4f} "
            f"| {r['graph_ms']:.4f} | {r['speedup']:.2f} | {r['max_rel_diff_u']:.1e} |"
            for r in results["graph"]
            if "plain_ms" in r
        ]
        lines += [f"- dx {r['dx']} {r['precision']}: {r['error']}" for r in results["graph"] if "error" in r]
    if results.get("cpu_rows"):
        lines += [
            "",
            "## linkedlist-cpu on this host (lagrangian, float64)",
            "",
            "| dx | N | threads | status | steps | step (ms) |",
            "|---|---|---|---|---|---|",
        ]
        lines += [
            f"| {r['dx']} | {r['n_particles']:,} | {r['threads']} | {r['status']} | {r['steps']} | "
            f"{1e3 * step_seconds(r['stages'], r['steps']):.1f} |"
            for r in results["cpu_rows"]
        ]
    for key in ("pytest_gpu", "bench", "asv", "ncu"):
        if results.get(key):
            lines += ["", f"## {key}", "", "```", json.dumps(results[key], indent=1, default=str), "```"]
    return "\n".join(lines) + "\n"


# ---------------------------------------------------------------- the stages
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
    rehearse: bool
    env: dict  # the environment of the stages' child processes


@dataclass(frozen=True)
class Stage:
    """One stage of the check: it runs if ``need_s`` seconds are left; ``work(check)`` returns False when it
    failed (an exception fails it too, and the next stage still runs)."""

    name: str
    need_s: float
    work: Callable[[Check], object]


def measure(c: Check):
    if c.cupy is None:
        c.profile["measured"] = {"note": "rehearsal: no GPU, no ceilings"}
    else:
        c.profile["measured"] = measure_ceilings(c.cupy)
    from pcabench.machine import profiles

    profiles.save(c.profile)
    write_file(c.out / "profile.json", json.dumps(c.profile, indent=2) + "\n")


def compare(c: Check) -> bool:
    c.state["compare"] = compare_with_cpu(c.plan, c.out)
    return agrees(c.state["compare"])


def walls(c: Check) -> bool:
    c.state["walls"] = walls_against_cpu(c.plan, c.out)
    return agrees(c.state["walls"])


def stored_sweep(c: Check, specs, spare_s: float) -> list[dict]:
    """``specs`` through the ordinary sweep into the check's store, within what is left of the budget less
    ``spare_s`` seconds kept for the stages after; the rows."""
    from pcabench.execute.sweep import sweep

    left = c.budget.left()
    return sweep(specs, c.store_path, run_budget=left, sweep_budget=left - spare_s, runner=run_and_release)


def gpu_sweep(c: Check) -> bool:
    c.state["gpu_rows"] = stored_sweep(c, gpu_specs(c.plan), spare_s=60)
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
    c.state["cpu_rows"] = stored_sweep(c, cpu_peer_specs(c.plan), spare_s=30)
    return all(r["status"] == "ok" for r in c.state["cpu_rows"])


def asv(c: Check) -> bool:
    from pcabench.gpu.payload import run_asv_gpu

    c.state["asv"] = run_asv_gpu(
        c.out / "asv",
        commits=("HEAD", H100_COMMIT),
        budget_s=min(150, c.budget.left()),
        bench=c.plan.asv_bench,
        asv_args=("--quick",),
    )
    return all(r.get("returncode") == 0 for r in c.state["asv"])


def bench(c: Check) -> bool:
    json_path = c.out / f"pytest-benchmark_{c.profile['id']}.json"
    cmd = [
        sys.executable,
        "-m",
        "pytest",
        "-o",
        "addopts=",
        "-p",
        "no:cacheprovider",
        "tests/benchmarks",
        "--benchmark-only",
        f"--benchmark-json={json_path}",
        "-q",
    ]
    if c.rehearse:
        cmd += ["-k", "linkedlist and step"]
    c.state["bench"] = run_logged(cmd, c.out / "pytest_benchmark.log", min(120, c.budget.left()), c.env)
    return c.state["bench"]["exit"] == 0


def pytest_gpu(c: Check) -> bool:
    c.state["pytest_gpu"] = run_logged(
        [sys.executable, "-m", "pytest", "-m", "gpu", "-q", "-p", "no:cacheprovider", "tests"],
        c.out / "pytest_gpu.log",
        min(150, c.budget.left()),
        c.env,
    )
    return c.state["pytest_gpu"]["exit"] in (0, 5)  # 5: every GPU test deselected or skipped (rehearsal)


def ncu(c: Check) -> bool:
    if shutil.which("ncu") is None or c.cupy is None:
        c.state["ncu"] = {"status": "no ncu or no GPU here"}
        return True
    c.state["ncu"] = run_logged(ncu_command(c.plan, c.out), c.out / "ncu.log", min(90, c.budget.left()), c.env)
    return c.state["ncu"]["exit"] == 0


# In order: each one's seconds to start (what it needs at the least), its work.
STAGES = (
    Stage("profile", 0, measure),
    Stage("compare", 40, compare),
    Stage("walls", 40, walls),
    Stage("sweep", 60, gpu_sweep),
    Stage("graph", 40, graph),
    Stage("cpu", 40, cpu_peers),
    Stage("asv", 60, asv),
    Stage("bench", 60, bench),
    Stage("pytest-gpu", 40, pytest_gpu),
    Stage("ncu", 45, ncu),
)


def run_stage(stage: Stage, c: Check) -> None:
    """Run ``stage`` if its seconds are left; record its status and keep going on failure."""
    t0 = time.perf_counter()
    if c.budget.left() < stage.need_s:
        status = f"not run: {c.budget.left():.0f} s left, needs about {stage.need_s:.0f}"
    else:
        c.budget.say(f"{stage.name} ...")
        try:
            value = stage.work(c)
            status = "ok" if value is not False else "failed"
        except Exception as exc:  # noqa: BLE001 - one stage's failure must not lose the others' results
            status = f"failed: {type(exc).__name__}: {str(exc)[:300]}"
    c.state["stages"].append({"stage": stage.name, "status": status, "seconds": time.perf_counter() - t0})
    c.budget.say(f"{stage.name}: {status}")


# ---------------------------------------------------------------- the check
def gpu_check(
    out: Path, results: Path, reports: Path, budget_s: float = 480.0, rehearse: bool = False, plan: Plan | None = None
) -> int:
    """Every stage of :data:`STAGES` within ``budget_s`` seconds; 0 when every stage that ran passed, else 1.

    With ``rehearse`` (no GPU needed) the kernels run in numba's CUDA simulator at a few hundred particles.
    """
    out = own_folder(out, "--out")  # never a link: the check writes and bundles everything in it
    if rehearse:
        from numba.core import config

        os.environ["NUMBA_ENABLE_CUDASIM"] = "1"  # for the child processes (asv, pytest)
        config.reload_config()  # and this one: numba read its settings when the solver registry imported it
    plan = plan or (REHEARSAL if rehearse else FULL)
    from pcabench.machine import profiles
    from pcabench.reports import write_reports
    from pcabench.store.provenance import git_commit

    budget = Budget(budget_s)
    _cuda, cupy = device_backend()  # raises SolverUnavailable with a clear message (no GPU, no simulator)
    state = {"budget_s": budget_s, "commit": git_commit(), "rehearsal": rehearse or simulated(), "stages": []}
    profile = profiles.capture()
    c = Check(
        plan,
        out,
        budget,
        state,
        profile,
        cupy,
        Path(results) / store_name(profile["id"]),
        rehearse,
        dict(os.environ, PCABENCH_COMMIT=state["commit"]),
    )
    for stage in STAGES:
        run_stage(stage, c)

    state["elapsed_s"] = budget.elapsed()
    text = markdown(profile, state)
    write_file(out / "gpu_check.md", text)
    write_file(out / "gpu_check.json", json.dumps(state, indent=1, default=str) + "\n")
    print(text, flush=True)
    try:
        for p in write_reports(Path(results), Path(reports)):
            print(f"wrote {p}", file=sys.stderr)
    except Exception as exc:  # noqa: BLE001 - the tarball must still be written
        state["stages"].append({"stage": "reports", "status": f"failed: {exc}", "seconds": 0.0})
    bundle(out, Path(results), Path(reports), profile["id"])
    budget.say(f"done; bring back {out / 'gpu_check.tar.gz'}")
    return 0 if all(s["status"] == "ok" or s["status"].startswith("not run") for s in state["stages"]) else 1


def bundle(out: Path, results: Path, reports: Path, machine: str) -> Path:
    """One tarball of what to bring back: the check's files, this machine's store and profile, the reports."""
    from pcabench import paths

    path = fresh(out / "gpu_check.tar.gz")
    with tarfile.open(path, "w:gz") as tar:
        for f in sorted(out.iterdir()):
            if f.name != path.name and (f.is_file() or f.is_dir()):
                tar.add(f, arcname=f"check/{f.name}")
        for f in sorted(results.glob(f"{machine}--*.jsonl")):
            tar.add(f, arcname=f"store/{f.name}")
        profile = paths.user_profiles() / f"{machine}.json"
        if profile.exists():
            tar.add(profile, arcname=f"profiles/{profile.name}")
        if reports.is_dir():
            tar.add(reports, arcname="reports")
    return path
