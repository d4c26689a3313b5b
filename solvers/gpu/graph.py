"""The GPU step captured once as a CUDA graph and replayed (CuPy stream capture, numba-cuda launches).

A step of linkedlist-gpu is a fixed list of launches on the solver's stream
with every buffer allocated before the time loop, so capturing it records the
whole step. A step that searches ends with the other particle block current,
so the steps of one cycle of blocks (one graph per block: two for moving
particles, one otherwise) are captured; replaying them in turn advances the
state exactly as the plain launches would, with one graph launch per step
instead of eight kernel launches from Python. Needs a real GPU (numba's
simulator has no streams to capture).
"""

from __future__ import annotations

from solvers.physics.integrators import step_program

GRAPH_INTEGRATORS = ("verlet", "kdk1", "euler")  # the steps that allocate nothing


class CapturedSteps:
    """One graph per particle block; :meth:`step` replays the one for the current block.

    The solver must have taken its first (priming) step already: that one can differ from the rest.
    Plain steps and graph steps may be mixed: each graph is chosen by the block it starts from.
    """

    def __init__(self, solver, integrator: str = "verlet"):
        if solver.stream is None:
            raise RuntimeError("CUDA graph capture needs a real GPU stream (not the simulator)")
        if integrator not in GRAPH_INTEGRATORS:
            raise ValueError(
                f"integrator: the graph path replays {', '.join(GRAPH_INTEGRATORS)} "
                f"(got {integrator!r}; rk2 allocates its saved copies inside the step)"
            )
        if getattr(solver, "absorber", None) is not None:
            raise ValueError(
                "--open: the graph path replays closed scenes only (an open edge's layer keeps damping factors "
                "that capture would record but never compute)"
            )
        if getattr(getattr(solver, "correction", None), "allocates", False):
            raise ValueError(
                "--correction: the graph path replays uncorrected steps only (a correction's per-particle passes "
                "allocate their arrays inside the step)"
            )
        self.solver = solver
        t0, start = solver.t, solver.state()
        self.graphs = {}  # block it starts from -> (graph, block current after it, seconds it advances)
        while solver.state() not in self.graphs:
            before, t_before = solver.state(), solver.t
            solver.stream.begin_capture()
            try:
                for _stage, op in step_program(integrator, solver, first=False):
                    op()
            finally:
                graph = solver.stream.end_capture()
            self.graphs[before] = (graph, solver.state(), solver.t - t_before)
        solver.set_state(start)  # capturing ran no kernel: the device state is still the one before
        solver.t = t0

    def step(self) -> None:
        """One step: launch the graph for the current block on the solver's stream (asynchronous)."""
        graph, after, dt = self.graphs[self.solver.state()]
        graph.launch(self.solver.stream)
        self.solver.set_state(after)
        self.solver.t += dt
