"""The kernel registry: every SPH kernel pcabench offers, found rather than listed (like the solvers' and scenes').

A kernel is a :class:`~solvers.kernels.base.Kernel` subclass with a ``name``:
the modules of this package, then the entry-point group ``pcabench.kernels``
of installed packages (``my-kernel = my_pkg.mod:MyKernel``), then those given
to :func:`register` in this process (tests, notebooks). Once known, a kernel
is in ``--kernel``, the Scene's checks, the dispersion prediction and its
stable CFL, the front preset and every solver that does not restrict its
``kernels``. A plug-in that does not load, is not a concrete Kernel, has no
plain name of its own or repeats a taken name is left out with one
:class:`KernelPluginWarning`; :func:`register` raises ValueError instead.

The compiled pair loops and the predictions are cached by kernel name, so a
name keeps one class for the life of the process.
"""

from __future__ import annotations

import inspect
import math
from functools import lru_cache
from pathlib import Path

from ..plugins import NAME, builtin_classes, entry_point_classes, name_problem
from .base import Kernel

ENTRY_POINT_GROUP = "pcabench.kernels"
DEFAULT_KERNEL = "gaussian"  # the paper's: what every run uses unless --kernel says otherwise
KERNEL_NAME = NAME  # the record's kernel field (pcabench/schema.py): the one name rule

_added: dict[str, Kernel] = {}  # kernels given to register() in this process
_classes: dict[str, type] = {}  # every class a name was registered with in this process (names are cache keys)


class KernelPluginWarning(UserWarning):
    """A plug-in kernel left out."""


def _builtin() -> list[type[Kernel]]:
    return builtin_classes(__package__, Path(__file__).parent, Kernel)


def _problem(cls, taken) -> str | None:
    """Why ``cls`` cannot be a kernel under its name (None: it can)."""
    if not (inspect.isclass(cls) and issubclass(cls, Kernel)) or inspect.isabstract(cls):
        return "not a concrete Kernel subclass"
    name = cls.__dict__.get("name")
    if not name:
        return "the class sets no name of its own"
    if name_problem(name, "kernel"):
        return name_problem(name, "kernel")
    if name in taken:
        return f"the kernel name {name!r} is taken"
    if cls.support is not None and not (isinstance(cls.support, (int, float)) and 0 < cls.support <= 5):
        return f"support {cls.support!r} must be None (truncated) or in (0, 5] (units of h)"
    if not (isinstance(cls.norm, (int, float)) and math.isfinite(cls.norm) and cls.norm > 0):
        return f"norm {cls.norm!r} must be a positive number"
    return None


def _plugins(taken: set) -> list[type[Kernel]]:
    return entry_point_classes(ENTRY_POINT_GROUP, _problem, taken, KernelPluginWarning)


@lru_cache(maxsize=None)
def _found() -> dict[str, Kernel]:
    builtin = sorted(_builtin(), key=lambda cls: (cls.name != DEFAULT_KERNEL, cls.name))
    out = {cls.name: cls() for cls in builtin}
    out.update({cls.name: cls() for cls in _plugins(set(out))})
    return out


def kernels() -> dict[str, Kernel]:
    """{name: kernel (an instance)}: the paper's Gaussian first, the other built-ins, plug-ins', registered."""
    return {**_found(), **_added}


def kernel_names() -> tuple[str, ...]:
    return tuple(kernels())


def kernel_named(name: str) -> Kernel:
    """The kernel ``name``; ValueError naming the allowed kernels otherwise."""
    try:
        return kernels()[name]
    except (KeyError, TypeError):
        raise ValueError(f"kernel must be one of {', '.join(kernels())} (got {name!r})") from None


def truncated(name: str) -> bool:
    """Whether kernel ``name`` is cut at the scene's ``cutoff_factor`` (the Gaussian) rather than at its own
    support; a name not known here (a stored row of a plug-in not installed) is not."""
    kern = kernels().get(name)
    return kern is not None and kern.support is None


def register(cls: type[Kernel]) -> Kernel:
    """Add kernel class ``cls`` for this process (tests, plug-ins loaded by hand); ValueError if it cannot be one."""
    why = _problem(cls, set(kernels()))
    if why is None and _classes.get(cls.name, cls) is not cls:
        why = f"the kernel name {cls.name!r} was another class's in this process (compiled loops are cached by name)"
    if why:
        raise ValueError(f"kernel {getattr(cls, '__name__', cls)!r:.80}: {why}")
    _classes[cls.name] = cls
    _added[cls.name] = kern = cls()
    return kern


def unregister(name: str) -> None:
    """Remove a kernel :func:`register` added; ValueError for any other name."""
    if name not in _added:
        raise ValueError(f"kernel {name!r} was not added by register(): only those can be removed")
    del _added[name]
