"""linkedlist-gpu: the kernels agree with linkedlist-cpu.

CI has no GPU: the simulator tests run the same numba-cuda kernels in numba's
CUDA simulator (NUMBA_ENABLE_CUDASIM=1, NumPy in place of CuPy) in a
subprocess, on a few hundred particles. The ``gpu`` tests run on a real GPU
and skip cleanly without one.
"""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest

from solvers import Scene, SceneError, SolverUnavailable, make_solver

from .conftest import in_simulator, run_fields

SIM_SCRIPT = r"""
import json, sys, tempfile, numpy as np
from pathlib import Path
from pcabench.execute.run import run
from pcabench.spec import RunSpec
from solvers import Scene
precision, model, steps, integrator, kernel = sys.argv[1], sys.argv[2], int(sys.argv[3]), sys.argv[4], sys.argv[5]
scene = Scene(dx=1.0, x_min=-8.0, x_max=8.0, steps=steps, model=model, precision=precision, integrator=integrator,
              kernel=kernel)
out = {}
with tempfile.TemporaryDirectory() as d:
    for solver in ("linkedlist-cpu", "linkedlist-gpu"):
        p = Path(d) / (solver + ".npz")
        rec = run(RunSpec(solver, scene), fields_path=p)
        out[solver] = {"status": rec.status, "message": rec.message[:500], "neighbours": rec.mean_neighbours}
        if rec.status == "ok":
            out[solver]["fields"] = {k: np.load(p)[k].tolist() for k in ("u", "drho", "x")}
print(json.dumps(out))
"""


def _simulate(precision, model, steps, integrator="verlet", kernel="gaussian"):
    return in_simulator(SIM_SCRIPT, precision, model, steps, integrator, kernel)


def _max_rel(a, b):
    a, b = np.asarray(a), np.asarray(b)
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))


@pytest.mark.tier2  # the simulator feature by feature; check-solver's GPU case (default tier) covers them
@pytest.mark.parametrize(
    "precision,model,steps,tol",
    [
        ("float64", "lagrangian", 20, 1e-12),
        ("float32", "linear", 8, 2e-5),
    ],
)
def test_simulated_gpu_kernels_match_cpu(precision, model, steps, tol):
    out = _simulate(precision, model, steps)
    cpu, gpu = out["linkedlist-cpu"], out["linkedlist-gpu"]
    assert cpu["status"] == "ok" and gpu["status"] == "ok", (cpu["message"], gpu["message"])
    assert gpu["neighbours"] == pytest.approx(cpu["neighbours"])
    for name in ("u", "drho", "x"):
        assert _max_rel(gpu["fields"][name], cpu["fields"][name]) < tol, name


def test_gpu_solver_without_gpu_says_so(monkeypatch):
    from solvers import linkedlist_gpu

    if not linkedlist_gpu.simulated():
        try:
            linkedlist_gpu.device_backend()
        except SolverUnavailable as exc:
            assert "GPU" in str(exc)
            return
    pytest.skip("a GPU (or the simulator) is present here")


def test_gpu_cli_without_gpu_exits_clearly():
    from .conftest import gpu_available

    if gpu_available():
        pytest.skip("a GPU is present")
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_ENABLE_CUDASIM"}
    proc = subprocess.run(
        [sys.executable, "-m", "pcabench.cli", "run", "--solver", "linkedlist-gpu", "--dx", "1"],
        capture_output=True,
        text=True,
        env=env,
        timeout=300,
    )
    assert proc.returncode == 3
    assert "GPU" in proc.stderr and "Traceback" not in proc.stderr


# ------------------------------------------------------------ on a real GPU
@pytest.mark.gpu
@pytest.mark.parametrize("model", ["lagrangian", "fixed", "linear"])
def test_gpu_float64_matches_cpu(requires_gpu, tmp_path, model):
    scene = Scene(dx=0.25, steps=20, model=model)
    cpu_rec, cpu = run_fields(scene, "linkedlist-cpu", tmp_path)
    gpu_rec, gpu = run_fields(scene, "linkedlist-gpu", tmp_path)
    assert cpu_rec.status == gpu_rec.status == "ok", gpu_rec.message
    for name in ("u", "drho", "x"):
        assert _max_rel(gpu[name], cpu[name]) < 1e-12, name


@pytest.mark.gpu
def test_gpu_float32_matches_float64(requires_gpu, tmp_path):
    scene = Scene(dx=0.1, steps=100, model="linear", strip_height=2.0)
    r64, f64 = run_fields(scene, "linkedlist-gpu", tmp_path)
    r32, f32 = run_fields(scene.replace(precision="float32"), "linkedlist-gpu", tmp_path)
    assert r64.status == r32.status == "ok"
    assert _max_rel(f32["u"], f64["u"]) < 1e-4
    assert abs(r32.mse - r64.mse) < 1e-4


@pytest.mark.gpu
def test_gpu_refuses_scene_larger_than_card(requires_gpu):
    solver = make_solver("linkedlist-gpu")
    scene = Scene(dx=0.001, memory_limit_bytes=2**50)  # 1e9 particles, ~240 GB
    with pytest.raises(SceneError, match="smallest dx that fits"):
        solver.input(scene)


