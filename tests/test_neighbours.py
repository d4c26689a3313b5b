"""mean_neighbours has no side effect: it counts on a cell list of its own, leaving the particles, their
order and the solver's cell list as they were, and counts what re-sorting the state counted."""

from __future__ import annotations

import os

import numpy as np
import pytest

from solvers import Scene, make_solver

from .conftest import in_simulator

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def advanced(solver, scene, steps=4):
    solver.input(scene)
    solver.init()
    for _ in range(steps):
        solver.snp()
        solver.rates(True, True)
        solver.kick(0.5)
        solver.advance(1.0)  # the particles moved since the last search: the cell list is stale
    return solver


def snapshot(solver) -> dict:
    """Every per-particle array (object and values), the cell list and the clock."""
    out = {f"arrays.{k}": (id(v), np.array(solver.to_host(v), copy=True)) for k, v in solver.arrays.items()}
    for name in ("cell", "begin", "order", "sorted_cell"):
        if getattr(solver.nnps, name, None) is not None:
            v = getattr(solver.nnps, name)
            out[name] = (id(v), np.array(solver.to_host(v), copy=True))
    out["scalars"] = (0, np.array([solver.t, solver.nnps.valid], dtype=float))
    return out


def assert_unchanged(before: dict, after: dict) -> None:
    assert before.keys() == after.keys()
    for key, (ident, values) in before.items():
        assert after[key][0] == ident, f"{key} was replaced"
        np.testing.assert_array_equal(after[key][1], values, err_msg=key)


def resorted_count(solver) -> int:
    """The count as mean_neighbours made it before: re-sort the state, then count on the solver's cell list."""
    solver.nnps.valid = False
    solver.snp()
    return int(solver.launch("neighbours", *solver.geometry(), solver.k))


@pytest.mark.parametrize("threads,pair_loop", [(1, "list"), (1, "gather"), (2, "list")])
@pytest.mark.parametrize("model", ["lagrangian", "fixed"])
def test_mean_neighbours_leaves_the_state_as_it_was(threads, pair_loop, model):
    import numba

    if threads > numba.config.NUMBA_NUM_THREADS:
        pytest.skip("one numba thread here")
    scene = Scene(dx=1.0, steps=4, model=model, mach=0.3)  # a strong pulse: particles change cells
    solver = advanced(make_solver("linkedlist-cpu", threads=threads, pair_loop=pair_loop), scene)
    before = snapshot(solver)
    mean = solver.mean_neighbours()
    assert_unchanged(before, snapshot(solver))
    assert solver.mean_neighbours() == mean  # and again: nothing moved
    assert mean * scene.n_particles == resorted_count(solver)  # the count the re-sorting version made
    assert 100 < mean < 140  # about pi (3 h / dx)^2


def test_allpair_mean_neighbours_leaves_the_state_as_it_was():
    scene = Scene(dx=1.0, steps=2, mach=0.3)
    solver = advanced(make_solver("allpair-cpu"), scene, 2)
    before = snapshot(solver)
    mean = solver.mean_neighbours()
    assert_unchanged(before, snapshot(solver))
    reference = advanced(make_solver("linkedlist-cpu"), scene, 2).mean_neighbours()
    assert mean == reference


SIM_SCRIPT = r"""
import json, numpy as np
from solvers import Scene, make_solver
scene = Scene(dx=1.0, x_min=-8.0, x_max=8.0, steps=3, mach=0.3)
s = make_solver("linkedlist-gpu")
s.input(scene); s.init()
for _ in range(3):
    s.snp(); s.rates(True, True); s.kick(0.5); s.advance(1.0)
keep = {"current": s.state(), "cell": s.nnps.cell.copy(), "begin": s.nnps.begin.copy(), "order": s.nnps.order.copy(),
        **{k: v.copy() for k, v in s.arrays.items()}}
mean = s.mean_neighbours()
same = s.state() == keep["current"] and all(np.array_equal(s.arrays[k], v) for k, v in keep.items()
                                            if k in s.arrays)
same = same and all(np.array_equal(getattr(s.nnps, k), keep[k]) for k in ("cell", "begin", "order"))
s.nnps.valid = False; s.snp()
counts = np.zeros(scene.n_particles, np.int32)
s.launch("neighbours", *s.geometry(), counts, s.k)
cpu = make_solver("linkedlist-cpu"); cpu.input(scene); cpu.init()
for _ in range(3):
    cpu.snp(); cpu.rates(True, True); cpu.kick(0.5); cpu.advance(1.0)
print(json.dumps({"same": bool(same), "mean": mean, "resorted": int(counts.sum()) / scene.n_particles,
                  "cpu": cpu.mean_neighbours()}))
"""


@pytest.mark.tier2  # 11 s warm in the simulator: the README command kept within 5 minutes (2026-12-08)
def test_simulated_gpu_mean_neighbours_leaves_the_state_as_it_was():
    out = in_simulator(SIM_SCRIPT)
    assert out["same"] and out["mean"] == out["resorted"] == pytest.approx(out["cpu"]), out
