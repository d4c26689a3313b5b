"""Time one step and each stage (SNP, PI, SU) of every CPU solver, by precision and particle count.

Compilation and the first step happen in ``setup``, outside the timed region
(``bench_jit.py`` times compilation on its own). All-pair stops at 16K
particles; ``PCABENCH_BENCH_LARGE=1`` adds 100K and 400K for the linked list.
"""

from .common import Prepared, StageBenchmarks, Unsupported, cpu_dx, solver_names


class TimeStep(StageBenchmarks):
    params = [solver_names("cpu"), ["float64", "float32"], list(cpu_dx())]
    param_names = ["solver", "precision", "dx"]
    timeout = 300
    min_run_count = 3

    def setup(self, solver, precision, dx):
        try:
            self.p = Prepared(solver, precision, dx)
        except Unsupported as exc:
            raise NotImplementedError(str(exc)) from None


class TimeStepThreads:
    """The multi-threaded linked list on every core numba may use (the honest CPU peer)."""

    params = [["float64", "float32"], list(cpu_dx())]
    param_names = ["precision", "dx"]
    timeout = 300

    def setup(self, precision, dx):
        import numba

        self.p = Prepared("linkedlist-cpu", precision, dx, threads=numba.config.NUMBA_NUM_THREADS)

    def time_step(self, *_):
        self.p.step()
