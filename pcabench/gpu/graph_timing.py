"""The step captured as a CUDA graph against plain launches, alternating, best of several rounds (stage 4)."""

from __future__ import annotations

import numpy as np

from solvers import GPU_SOLVER, Scene, make_solver
from solvers.physics.integrators import step_program


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
    block, cells = solver.blocks_of[current].copy(), solver.nnps.cells[current].copy()
    begin, t0 = solver.nnps.begin.copy(), solver.t
    u = {}
    for name, one_step in (("plain", plain), ("graph", graph.step)):
        solver.set_state(current)
        solver.blocks_of[current][...] = block
        solver.nnps.cells[current][...] = cells
        solver.nnps.begin[...] = begin
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
