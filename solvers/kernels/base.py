"""What an SPH kernel is: W(r, h), G(r, h) = W'(r) / r, its reach, and the G the pair loops compile.

A kernel is one class (one file in solvers/kernels/, or a plug-in through the
entry-point group ``pcabench.kernels``) with a ``name``. It states

* ``support``: its compact support in units of h (the cutoff is then
  ``support * h``), or None for a kernel truncated at the scene's
  ``cutoff_factor`` (the Gaussian);
* ``norm``: its 2D normalisation sigma, W = sigma / h^2 f(r/h), so that W
  integrates to 1 over the plane (dimensionless);
* :meth:`value` and :meth:`gradient`, the reference forms in NumPy (float64);
* :meth:`compiled_gradient`: G(r^2, k) for the pair loops, a plain function of
  the squared distance and the constant tuple ``k`` (solvers/kernels/constants.py), in
  the solver's float type throughout, which every backend compiles
  (numba's CPU target, numba-cuda, the CUDA simulator as Python).

grad_i W_ij = G(r_ij) (x_i - x_j): the pair loops never divide by r.
"""

from __future__ import annotations

import abc


class Kernel(abc.ABC):
    """Base class of the SPH kernels (2D). Subclasses set ``name``, ``norm`` and, if compact, ``support``."""

    name: str = ""  # what --kernel and the stored record's ``kernel`` column call it
    summary: str = ""  # one line for --help
    support: float | None = None  # compact support / h; None: truncated at the scene's cutoff_factor
    norm: float = 0.0  # 2D normalisation sigma: W = sigma / h^2 f(r/h), dimensionless
    negative_lobe: bool = False  # W < 0 somewhere (a higher-order kernel): the tensile instability's source

    @abc.abstractmethod
    def value(self, r, h: float):
        """W(r) in 2D, 1/m^2, at distances ``r`` (m) for smoothing length ``h`` (m); NumPy, float64. A
        truncated kernel is returned untruncated (the caller applies the scene's cutoff)."""

    @abc.abstractmethod
    def gradient(self, r, h: float):
        """G(r) = W'(r) / r, 1/m^4 (NumPy, float64), so that grad_i W_ij = G(r_ij) (x_i - x_j)."""

    def grad0(self, h: float) -> float:
        """G(0), 1/m^4: the constant tuple's ``GRAD0`` slot, which the compiled G scales."""
        return float(self.gradient(0.0, h))

    @abc.abstractmethod
    def compiled_gradient(self, dtype, exp_neg):
        """G(r2, k) for the pair loops, 1/m^4, in ``dtype`` throughout (to be compiled by the caller).

        ``r2`` is the squared distance (m^2, within the cutoff: the loops test it first), ``k`` the constant
        tuple (solvers/kernels/constants.py: ``k[GRAD0]`` = G(0), ``k[INV_H2]`` = 1/h^2); ``exp_neg(x) = exp(-x)`` is
        the caller's compiled exp for kernels that need one. Float constants must be ``dtype`` scalars made
        here, so that float32 loops never promote to float64; the function must not reach ``self``.
        """

    def __repr__(self) -> str:
        return f"<kernel {self.name}>"
