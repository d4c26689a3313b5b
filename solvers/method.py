"""The numerical method of a run, as one value: the kernel, h/dx, the truncation, the CFL and the integrator.

A :class:`Method` is what a Scene's numerics are (``Scene.method``) and what a stored row's are
(:meth:`Method.of`): the one answer to "which method is this" (its :attr:`~Method.label`) and "is this the
paper's" (:meth:`~Method.is_paper`). Its defaults are the paper's method (:data:`PAPER`, which Scene's defaults
read: one place per fact); the Gaussian-only rule lives here: a kernel of compact support (the Wendland kernels)
is cut at its support, so its ``cutoff_factor`` is no part of its method (None).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from solvers.corrections import DEFAULT_CORRECTION
from solvers.kernels import DEFAULT_KERNEL

FIELDS = ("kernel", "h_factor", "cutoff_factor", "cfl", "integrator", "correction")  # Scene's parameters it holds
INTEGRATORS = ("verlet", "kdk1", "euler", "rk2", "rk4")
# The paper's method, every Scene's default: a Gaussian at h = 2.13 dx cut at 3h, dt = 0.2 dx / c0, Verlet.
PAPER = {
    "kernel": DEFAULT_KERNEL,
    "h_factor": 2.13,
    "cutoff_factor": 3.0,
    "cfl": 0.2,
    "integrator": "verlet",
    "correction": DEFAULT_CORRECTION,
}


def is_finite_number(value) -> bool:
    """Whether ``value`` is a finite int or float (not a bool): the test every numeric scene parameter meets."""
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def _close(a: float, b: float) -> bool:
    return math.isclose(float(a), float(b), rel_tol=1e-5, abs_tol=1e-8)  # as numpy.isclose, a stored float's


@dataclass(frozen=True)
class Method:
    """Kernel (a registered name), h / dx, the truncation in units of h (the Gaussian's; None for a kernel cut
    at its own support), CFL (dt c0 / dx), time integrator and kernel correction (solvers/corrections/)."""

    kernel: str
    h_factor: float
    cutoff_factor: float | None
    cfl: float
    integrator: str
    correction: str = "none"

    @classmethod
    def of(cls, values) -> "Method":
        """The method of a Scene or of a stored row (a dict, a DataFrame row: the fields of :data:`FIELDS`; one a
        row predates at the paper's, :data:`PAPER`)."""
        from solvers.kernels import truncated

        if isinstance(getattr(values, "method", None), cls):  # a Scene: its own
            return values.method

        def get(name):
            value = getattr(values, name, None) if not hasattr(values, "get") else values.get(name)
            if value is None or isinstance(value, float) and math.isnan(value):
                return PAPER[name]
            return value

        kernel = str(get("kernel"))
        return cls(
            kernel=kernel,
            h_factor=float(get("h_factor")),
            cutoff_factor=float(get("cutoff_factor")) if truncated(kernel) else None,
            cfl=float(get("cfl")),
            integrator=str(get("integrator")),
            correction=str(get("correction")),
        )

    def problems(self):
        """Why this method cannot run (one line each, naming the parameter and its range; none where it can): h/dx
        in [0.5, 10], a truncation in [1, 5] h, a registered kernel and correction, no truncation of a compact
        kernel but its support, a cutoff past the nearest particles, a known integrator. (The CFL's range is the
        scene's: it bounds the steps a run takes.)"""
        from solvers.corrections import correction_named
        from solvers.kernels import kernel_named

        cut = self.cutoff_factor
        for name, value in (("h_factor", self.h_factor), ("cutoff_factor", cut)):
            if value is not None and not is_finite_number(value):
                yield f"{name} must be a finite number (got {value!r})"
                return
        if not 0.5 <= self.h_factor <= 10:
            yield f"h_factor (h/dx) must be in [0.5, 10] (got {self.h_factor})"
        elif cut is not None and cut < 1.0:
            yield f"cutoff_factor (cutoff/h) must be >= 1: a cutoff below h cuts the kernel's core (got {cut})"
        elif cut is not None and cut > 5.0:
            yield f"cutoff_factor (cutoff/h) of the truncated kernel {self.kernel} must be in [1, 5] (got {cut})"
        else:
            try:
                support = kernel_named(self.kernel).support
                correction_named(self.correction)
            except ValueError as exc:
                yield str(exc)
                return
            reach = support if support is not None else PAPER["cutoff_factor"] if cut is None else cut
            if support is not None and cut is not None:
                yield (
                    f"cutoff_factor applies to the truncated Gaussian only: {self.kernel} is cut at its compact "
                    f"support {support:g}h (got cutoff_factor {cut:g})"
                )
            elif not self.h_factor * reach > 1:
                yield (
                    f"cutoff_factor * h_factor (cutoff/dx) must be > 1 to reach the nearest particles, dx away "
                    f"(got {reach:g} * {self.h_factor:g} = {reach * self.h_factor:g})"
                )
            elif self.integrator not in INTEGRATORS:
                yield f"integrator must be one of {', '.join(INTEGRATORS)} (got {self.integrator!r})"

    @classmethod
    def paper(cls) -> "Method":
        """The paper's method, every Scene's default (:data:`PAPER`: the Gaussian at h = 2.13 dx, cut at 3h,
        CFL 0.2, Verlet)."""
        return cls.of(PAPER)

    def is_paper(self) -> bool:
        """Whether this is the paper's method (floats compared as stored floats are)."""
        paper = self.paper()
        if (self.kernel, self.integrator, self.correction) != (paper.kernel, paper.integrator, paper.correction):
            return False
        same = _close(self.h_factor, paper.h_factor) and _close(self.cfl, paper.cfl)
        return same and (self.cutoff_factor is None or _close(self.cutoff_factor, paper.cutoff_factor))

    @property
    def label(self) -> str:
        """``kernel, h 2.13dx, 3h, CFL 0.2``: the truncation written only for a kernel that has one, the integrator
        and the correction only where they are not the default's (``, rk4, gradient-corrected``)."""
        return self._words(with_step=True)

    @property
    def numerics(self) -> str:
        """The label without the CFL (``laguerre-gauss, h 1.5dx, 4h, rk4, gradient-corrected``): a method whose
        step is shown apart."""
        return self._words(with_step=False)

    def _words(self, with_step: bool) -> str:
        cut = f", {self.cutoff_factor:g}h" if self.cutoff_factor is not None else ""
        cfl = f", CFL {self.cfl:g}" if with_step else ""
        step = f", {self.integrator}" if self.integrator != PAPER["integrator"] else ""
        corrected = f", {self.correction}-corrected" if self.correction != PAPER["correction"] else ""
        return f"{self.kernel}, h {self.h_factor:g}dx{cut}{cfl}{step}{corrected}"

    @property
    def words(self) -> str:
        """The method in a sentence's words, every field named (``Gaussian, h = 2.13 dx, 3h, CFL 0.2, Verlet``):
        how the reports name the paper's method (``Method.paper().words``)."""
        cut = f", {self.cutoff_factor:g}h" if self.cutoff_factor is not None else ""
        corrected = f", {self.correction}-corrected" if self.correction != "none" else ""
        name = self.kernel[:1].upper() + self.kernel[1:]
        step = self.integrator[:1].upper() + self.integrator[1:] if self.integrator == "verlet" else self.integrator
        return f"{name}, h = {self.h_factor:g} dx{cut}, CFL {self.cfl:g}, {step}{corrected}"

    def scene_fields(self) -> dict:
        """The Scene fields this method sets (a compact kernel's ``cutoff_factor`` left at its default)."""
        out = {
            "kernel": self.kernel,
            "h_factor": self.h_factor,
            "cfl": self.cfl,
            "integrator": self.integrator,
            "correction": self.correction,
        }
        if self.cutoff_factor is not None:
            out["cutoff_factor"] = self.cutoff_factor
        return out
