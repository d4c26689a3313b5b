"""What an SPH kernel is: W(r, h), G(r, h) = W'(r) / r, its reach, and the G the pair loops compile.

A kernel is one class (one file in solvers/kernels/, or a plug-in through the
entry-point group ``pcabench.kernels``) with a ``name``. It states

* ``support``: its compact support in units of h (the cutoff is then
  ``support * h``), or None for a kernel truncated at the scene's
  ``cutoff_factor`` (the Gaussian);
* ``norm``: its 2D normalisation sigma, W = sigma / h^2 f(r/h), so that W
  integrates to 1 over the plane (dimensionless); ``dimensions``: the
  dimensions it is normalised for, (2,) unless it states (2, 3), and then
  ``norms`` {dims: sigma} (W = sigma / h^d f_d(r/h));
* :meth:`value` and :meth:`gradient`, the reference forms in NumPy (float64);
* :meth:`compiled_gradient`: G(r^2, k) for the pair loops, a plain function of
  the squared distance and the constant tuple ``k`` (solvers/kernels/constants.py), in
  the solver's float type throughout, which every backend compiles
  (numba's CPU target, numba-cuda, the CUDA simulator as Python).

grad_i W_ij = G(r_ij) (x_i - x_j): the pair loops never divide by r. A kernel
of several ``dimensions`` takes ``dims`` (2 or 3) as a keyword in :meth:`value`,
:meth:`gradient`, :meth:`grad0` and :meth:`compiled_gradient`; 2D callers pass
none (a 2D-only plug-in needs no such keyword), :func:`in_dims` chooses.
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
    dimensions: tuple = (2,)  # the dimensions it is normalised for: (2, 3) takes ``dims`` in its methods
    norms: dict = {}  # {dims: sigma} where it has several dimensions (norm is norms[2])
    # A truncated kernel's cut (in h) below which it loses its order ("--cutoff 2" leaves a fourth-order kernel
    # second order); None where none is stated
    order_cutoff: float | None = None

    @abc.abstractmethod
    def value(self, r, h: float):
        """W(r) in 2D, 1/m^2, at distances ``r`` (m) for smoothing length ``h`` (m); NumPy, float64. A
        truncated kernel is returned untruncated (the caller applies the scene's cutoff)."""

    @abc.abstractmethod
    def gradient(self, r, h: float):
        """G(r) = W'(r) / r, 1/m^4 (NumPy, float64), so that grad_i W_ij = G(r_ij) (x_i - x_j)."""

    def grad0(self, h: float, **dims) -> float:
        """G(0), 1/m^(d+2): the constant tuple's ``GRAD0`` slot, which the compiled G scales."""
        return float(self.gradient(0.0, h, **dims))

    @abc.abstractmethod
    def compiled_gradient(self, dtype, exp_neg):
        """G(r2, k) for the pair loops, 1/m^4, in ``dtype`` throughout (to be compiled by the caller).

        ``r2`` is the squared distance (m^2, within the cutoff: the loops test it first), ``k`` the constant
        tuple (solvers/kernels/constants.py: ``k[GRAD0]`` = G(0), ``k[INV_H2]`` = 1/h^2); ``exp_neg(x) = exp(-x)`` is
        the caller's compiled exp for kernels that need one. Float constants must be ``dtype`` scalars made
        here, so that float32 loops never promote to float64; the function must not reach ``self``.
        """

    def in_dims(self, dims: int) -> dict:
        """The keywords that ask this kernel's methods for ``dims`` dimensions ({} for 2D: every kernel's
        default); ValueError naming the kernel's dimensions where it has no such normalisation."""
        if dims not in self.dimensions:
            raise ValueError(
                f"--kernel {self.name} is normalised in {' and '.join(f'{d}D' for d in self.dimensions)} only "
                f"(got a {dims}D scene)"
            )
        return {} if dims == 2 else {"dims": dims}

    def __repr__(self) -> str:
        return f"<kernel {self.name}>"
