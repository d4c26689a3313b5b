"""linkedlist-gpu: one step and each stage, float32 and float64 (skipped where no CUDA GPU exists).

Every timed call ends with a device synchronisation, so the queued kernels are
inside the measurement. ``track_step_ms`` times the same step with CUDA
events instead of the host clock. Nothing touches CUDA at import: the check
runs in ``setup``.
"""

import shutil
import tempfile

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
    """The GPU kernels' compile in a fresh interpreter: cold (an empty JIT cache) and cached (numba-cuda's
    cache of the kernels, per compute capability, filled by a first process)."""

    params = [["float32", "float64"], ["cold", "cached"]]
    param_names = ["precision", "cache"]
    unit = "s"
    timeout = 600

    def setup(self, precision, cache):
        if not gpu_available():
            raise NotImplementedError("no CUDA GPU on this machine")
        self.folder = tempfile.mkdtemp(prefix="pcabench-jit-")
        if cache == "cached":
            jit_seconds_in_fresh_process("linkedlist-gpu", precision, self.folder)

    def teardown(self, *_):
        if hasattr(self, "folder"):
            shutil.rmtree(self.folder, ignore_errors=True)

    def track_jit_seconds(self, precision, cache):
        return jit_seconds_in_fresh_process("linkedlist-gpu", precision, self.folder)
