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

and writes DIR/profile.json, DIR/gpu_results.jsonl (run records),
DIR/gpu_check.md (tables) and DIR/pytest_gpu.log.
"""
from __future__ import annotations

import argparse
import json
import math
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

PAPER_SIZES = (0.1, 0.05, 0.025, 0.01, 0.005, 0.004)
CPU_SIZES = (0.1, 0.05, 0.025)  # 100K .. 1.6M: Table 6's CPU column on the GPU's host
CPU_STEPS = 5
MODELS = ("lagrangian", "fixed", "linear")
PRECISIONS = ("float32", "float64")


def measure_ceilings(cupy) -> dict:
    """Device-to-device copy bandwidth (bytes read + written) and FP32/FP64 FMA rates."""
    from solvers.linkedlist_gpu import device_backend

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
    from pcabench.run import run
    from solvers import Scene

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


def timing_sweep(sizes, steps: int, store_path: Path, profile_id: str, models=MODELS) -> list[dict]:
    from pcabench import store
    from pcabench.run import run
    from solvers import Scene

    rows = []
    for dx in sizes:
        for precision in PRECISIONS:
            for model in models:
                scene = Scene(dx=dx, steps=steps, model=model, precision=precision,
                              memory_limit_bytes=2**40)  # the GPU solver checks its own memory
                t0 = time.perf_counter()
                rec = run(scene, "linkedlist-gpu", profile_id=profile_id)
                row = store.append(rec, store_path)
                step = rec.step_seconds
                pairs = 2 * rec.n_particles * (rec.mean_neighbours if math.isfinite(rec.mean_neighbours) else 0)
                st = rec.stages
                loop = st["snp"] + st["pi"] + st["su"]
                row_out = {
                    "dx": dx, "N": rec.n_particles, "precision": precision, "model": model,
                    "status": rec.status, "step_ms": 1e3 * step,
                    "snp_pct": 100 * st["snp"] / loop if loop else float("nan"),
                    "pi_pct": 100 * st["pi"] / loop if loop else float("nan"),
                    "su_pct": 100 * st["su"] / loop if loop else float("nan"),
                    "ns_per_particle_step": 1e9 * step / rec.n_particles,
                    "ps_per_pair": 1e12 * step / pairs if pairs else float("nan"),
                    "neighbours": rec.mean_neighbours, "mse": rec.mse,
                    "init_ms": 1e3 * st["init"], "output_ms": 1e3 * st["output"],
                    "jit_s": rec.jit_seconds, "wall_s": time.perf_counter() - t0,
                }
                rows.append(row_out)
                print(" ".join(f"{k}={v:.4g}" if isinstance(v, float) else f"{k}={v}"
                               for k, v in row_out.items()), flush=True)
                if rec.status != "ok":
                    print(f"   {rec.message.splitlines()[0] if rec.message else ''}", flush=True)
    return rows


def cpu_peer(sizes, steps: int, store_path: Path, profile_id: str) -> list[dict]:
    """linkedlist-cpu, lagrangian float64, one thread and every core, on this GPU's host."""
    from pcabench import store
    from pcabench.run import run
    from solvers import Scene
    from pcabench.study import all_cores

    rows = []
    for dx in sizes:
        for threads in sorted({1, all_cores()}):
            rec = run(Scene(dx=dx, steps=steps), "linkedlist-cpu", threads=threads, profile_id=profile_id)
            store.append(rec, store_path)
            rows.append({"dx": dx, "N": rec.n_particles, "threads": threads, "status": rec.status,
                         "step_ms": 1e3 * rec.step_seconds})
            print(f"cpu dx={dx} N={rec.n_particles} threads={threads}: {rec.status}, "
                  f"{1e3 * rec.step_seconds:.1f} ms per step", flush=True)
    return rows


def markdown(profile, compare_rows, timing_rows, steps, cpu_rows=()) -> str:
    g = profile.get("gpu") or {}
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
        lines += [f"| {r['dx']} | {r['N']:,} | {r['threads']} | {r['status']} | {r['step_ms']:.1f} |"
                  for r in cpu_rows]
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="pcabench gpu-check", description=__doc__.split("\n")[0])
    parser.add_argument("--out", default="gpu_check_out", help="folder for the results")
    parser.add_argument("--sizes", type=float, nargs="+", default=list(PAPER_SIZES))
    parser.add_argument("--steps", type=int, default=100)
    parser.add_argument("--models", nargs="+", default=list(MODELS), choices=MODELS)
    parser.add_argument("--skip-tests", action="store_true")
    parser.add_argument("--skip-compare", action="store_true")
    parser.add_argument("--skip-cpu", action="store_true", help="no linkedlist-cpu timings on this host")
    parser.add_argument("--only-ceilings", action="store_true", help="profile and measured ceilings only")
    args = parser.parse_args(argv)
    return gpu_check(args)


def gpu_check(args) -> int:
    from pcabench import profiles
    from solvers.linkedlist_gpu import device_backend

    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    _cuda, cupy = device_backend()  # raises SolverUnavailable with a clear message
    profile = profiles.capture()
    if cupy is not None:
        profile["measured"] = measure_ceilings(cupy)
    (out / "profile.json").write_text(json.dumps(profile, indent=2) + "\n")
    print(json.dumps(profile, indent=1), flush=True)
    if args.only_ceilings:
        return 0
    rc = 0
    if not args.skip_tests:
        with open(out / "pytest_gpu.log", "w") as log:
            rc = subprocess.run([sys.executable, "-m", "pytest", "-m", "gpu", "-q", "tests"],
                                stdout=log, stderr=subprocess.STDOUT).returncode
        print(f"pytest -m gpu: exit {rc} (log in {out / 'pytest_gpu.log'})", flush=True)
    compare_rows = [] if args.skip_compare else compare_with_cpu()
    timing_rows = timing_sweep(args.sizes, args.steps, out / "gpu_results.jsonl", profile["id"],
                               models=args.models)
    cpu_rows = [] if args.skip_cpu else cpu_peer(CPU_SIZES, CPU_STEPS, out / "gpu_results.jsonl", profile["id"])
    text = markdown(profile, compare_rows, timing_rows, args.steps, cpu_rows)
    (out / "gpu_check.md").write_text(text)
    print(text, flush=True)
    return rc


if __name__ == "__main__":
    sys.exit(main())
