"""JIT compilation, which every other benchmark keeps out of its timed region, timed on its own.

Each measurement starts a fresh interpreter, as a new user's first run does.
"""

from .common import jit_seconds_in_fresh_process, solver_names


class TrackJIT:
    params = [solver_names("cpu"), ["float64", "float32"]]
    param_names = ["solver", "precision"]
    unit = "s"
    timeout = 600

    def track_jit_seconds(self, solver, precision):
        return jit_seconds_in_fresh_process(solver, precision)
