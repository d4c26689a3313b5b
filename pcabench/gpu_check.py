"""One command that does all the GPU work on a GPU machine.

    pcabench gpu-check --out DIR

1. captures the hardware profile and measures the card's ceilings (device
   copy bandwidth, FP32 and FP64 FMA rate);
2. runs the GPU tests (pytest -m gpu);
3. compares linkedlist-gpu with linkedlist-cpu on a small scene for every
   model and precision (max relative difference of u and drho);
4. times linkedlist-gpu across dx = 0.1 ... 0.004 for both precisions and the
   three models (the paper's full domain, 100 steps by default);
5. times linkedlist-cpu on the same machine, one thread (the paper's CPU
   code) and every core, at dx = 0.1 ... 0.025 for a few steps: Table 6's
   CPU column, so that the speedup compares one machine's CPU and GPU;

The sweeps of 4 and 5 are ordinary sweeps (``sweep.py``): their runs go to
the results store like a study's, under preset ``gpu``, and the reports are
regenerated. DIR gets profile.json, gpu_check.md (tables) and pytest_gpu.log.
"""
from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np

from solvers import MODELS, PRECISIONS, Scene
from solvers.gpu_device import device_backend

from .record import STEP_STAGES, step_seconds
from .run import run
from .spec import ALL_CORES, SERIAL, RunSpec
from .store import store_name

GPU_DX = (0.1, 0.05, 0.025, 0.01, 0.005, 0.004)  # 100K .. 62.5M particles
CPU_DX = (0.1, 0.05, 0.025)  # 100K .. 1.6M: Table 6's CPU column on the GPU's host
CPU_STEPS = 5


