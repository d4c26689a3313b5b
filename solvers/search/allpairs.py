"""The paper's all-pair search as an object a solver holds: nothing to build, every pair tested in the loops."""

from __future__ import annotations

import numpy as np

from solvers.interface import POSITIONS


class AllPairs:
    """No cells: the pair loops take the positions alone and test every pair against the cutoff (the minimum
    image across a periodic axis), as the paper's all-pair code does."""

    valid = True

    def __init__(self, scene, launch, xp=np):
        self.scene, self.launch, self.xp = scene, launch, xp

    def arguments(self, arrays) -> tuple:
        """What every pair loop takes first: the positions."""
        return tuple(arrays[name] for name in POSITIONS[self.scene.dims])

    def count(self, arrays, k) -> int:
        """Neighbours within the cutoff summed over particles (nothing is changed)."""
        return int(self.launch("neighbours", *self.arguments(arrays), k))
