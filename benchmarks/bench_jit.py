"""JIT compilation, which every other benchmark keeps out of its timed region, timed on its own.

Each measurement starts a fresh interpreter. ``cold``: with an empty JIT cache (solvers/jitcache.py), as a
new user's first run of a configuration meets it; ``cached``: with the cache a first process filled, as
every later run meets it.
"""

import shutil
import tempfile

from .common import jit_seconds_in_fresh_process, solver_names


class TrackJIT:
    params = [solver_names("cpu"), ["float64", "float32"], ["cold", "cached"]]
    param_names = ["solver", "precision", "cache"]
    unit = "s"
    timeout = 600

    def setup(self, solver, precision, cache):
        self.folder = tempfile.mkdtemp(prefix="pcabench-jit-")
        if cache == "cached":
            jit_seconds_in_fresh_process(solver, precision, self.folder)  # fills it

    def teardown(self, *_):
        shutil.rmtree(self.folder, ignore_errors=True)

    def track_jit_seconds(self, solver, precision, cache):
        return jit_seconds_in_fresh_process(solver, precision, self.folder)