def measure_ceilings(cupy) -> dict:
    """Device-to-device copy bandwidth (bytes read + written) and FP32/FP64 FMA rates."""
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

    def fma_kernel(dtype):
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
        k = fma_kernel(dtype)
        m, c = dtype(0.999), dtype(0.001)  # typed constants keep the chain in dtype
        k[threads // 256, 256](x, iters, m, c)
        cupy.cuda.runtime.deviceSynchronize()
        start.record()
        k[threads // 256, 256](x, iters, m, c)
        end.record()
        end.synchronize()
        seconds = cupy.cuda.get_elapsed_time(start, end) / 1e3
        out[key] = round(2 * 8 * iters * threads / seconds / 1e12, 2)
    out["note"] = "measured by pcabench gpu-check (median of 10 copies; one FMA-chain kernel)"
    return out


def compare_with_cpu(dx: float = 0.5, steps: int = 20) -> list[dict]:
    """Max relative difference GPU vs CPU of the final u and drho, every model and precision."""
    rows = []
    for precision in PRECISIONS:
        for model in MODELS:
            scene = Scene(dx=dx, steps=steps, model=model, precision=precision)
            fields = {}
            for solver in ("linkedlist-cpu", "linkedlist-gpu"):
                path = Path(f"/tmp/pcabench_cmp_{solver}.npz")
                rec = run(scene, solver, fields_path=path)
                if rec.status != "ok":
                    raise RuntimeError(f"{solver} {model} {precision}: {rec.status} {rec.message}")
                fields[solver] = np.load(path)
            diff = {}
            for name in ("u", "drho"):
                c, g = fields["linkedlist-cpu"][name], fields["linkedlist-gpu"][name]
                diff[name] = float(np.max(np.abs(g - c)) / np.max(np.abs(c)))
            rows.append({"precision": precision, "model": model, "dx": dx, "steps": steps,
                         "max_rel_diff_u": diff["u"], "max_rel_diff_drho": diff["drho"]})
            print(f"compare {precision} {model}: u {diff['u']:.2e}, drho {diff['drho']:.2e}", flush=True)
    return rows


def gpu_specs(sizes, steps: int, models=MODELS) -> list[RunSpec]:
    """The GPU timing sweep: linkedlist-gpu on the paper's full domain, every size, precision and model."""
    return [RunSpec("linkedlist-gpu", Scene(dx=dx, steps=steps, model=model, precision=precision,
                                            memory_limit_bytes=2**40), preset="gpu")  # the GPU checks its own memory
            for dx in sizes for precision in PRECISIONS for model in models]


def cpu_peer_specs() -> list[RunSpec]:
    """linkedlist-cpu, lagrangian float64, one thread and every core, on this GPU's host: Table 6's CPU column."""
    return [RunSpec("linkedlist-cpu", Scene(dx=dx, steps=CPU_STEPS), threads, preset="gpu")
            for dx in CPU_DX for threads in (SERIAL, ALL_CORES)]


def timing_row(row: dict) -> dict:
    """One stored GPU run as the check's table row: step time, stage shares, ns per particle-step, ps per pair."""
    st, steps, n = row["stages"], max(row["steps"] or 0, 1), row["n_particles"]
    step = step_seconds(st, steps)
    loop = step * steps
    pairs = 2 * n * (row.get("mean_neighbours") or 0)  # both sweeps of a Verlet step
    share = {s: 100 * st[s] / loop if loop else float("nan") for s in STEP_STAGES}
    return {"dx": row["dx"], "N": n, "precision": row["precision"], "model": row["model"], "status": row["status"],
            "step_ms": 1e3 * step, **{f"{s}_pct": share[s] for s in STEP_STAGES},
            "ns_per_particle_step": 1e9 * step / n, "ps_per_pair": 1e12 * step / pairs if pairs else float("nan"),
            "neighbours": row.get("mean_neighbours") or float("nan"),
            "mse": row.get("mse") if row.get("mse") is not None else float("nan"),
            "init_ms": 1e3 * st["init"], "output_ms": 1e3 * st["output"]}


def markdown(profile, compare_rows, gpu_rows, steps, cpu_rows=()) -> str:
    g = profile.get("gpu") or {}
    timing_rows = [timing_row(r) for r in gpu_rows]
    lines = [f"# GPU check: {g.get('name', '?')} ({profile['id']})", "",
             f"Measured ceilings: {json.dumps(profile.get('measured', {}))}", "",
             "## GPU vs linkedlist-cpu (max relative difference after the steps shown)", "",
             "| precision | model | dx | steps | u | drho |", "|---|---|---|---|---|---|"]
    for r in compare_rows:
        lines.append(f"| {r['precision']} | {r['model']} | {r['dx']} | {r['steps']} | "
                     f"{r['max_rel_diff_u']:.2e} | {r['max_rel_diff_drho']:.2e} |")
    lines += ["", f"## Timing, full paper domain, {steps} steps, Verlet, cutoff 3h", "",
              "| dx | N | precision | model | status | step (ms) | SNP % | PI % | SU % | ns/particle-step "
              "| ps/pair | neighbours | MSE | init (ms) | output (ms) |",
              "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in timing_rows:
        lines.append(
            f"| {r['dx']} | {r['N']:,} | {r['precision']} | {r['model']} | {r['status']} | {r['step_ms']:.3f} | "
            f"{r['snp_pct']:.1f} | {r['pi_pct']:.1f} | {r['su_pct']:.1f} | {r['ns_per_particle_step']:.3f} | "
            f"{r['ps_per_pair']:.2f} | {r['neighbours']:.1f} | {r['mse']:.3g} | {r['init_ms']:.1f} | "
            f"{r['output_ms']:.1f} |")
    lines += ["", "ps/pair counts both sweeps of a Verlet step (2 x N x mean neighbours pairs)."]
    if cpu_rows:
        lines += ["", "## linkedlist-cpu on this host (lagrangian, float64)", "",
                  "| dx | N | threads | status | step (ms) |", "|---|---|---|---|---|"]
        lines += [f"| {r['dx']} | {r['n_particles']:,} | {r['threads']} | {r['status']} | "
                  f"{1e3 * step_seconds(r['stages'], r['steps']):.1f} |" for r in cpu_rows]
    return "\n".join(lines) + "\n"


def gpu_check(out: Path, results: Path, reports: Path, sizes=GPU_DX, steps: int = 100, models=MODELS,
              run_tests: bool = True, compare: bool = True, cpu_peer: bool = True, only_ceilings: bool = False,
              run_budget: float = 900.0) -> int:
    """Profile and ceilings, GPU tests, GPU-vs-CPU comparison, then the GPU (and CPU-peer) sweep and reports.

    The sweep is an ordinary sweep (one child process per run, the same store,
    resume and report code as ``pcabench study``); its runs carry preset ``gpu``.
    """
    from . import profiles
    from .reports import write_reports
    from .sweep import sweep

    out.mkdir(parents=True, exist_ok=True)
    _cuda, cupy = device_backend()  # raises SolverUnavailable with a clear message
    profile = profiles.capture()
    if cupy is not None:
        profile["measured"] = measure_ceilings(cupy)
    profiles.save(profile)
    (out / "profile.json").write_text(json.dumps(profile, indent=2) + "\n")
    print(json.dumps(profile, indent=1), flush=True)
    if only_ceilings:
        return 0
    rc = 0
    if run_tests:
        with open(out / "pytest_gpu.log", "w") as log:
            rc = subprocess.run([sys.executable, "-m", "pytest", "-m", "gpu", "-q", "tests"],
                                stdout=log, stderr=subprocess.STDOUT).returncode
        print(f"pytest -m gpu: exit {rc} (log in {out / 'pytest_gpu.log'})", flush=True)
    compare_rows = compare_with_cpu() if compare else []
    store_path = results / store_name(profile["id"])
    gpu_rows = sweep(gpu_specs(sizes, steps, models), store_path, run_budget, sweep_budget=24 * 3600.0)
    cpu_rows = sweep(cpu_peer_specs(), store_path, run_budget, sweep_budget=24 * 3600.0) if cpu_peer else []
    text = markdown(profile, compare_rows, gpu_rows, steps, cpu_rows)
    (out / "gpu_check.md").write_text(text)
    print(text, flush=True)
    for p in write_reports(results, reports):
        print(f"wrote {p}", file=sys.stderr)
    return rc
