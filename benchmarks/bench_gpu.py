"""linkedlist-gpu: one step and each stage, float32 and float64 (skipped where no CUDA GPU exists).

Every timed call ends with a device synchronisation, so the queued kernels are
inside the measurement. ``track_step_ms`` times the same step with CUDA
events instead of the host clock. Nothing touches CUDA at import: the check
runs in ``setup``.
"""

from .common import Prepared, StageBenchmarks, gpu_available, gpu_dx, jit_seconds_in_fresh_process


class TimeGPUStep(StageBenchmarks):
    params = [["float32", "float64"], list(gpu_dx())]
    param_names = ["precision", "dx"]
    timeout = 300

    def setup(self, precision, dx):
        if not gpu_available():
            raise NotImplementedError("no CUDA GPU on this machine")
        self.p = Prepared("linkedlist-gpu", precision, dx)

    def track_step_ms(self, *_):
        cupy = self.p.solver.cupy
        start, end = cupy.cuda.Event(), cupy.cuda.Event()
        start.record()
        for _ in range(10):
            self.p.step()
        end.record()
        end.synchronize()
        return cupy.cuda.get_elapsed_time(start, end) / 10

    track_step_ms.unit = "ms"


class TrackGPUJIT:
    params = [["float32", "float64"]]
    param_names = ["precision"]
    unit = "s"
    timeout = 600

    def setup(self, precision):
        if not gpu_available():
            raise NotImplementedError("no CUDA GPU on this machine")

    def track_jit_seconds(self, precision):
        return jit_seconds_in_fresh_process("linkedlist-gpu", precision)
