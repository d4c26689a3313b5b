"""Peak resident memory of a run: compile, place the particles, take one step."""

from .common import Prepared, Unsupported, cpu_dx, is_all_pairs, solver_names


class PeakMemory:
    params = [solver_names("cpu"), ["float64", "float32"], list(cpu_dx())]
    param_names = ["solver", "precision", "dx"]
    timeout = 300

    def setup(self, solver, precision, dx):
        if is_all_pairs(solver) and dx < 0.25:
            raise NotImplementedError("all-pair is benchmarked up to 16K particles")

    def peakmem_run(self, solver, precision, dx):
        try:
            Prepared(solver, precision, dx).step()
        except Unsupported:
            pass
