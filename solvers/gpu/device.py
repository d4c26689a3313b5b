"""The GPU backend: numba-cuda and CuPy on a real device, or numba's CUDA simulator without one."""

from __future__ import annotations

import os
from functools import lru_cache

import numpy as np

from solvers.interface import SolverUnavailable


def simulated() -> bool:
    """True when numba's CUDA simulator is switched on (NUMBA_ENABLE_CUDASIM=1)."""
    return os.environ.get("NUMBA_ENABLE_CUDASIM", "0") == "1"


def _compat_numba_cuda() -> None:
    """Let numba-cuda <= 0.30 run on NumPy 2.5: it registers an overload for ``np.row_stack``, which
    NumPy 2.5 removed, and its first kernel compilation fails without this alias."""
    if not hasattr(np, "row_stack"):
        np.row_stack = np.vstack


@lru_cache(maxsize=None)
def device_backend():
    """(cuda, cupy or None): numba-cuda and, on a real GPU, CuPy. Raises SolverUnavailable."""
    _compat_numba_cuda()
    try:
        from numba import cuda
    except ImportError as exc:  # pragma: no cover - numba without CUDA support
        raise SolverUnavailable(
            'linkedlist-gpu needs numba-cuda: pip install -e ".[gpu-cuda13]" (or .[gpu] for CUDA 12)'
        ) from exc
    if simulated():
        return cuda, None
    try:
        import cupy
    except ImportError as exc:
        raise SolverUnavailable(
            'linkedlist-gpu needs CuPy and a CUDA GPU: pip install -e ".[gpu-cuda13]" (or .[gpu] for CUDA 12) on a '
            "machine with an NVIDIA GPU (or set NUMBA_ENABLE_CUDASIM=1 to run its kernels in the simulator)"
        ) from exc
    try:
        if cupy.cuda.runtime.getDeviceCount() < 1 or not cuda.is_available():
            raise RuntimeError("no CUDA device")
    except Exception as exc:  # noqa: BLE001 - any driver/runtime failure means no usable GPU
        raise SolverUnavailable(
            f"linkedlist-gpu: no CUDA GPU on this machine ({exc}); use linkedlist-cpu, or set "
            "NUMBA_ENABLE_CUDASIM=1 to run its kernels in the simulator"
        ) from exc
    _one_stream()
    return cuda, cupy


def _one_stream() -> None:
    """All work goes to one stream, so numba need not synchronise on every CuPy array it is handed
    (the CUDA Array Interface's default)."""
    from numba import config

    config.CUDA_ARRAY_INTERFACE_SYNC = False
