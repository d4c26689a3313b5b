"""This machine's memory, for the harness: what a run may use, and whether an error was an out-of-memory.

A :class:`~solvers.scene.Scene` is a pure value: it checks its arrays against
``memory_limit_bytes`` when it states one and never reads the machine. The
harness reads the machine here, before any work: :func:`bounded` gives a scene
the memory this process may use now (MemAvailable and every level of its
cgroup), so a run that will not fit is refused with the scene's own one-line
SceneError (naming dx and the smallest dx that fits) before anything runs.
"""

from __future__ import annotations

import os
import sys

from solvers.scene import Scene

CGROUP_MOUNT = "/sys/fs/cgroup"
PROC_CGROUP = "/proc/self/cgroup"  # this process's cgroup in each hierarchy
# cgroup v2 (the unified hierarchy at the mount) and v1 (its memory hierarchy): folder, limit, usage, events
CGROUP_MEMORY = (
    ("", "memory.max", "memory.current", "memory.events"),
    ("memory", "memory.limit_in_bytes", "memory.usage_in_bytes", "memory.oom_control"),
)


def _read_int(path: str) -> int | None:
    try:
        with open(path) as f:
            text = f.read().split()[0]
        return None if text == "max" else int(text)
    except (OSError, ValueError, IndexError):
        return None


def cgroup_memory_folders() -> list[tuple[str, str, str, str]]:
    """``(folder, limit, usage, events)`` files of this process's memory cgroup and each of its ancestors,
    v2 then v1, innermost first: every level's limit applies, and a nested one may be the smallest."""
    own = {}
    try:
        with open(PROC_CGROUP) as f:
            for line in f:
                _, controllers, path = line.rstrip("\n").split(":", 2)
                for sub, *_ in CGROUP_MEMORY:
                    if (controllers == "") if sub == "" else (sub in controllers.split(",")):
                        own[sub] = path
    except (OSError, ValueError):
        pass
    out = []
    for sub, limit, usage, events in CGROUP_MEMORY:
        parts = [p for p in own.get(sub, "/").split("/") if p not in ("", ".", "..")]
        for k in range(len(parts), -1, -1):
            folder = os.path.join(CGROUP_MOUNT, sub, *parts[:k])
            if os.path.isdir(folder):
                out.append(
                    (folder, os.path.join(folder, limit), os.path.join(folder, usage), os.path.join(folder, events))
                )
    return out


def available_memory_bytes() -> int:
    """Memory this process may still use, bytes: the smallest of the host's available memory
    (MemAvailable) and, at every level of its cgroup (v2 memory.max, v1 memory.limit_in_bytes), the
    limit less the usage."""
    limits = []
    try:
        with open("/proc/meminfo") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    limits.append(int(line.split()[1]) * 1024)
    except (OSError, ValueError):
        pass
    for _, limit_path, usage_path, _ in cgroup_memory_folders():
        limit = _read_int(limit_path)
        if limit is not None and limit < 2**60:
            limits.append(max(limit - (_read_int(usage_path) or 0), 0))
    if not limits:
        try:
            limits.append(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
        except (ValueError, OSError, AttributeError):  # pragma: no cover - non-POSIX
            limits.append(16 * 2**30)
    return min(limits)


def bounded(scene: Scene) -> Scene:
    """``scene`` with ``memory_limit_bytes`` set to what this process may use now (unless it states its
    own limit): a SceneError naming dx and the smallest dx that fits where its arrays do not fit. The
    limit also lets linkedlist-cpu's ``auto`` take the pair list only where the list fits."""
    if scene.memory_limit_bytes is not None:
        return scene
    return scene.replace(memory_limit_bytes=available_memory_bytes())


# ---------------------------------------------------------------- out-of-memory, by exception type
CUDA_ERROR_OUT_OF_MEMORY = 2  # the driver API's CUresult (numba-cuda's CudaAPIError.code)
CUDA_ERROR_MEMORY_ALLOCATION = 2  # the runtime API's cudaErrorMemoryAllocation (CuPy's CUDARuntimeError.status)


def _loaded(module: str, name: str):
    """Class ``name`` of ``module`` if that module is already imported, else None (a GPU library that
    was never imported cannot have raised: nothing is imported here)."""
    return getattr(sys.modules.get(module), name, None)


def _code(exc: BaseException, attr: str) -> int | None:
    try:
        return int(getattr(exc, attr))
    except (AttributeError, TypeError, ValueError):
        return None


def is_out_of_memory(exc: BaseException) -> bool:
    """Whether ``exc`` (or an exception it was raised from) is an out-of-memory: a MemoryError, CuPy's
    OutOfMemoryError, CuPy's CUDARuntimeError with cudaErrorMemoryAllocation, or numba-cuda's
    CudaAPIError with CUDA_ERROR_OUT_OF_MEMORY. Recognised by type and code, never by message text."""
    kinds = [(MemoryError, None, None)]
    for module, name, attr, code in (
        ("cupy.cuda.memory", "OutOfMemoryError", None, None),
        ("cupy_backends.cuda.api.runtime", "CUDARuntimeError", "status", CUDA_ERROR_MEMORY_ALLOCATION),
        ("numba.cuda.cudadrv.driver", "CudaAPIError", "code", CUDA_ERROR_OUT_OF_MEMORY),
    ):
        cls = _loaded(module, name)
        if isinstance(cls, type):
            kinds.append((cls, attr, code))
    seen = set()
    while exc is not None and id(exc) not in seen:
        seen.add(id(exc))
        for cls, attr, code in kinds:
            if isinstance(exc, cls) and (attr is None or _code(exc, attr) == code):
                return True
        exc = exc.__cause__ or exc.__context__
    return False
