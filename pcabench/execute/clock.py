"""The stage clock: times each operation of a run and books it to a paper stage.

On the CPU the solver's work is synchronous, so a host timer around each
operation is honest. On a GPU the work is queued asynchronously: the CUDA
clock records an event before and after every operation on the stream and
resolves the elapsed times once, after the run, so timing adds no
synchronisation inside the step loop.
"""

from __future__ import annotations

import time
from collections import defaultdict

from solvers.interface import STAGES


class HostClock:
    """perf_counter around each operation, for synchronous (CPU) solvers."""

    def __init__(self):
        self.seconds = defaultdict(float)
        self.calls = defaultdict(int)

    def time(self, stage: str, op, *args):
        t0 = time.perf_counter()
        result = op(*args)
        self.seconds[stage] += time.perf_counter() - t0
        self.calls[stage] += 1
        return result

    def totals(self) -> dict:
        """Seconds spent in each of the six stages."""
        return {s: float(self.seconds.get(s, 0.0)) for s in STAGES}


class CudaEventClock(HostClock):
    """CUDA events around each operation, resolved after the run.

    ``input`` happens before the device is up and ``output`` ends in a copy
    to the host, so those two use the host timer; the device stages use events.
    """

    HOST_STAGES = ("input",)

    def __init__(self, cupy):
        super().__init__()
        self.cupy = cupy
        self.pending = []

    def time(self, stage: str, op, *args):
        if stage in self.HOST_STAGES:
            return super().time(stage, op, *args)
        start, end = self.cupy.cuda.Event(), self.cupy.cuda.Event()
        start.record()
        result = op(*args)
        end.record()
        self.pending.append((stage, start, end))
        self.calls[stage] += 1
        return result

    def totals(self) -> dict:
        if self.pending:
            self.pending[-1][2].synchronize()
            for stage, start, end in self.pending:
                self.seconds[stage] += self.cupy.cuda.get_elapsed_time(start, end) / 1e3
            self.pending.clear()
        return super().totals()


def clock_for(solver):
    """The honest clock for ``solver``: events on a GPU, the host timer otherwise."""
    if getattr(solver, "device", "cpu") == "gpu" and getattr(solver, "cupy", None) is not None:
        return CudaEventClock(solver.cupy)
    return HostClock()