# ------------------------------------------------------------ launches per step (simulator)
LAUNCH_SCRIPT = r"""
import json, numpy as np
from numba.cuda.simulator.kernel import FakeCUDAKernel
from solvers import Scene, make_solver
from solvers.physics.integrators import step_program
from solvers.gpu.cuda_kernels import kernels, scan_block

launches = []
plain_call = FakeCUDAKernel.__call__
def counted(self, *args):
    if not self._device:
        launches.append(self.fn.__name__)
    return plain_call(self, *args)
FakeCUDAKernel.__call__ = counted

class Untouchable:
    "Stands for the array module during a step: any use would be a launch or a host round trip."
    def __init__(self, used): self.used = used
    def __getattr__(self, name):
        self.used.append(name)
        raise AssertionError(f"xp.{name} inside a step")

out = {}
for integrator in ("verlet", "kdk1", "euler"):
    solver = make_solver("linkedlist-gpu")
    solver.input(Scene(dx=1.0, x_min=-8.0, x_max=8.0, model="lagrangian", integrator=integrator))
    solver.init()
    for _stage, op in step_program(integrator, solver, first=True):
        op()
    used, syncs = [], []
    xp, solver.xp = solver.xp, Untouchable(used)
    solver.synchronize = lambda: syncs.append(1)
    launches.clear()
    for _stage, op in step_program(integrator, solver, first=False):
        op()
    solver.xp = xp
    out[integrator] = {"launches": list(launches), "xp": used, "syncs": len(syncs)}

# cellBegin over many tiles of the one-block scan, against NumPy
rng = np.random.default_rng(1)
counts = rng.integers(0, 9, size=7 * scan_block() * 4 + 5).astype(np.int32)
begin = np.zeros(counts.size + 1, np.uint32)
expected = np.concatenate([[0], np.cumsum(counts)])
kernels("float64")["cell_begin"][1, scan_block()](counts, begin)
out["scan"] = {"ok": bool(np.array_equal(begin, expected)), "zeroed": bool(not counts.any())}
print(json.dumps(out))
"""


@pytest.mark.tier2  # a few steps in numba's CUDA simulator: 23 s (the second tier; the other simulator tests stay)
def test_simulated_step_launches_and_host_round_trips():
    """A lagrangian Verlet step is at most 8 kernel launches, touches no array-module operation (each would be
    a CuPy launch or a host round trip on a GPU) and never synchronises; the one-block cellBegin scan is exact."""
    out = in_simulator(LAUNCH_SCRIPT)
    verlet = out["verlet"]
    assert len(verlet["launches"]) <= 8, verlet["launches"]
    assert {"cell_count", "cell_begin", "scatter", "continuity", "momentum"} <= set(verlet["launches"])
    for integrator in ("verlet", "kdk1", "euler"):
        assert out[integrator]["xp"] == [] and out[integrator]["syncs"] == 0, out[integrator]
    assert out["scan"] == {"ok": True, "zeroed": True}


@pytest.mark.tier2  # the simulator feature by feature; check-solver's GPU case (default tier) covers them
@pytest.mark.parametrize("integrator", ["rk2", "kdk1"])
def test_simulated_gpu_integrators_match_cpu(integrator):
    """The counting sort carries the two-stage integrator's saved copies along (rk2) and the one-sweep step."""
    out = _simulate("float64", "lagrangian", 6, integrator)
    cpu, gpu = out["linkedlist-cpu"], out["linkedlist-gpu"]
    assert cpu["status"] == "ok" and gpu["status"] == "ok", (cpu["message"], gpu["message"])
    for name in ("u", "drho", "x"):
        assert _max_rel(gpu["fields"][name], cpu["fields"][name]) < 1e-12, name


@pytest.mark.gpu
@pytest.mark.parametrize("precision,tol", [("float64", 1e-12), ("float32", 1e-4)])
def test_gpu_graph_replays_the_plain_step(requires_gpu, precision, tol):
    """The captured step (CUDA graph) advances the state as the plain launches do, from one state."""
    from pcabench.gpu.graph_timing import graph_vs_plain

    row = graph_vs_plain(0.25, precision, steps=10, rounds=1, scene_overrides={})
    assert row["max_rel_diff_u"] < tol, row
    assert row["graph_ms"] > 0 and row["plain_ms"] > 0


@pytest.mark.gpu
def test_gpu_walls_match_cpu(requires_gpu, tmp_path):
    """The GPU check's walls stage on the card: plane-wall and pulse-wall (mirror particles), linear and
    lagrangian, float64 and float32, against linkedlist-cpu."""
    from pcabench.gpu.agreement import agrees
    from pcabench.studies.paper.gpu import FULL
    from pcabench.studies.walls import gpu as walls_gpu

    cases = walls_gpu.cases(rehearse=False)
    rows = walls_gpu.against_cpu(cases, FULL.compare_steps, tmp_path)
    assert len(rows) == len(cases.scenes) * 2 * len(cases.models) and agrees(rows), rows
