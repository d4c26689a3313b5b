"""SPH kernels, one file per kernel (see base.py), found by registry.py."""

from __future__ import annotations

from solvers.kernels.base import Kernel
from solvers.kernels.registry import (
    DEFAULT_KERNEL,
    ENTRY_POINT_GROUP,
    KERNELS,
    KernelPluginWarning,
    kernel_named,
    kernel_names,
    kernels,
    register,
    truncated,
    unregister,
)

__all__ = [
    "Kernel",
    "DEFAULT_KERNEL",
    "ENTRY_POINT_GROUP",
    "KERNELS",
    "KernelPluginWarning",
    "kernel_named",
    "kernel_names",
    "kernels",
    "register",
    "truncated",
    "unregister",
]
