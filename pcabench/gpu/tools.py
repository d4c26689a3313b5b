"""The GPU check's subprocess stages (asv, pytest-benchmark, the GPU tests, Nsight Compute), each logged
(stages 6-8)."""

from __future__ import annotations

import subprocess
import sys
import time
from pathlib import Path

from pcabench.gpu.plan import Plan
from pcabench.store.safeio import fresh
from solvers import GPU_SOLVER


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
