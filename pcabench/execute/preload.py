"""What a sweep's forkserver (pcabench/execute/forkserver.py) does once, before it forks any run's child: import the
harness and the solvers with numpy and numba, initialise numba's CPU target (its registries of typing and
lowering, 0.25 s a process here), and load from the disk cache the compiled loops of the sweep's serial
CPU configurations (:func:`warm`), so that each child starts warm."""

import json
import os
import warnings

from numba.core.registry import cpu_target

from solvers.plugins import PluginWarning

warnings.filterwarnings("ignore", category=PluginWarning)  # the sweep (the parent) says it once

from pcabench.execute import child  # noqa: E402, F401 - the harness, the solvers, numpy and numba

WARM = "PCABENCH_WARM"  # the forkserver's environment: a JSON list of the sweep's RunSpecs to warm
from pcabench.execute.ahead import WARMED  # noqa: E402 - built-in CPU solvers whose serial warm-up starts no thread


def warm(specs: list) -> int:
    """Load each serial built-in CPU spec's compiled loops from the disk cache (its solver's warm-up on a
    tiny scene), compiling nothing: a configuration not cached yet is left to its first run, which
    compiles and reports it. No GPU (CUDA does not survive a fork) and no threads (nor does numba's pool).
    How many configurations were warmed."""
    from solvers import jitcache
    from solvers.interface import tiny_scene
    from solvers.registry import make_solver

    warmed = 0
    for spec in specs:
        if spec.solver not in WARMED or spec.threads != 1:
            continue
        try:
            with jitcache.loads_only():
                solver = make_solver(spec.solver, threads=1, pair_loop=spec.pair_loop)
                solver.input(tiny_scene(spec.scene))  # the loops, not the scene's arrays
                solver.warmup()
            warmed += 1
        except Exception:  # noqa: BLE001 - not cached (NotCached) or anything else: the run will say
            pass
    return warmed


cpu_target.target_context.refresh()
if os.environ.get(WARM):
    from pcabench.spec import RunSpec

    warm([RunSpec.from_json(json.dumps(s)) for s in json.loads(os.environ[WARM])])
