"""Rigid walls at the x edges: mirror particles across each wall, in the pair sums themselves.

A scene kind names its walls (``SceneKind.walls``: "x_min", "x_max"); the wall is the lattice's edge, half a
spacing from its first or last column (``Scene.walls``). Every pair sum reaches across it to the mirror image of
each particle within a cutoff of it, at x' = 2 x_w - x with the normal velocity reversed and everything else its
own (solvers/physics/pairs.py ``ranges(mirror=True)``): the compiled loops read the walls from the kernel's
constants (``k[WALL_LO]``, ``k[WALL_HI]``, solvers/kernels/constants.py) and compile their seams in where the
scene reaches across an x edge (:func:`across`). The cell grid ends at a wall (its column of cells holds every
particle with mirror neighbours: :meth:`Walls.spare_cells`). A solver whose sums come from a pair list adds the
mirrors' part with the wall loops (:meth:`Walls.mirror_sweeps`).
"""

from __future__ import annotations

from solvers.boundaries.base import Boundary


def across(scene) -> bool:
    """Whether the pair sums of ``scene`` reach across an x edge: a periodic seam or a rigid wall (the pair
    functions' compile-time ``across``, solvers/physics/pairs.py)."""
    return bool(scene.periodic_x or scene.walls)


class Walls(Boundary):
    """The scene's rigid walls at its x edges (mirror particles)."""

    name = "walls"
    kind = "wall-x"

    @classmethod
    def applies(cls, scene) -> bool:
        return bool(scene.walls)

    @staticmethod
    def spare_cells(scene) -> tuple:
        """(left, right): whether the cell grid keeps a spare column beyond each x edge for particles drifting past
        it (a free edge's; none at a wall, the grid's edge)."""
        return "x_min" not in scene.walls, "x_max" not in scene.walls

    def mirror_sweeps(self, solver, continuity: tuple, momentum: bool) -> None:
        """The mirrors' part of the sums a pair list holds only the real pairs of: the continuity rates ``continuity``
        ((v, rate) pairs: the whole rate and a split absorber's x part with v = 0) and the acceleration."""
        a, k = solver.arrays, solver.k
        for v, out in continuity:
            solver.launch("wall_continuity", *solver.geometry(), a["u"], v, a["vol"], a["drho"], out, k)
        if momentum:
            solver.launch("wall_momentum", *solver.geometry(), a["mass"], a["pr"], a["ax"], a["ay"], k)

    def mirror_moments(self, solver, out: tuple) -> None:
        """The mirrors' part of the gradient correction's moments (``out``: M_xx, M_xy, M_yy, Gamma x, y)."""
        solver.launch("wall_moments", *solver.geometry(), solver.arrays["vol"], *out, solver.k)
