"""What a boundary model is: one kind of edge or wall of a scene, acting on a solver at fixed points of a step.

A scene's boundaries (walls at its x edges, an absorbing layer beyond its open edges, a rigid body inside it) are
each a :class:`Boundary`, one file each (walls.py, layer.py, body.py), the models that apply to a scene listed by
:func:`solvers.boundaries.boundary_models`. A solver calls every model of its scene at the same points of a step
(solvers/interface.py): :meth:`~Boundary.start` once its arrays exist, :meth:`~Boundary.before_sweep` before the
pair sums, :meth:`~Boundary.damp` around each kick and advance, :meth:`~Boundary.advanced` after the advance's
kernel, :meth:`~Boundary.moved` once moving particles moved, and it carries the arrays a model adds to the state
(:attr:`~Boundary.state`, saved and restored with drho) and to the rates (:attr:`~Boundary.rates`, summed over a
Runge-Kutta step's stages). A periodic seam or a free edge is no model: the neighbour search and the cell grid
make them (solvers/search/, ``cell_grid``).
"""

from __future__ import annotations


class Boundary:
    """One boundary of a scene in a solver; every hook does nothing unless the model says otherwise."""

    name: str = ""
    kind: str = ""  # the boundary kind a solver must offer for it (solvers/scenes/base.py BOUNDARY_KINDS)
    state: tuple = ()  # per-particle arrays it adds to the state (saved and restored with drho)
    rates: tuple = ()  # per-particle rates it adds (summed over a Runge-Kutta step's stages)

    def __init__(self, scene):
        self.scene = scene

    @classmethod
    def applies(cls, scene) -> bool:
        """Whether ``scene`` has this boundary."""
        raise NotImplementedError

    def start(self, solver, x, y, drho, z=None) -> None:
        """The solver's arrays exist (``solver.arrays``), its particles at their lattice sites ``x``, ``y`` (and
        ``z`` in a 3D scene; m) with the initial ``drho`` (kg/m^3): set the model's own arrays and places."""

    def before_sweep(self, solver) -> bool:
        """Before the pair sums of PI; True where it changed drho (a solver then recomputes what it keeps of it)."""
        return False

    def damp(self, solver, f: float, fields: str) -> None:
        """Half of its damping of ``fields`` ("velocity" or "density") over an update of f dt, called before and
        after that update."""

    def advanced(self, solver, f: float) -> None:
        """After the advance's kernel (drho += f dt D), before its second damping."""

    def moved(self, solver) -> None:
        """After an advance that moved the particles."""

    def __repr__(self) -> str:
        return f"<boundary {self.name}>"
