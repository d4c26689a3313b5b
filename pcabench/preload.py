"""What a sweep's forkserver (pcabench/forkserver.py) imports once, before it forks any run's child: the
harness and the solvers with numpy and numba, and numba's CPU target initialised (its registries of
typing and lowering, 0.25 s a process here), so that each child starts warm."""

from numba.core.registry import cpu_target

from . import child  # noqa: F401 - the harness, the solvers, numpy and numba

cpu_target.target_context.refresh()
