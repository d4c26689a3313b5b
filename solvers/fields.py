"""A run's final particle fields (the solver's output, what the scene kinds score), one dataclass with no imports of
the solvers: the scene kinds, the references and the harness import it at module level."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass
class Fields:
    """Final particle fields in particle-id order (id = (lz * ny + ly) * nx + lx). SI units. A 3D scene's carry
    ``z`` and ``w`` too (None in 2D)."""

    x: np.ndarray
    y: np.ndarray
    u: np.ndarray
    v: np.ndarray
    drho: np.ndarray
    t: float
    probes: dict | None = None  # {"t": times (s), name: drho there (kg/m^3)} recorded at the scene's probe points
    z: np.ndarray | None = None
    w: np.ndarray | None = None

    def save(self, path) -> None:
        third = {} if self.z is None else {"z": self.z, "w": self.w}
        np.savez(path, x=self.x, y=self.y, u=self.u, v=self.v, drho=self.drho, t=self.t, **third)
