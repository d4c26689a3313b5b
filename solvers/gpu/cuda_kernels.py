"""The GPU solver's device kernels (numba-cuda), from the shared pair physics.

Imported only once the GPU solver has a device (or numba's simulator), so
that nothing touches CUDA at the import of ``solvers``. The kernels
themselves are the template solvers/loops/gpu.py, specialised here.
"""

from __future__ import annotations

from functools import lru_cache

from numba import cuda

from solvers.gpu.device import device_backend, simulated
from solvers.kernels import DEFAULT_KERNEL
from solvers.kernels.constants import exp_neg_math
from solvers.physics.backend import pair_sources
from solvers.physics.pairs import make_pairs
from solvers.physics.pairs3d import make_pairs3d


def _device_function(fastmath: bool):
    """The decorator for the pair functions: numba-cuda's device functions on a GPU; plain Python in the
    simulator, which would otherwise take a lock around every device call (its swap of the ``cuda`` global),
    and with 32 Python threads per block beside its polling block manager that lock convoy made the
    warm-up and one step at 320 particles take 480 s instead of 12 s. The pair functions never touch
    ``cuda``, so as Python they compute the same thing."""
    if simulated():
        return lambda fn: fn
    return cuda.jit(device=True, fastmath=fastmath)


KERNELS = (
    "cell_count",
    "cell_begin",
    "scatter",
    "continuity",
    "momentum",
    "moments",
    "neighbours",
    "coefficients",
    "kick",
    "advance",
    "corrected_velocity",
    "corrected_continuity",
    "corrected_momentum",
)


# a 3D scene's own kernels (solvers/loops/gpu3d.py); the rest (the scan, the scatter, the coefficients) are the 2D's
KERNELS_3D = (
    "cell_count",
    "continuity",
    "momentum",
    "moments",
    "neighbours",
    "kick",
    "advance",
    "corrected_velocity",
    "corrected_continuity",
    "corrected_momentum",
)


@lru_cache(maxsize=None)
def device_pairs(precision: str, kernel: str = DEFAULT_KERNEL):
    """The pair functions as device functions (plain Python in the simulator) for ``precision`` and ``kernel``."""
    return make_pairs(_device_function(precision == "float32"), exp_neg_math, kernel, precision)


@lru_cache(maxsize=None)
def device_pairs3d(precision: str, kernel: str = DEFAULT_KERNEL):
    """The 3D pair functions (solvers/physics/pairs3d.py) as device functions, as :func:`device_pairs`."""
    return make_pairs3d(_device_function(precision == "float32"), exp_neg_math, kernel, precision)


@lru_cache(maxsize=None)
def kernels(precision: str, kernel: str = DEFAULT_KERNEL, dims: int = 2) -> dict:
    """The device kernels for ``precision`` and ``kernel`` (solvers/loops/gpu.py): on a GPU compiled by
    numba-cuda on first launch and cached on disk once per machine and compute capability
    (solvers/jitcache.py); in the simulator run as Python, so nothing is cached.

    float32 kernels use fastmath (the hardware's approximate expf, ~2 ulp);
    float64 kernels use the accurate libdevice exp. ``dims`` 3: a 3D scene's kernels (solvers/loops/gpu3d.py)
    over the 2D set.
    """
    device_backend()  # the device is usable (or simulated), numba-cuda patched for this NumPy
    from solvers import jitcache

    loops = jitcache.specialise(
        "solvers.loops.gpu",
        bind={"P": f"device_pairs({precision!r}, {kernel!r})", "scan_threads": repr(scan_block())},
        functions=dict.fromkeys(KERNELS, ("cuda.jit", {"fastmath": precision == "float32"})),
        imports=("from solvers.gpu.cuda_kernels import device_pairs",),
        depends=(*pair_sources(kernel), "solvers.gpu.cuda_kernels"),
        cache=not simulated(),
    )
    out = {name: getattr(loops, name) for name in KERNELS}
    if dims == 3:
        third = jitcache.specialise(
            "solvers.loops.gpu3d",
            bind={"P": f"device_pairs3d({precision!r}, {kernel!r})", "C": f"device_pairs({precision!r}, {kernel!r})"},
            functions=dict.fromkeys(KERNELS_3D, ("cuda.jit", {"fastmath": precision == "float32"})),
            imports=("from solvers.gpu.cuda_kernels import device_pairs, device_pairs3d",),
            depends=(*pair_sources(kernel, 3), *pair_sources(kernel), "solvers.gpu.cuda_kernels"),
            cache=not simulated(),
        )
        out.update({name: getattr(third, name) for name in KERNELS_3D})
    return out


def scan_block() -> int:
    """Threads of the one cell_begin block: 1024 on a GPU, 32 in the simulator (a Python thread each)."""
    return 32 if simulated() else 1024
