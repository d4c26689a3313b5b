"""Standard SPH: the pair sums as they are (the paper's method)."""

from __future__ import annotations

from solvers.corrections.base import Correction


class NoCorrection(Correction):
    """The kernel's gradient as it is: a phase-speed error at fixed h/dx (its lattice moment's departure)."""

    name = "none"
    summary = "standard SPH (the paper's)"
