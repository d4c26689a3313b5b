"""The kernel registry: every SPH kernel pcabench offers, found rather than listed (like the solvers' and scenes').

A kernel is a :class:`~solvers.kernels.base.Kernel` subclass with a ``name``:
the modules of this package, then the entry-point group ``pcabench.kernels``
of installed packages (``my-kernel = my_pkg.mod:MyKernel``), then those given
to :func:`register` in this process (tests, notebooks): the one
:class:`~solvers.plugins.Registry` mechanism. Once known, a kernel
is in ``--kernel``, the Scene's checks, the dispersion prediction and its
stable CFL, the front preset and every solver that does not restrict its
``kernels``. A plug-in that does not load, is not a concrete Kernel, has no
plain name of its own or repeats a taken name is left out with one
:class:`~solvers.plugins.PluginWarning`; :func:`register` raises ValueError instead.

The compiled pair loops and the predictions are cached by kernel name, so a
name keeps one class for the life of the process.
"""

from __future__ import annotations

import math

from solvers.kernels.base import Kernel
from solvers.plugins import NAME, PluginWarning, Registry

ENTRY_POINT_GROUP = "pcabench.kernels"
DEFAULT_KERNEL = "gaussian"  # the paper's: what every run uses unless --kernel says otherwise
KERNEL_NAME = NAME  # the record's kernel field (pcabench/store/schema.py): the one name rule

KernelPluginWarning = PluginWarning  # the one warning of every registry


def _problem(cls) -> str | None:
    """Why kernel class ``cls`` cannot be one beyond its name (None: it can)."""
    if cls.support is not None and not (isinstance(cls.support, (int, float)) and 0 < cls.support <= 5):
        return f"support {cls.support!r} must be None (truncated) or in (0, 5] (units of h)"
    if not (isinstance(cls.norm, (int, float)) and math.isfinite(cls.norm) and cls.norm > 0):
        return f"norm {cls.norm!r} must be a positive number"
    return None


KERNELS = Registry(
    "kernel",
    __package__,
    Kernel,
    group=ENTRY_POINT_GROUP,
    default=DEFAULT_KERNEL,
    make=lambda cls: cls(),
    problem=_problem,
    pinned=True,  # compiled loops and predictions are cached by kernel name
)


def kernels() -> dict[str, Kernel]:
    """{name: kernel (an instance)}: the paper's Gaussian first, the other built-ins, plug-ins', registered."""
    return KERNELS.all()


def kernel_names() -> tuple[str, ...]:
    return KERNELS.names()


def kernel_named(name: str) -> Kernel:
    """The kernel ``name``; ValueError naming the allowed kernels otherwise."""
    return KERNELS.get(name)


def truncated(name: str) -> bool:
    """Whether kernel ``name`` is cut at the scene's ``cutoff_factor`` (the Gaussian) rather than at its own
    support; a name not known here (a stored row of a plug-in not installed) is not. A built-in's answer loads
    no plug-in (the scenes' default method is made at import)."""
    kern = KERNELS.builtins().get(name) or kernels().get(name)
    return kern is not None and kern.support is None


register = KERNELS.register
unregister = KERNELS.unregister
