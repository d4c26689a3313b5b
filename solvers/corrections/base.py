"""What a kernel correction is: how the particle interaction (PI) turns the solver's pair sweeps into rates.

A correction is one class (one file in solvers/corrections/, or a plug-in through the entry-point group
``pcabench.corrections``) with a ``name``. Standard SPH (``none``) is one; the kernel gradient correction
(``gradient``) another; a Shepard or a reproducing-kernel correction would be one more file. It works through
the solver interface alone (solvers/interface.py: the sweeps ``Solver._sweep`` over the arrays it names, the
per-particle sums ``moments``, array operations in the solver's ``xp``), so every solver and every boundary
(mirrors at walls, a body's ghosts, open layers) runs it unchanged.

It states

* :meth:`sweep`: the rates of one PI, from the solver's current state and coefficients;
* :meth:`coefficients`: which of the coefficients (vol, pr) it needs computed before;
* :meth:`lattice_factor`: what it does to the lattice symbol D(k) in a periodic interior (the dispersion
  prediction, solvers/reference/dispersion.py), a scalar;
* ``arrays``: how many more arrays per particle it keeps (the scene's memory estimate).
"""

from __future__ import annotations


class SingularMoments(RuntimeError):
    """A particle's moment matrix is singular or near it: the corrected run fails at this step, naming where."""


class Correction:
    """Base class of the kernel corrections; this one is standard SPH (no correction)."""

    name: str = ""  # what --correction and the stored scene's ``correction`` call it
    summary: str = ""  # one line for --help
    arrays: int = 0  # arrays per particle it keeps beyond a standard solver's
    moments: bool = False  # whether it sums each particle's moments (a pair list keeps their sums for moving ones)
    allocates: bool = False  # whether its passes allocate arrays inside a step (a CUDA graph cannot replay it)

    def coefficients(self, continuity: bool, momentum: bool) -> tuple:
        """(vol, pr): which coefficients a PI of ``continuity``/``momentum`` needs first."""
        return continuity, momentum

    def sweep(self, solver, continuity: bool, momentum: bool) -> None:
        """PI's sweeps: dd (continuity, with a split absorber's parts) and/or ax, ay (momentum)."""
        solver._sweep(continuity, momentum)
        if continuity and solver.split:
            solver.continuity_parts()

    def lattice_factor(self, scene) -> float:
        """The factor on the lattice symbol D(k) in a periodic interior (1: none)."""
        return 1.0

    def __repr__(self) -> str:
        return f"<correction {self.name}>"
