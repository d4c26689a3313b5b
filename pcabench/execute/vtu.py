"""A run's final fields as a VTK unstructured grid (.vtu) that ParaView opens: one vertex per particle, with drho
(kg/m^3) and the velocity vector (m/s) as point data, written by meshio (the optional extra ``vtk``)."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

import numpy as np

EXTRA = "vtk"  # pyproject.toml's optional extra that brings meshio


def available() -> str:
    """'' where meshio can be imported, else one line saying how to install it."""
    try:
        import meshio  # noqa: F401
    except ImportError:
        return f"--fields NAME.vtu writes VTK through meshio, which is not installed: pip install -e '.[{EXTRA}]'"
    return ""


def mesh_of(fields):
    """The particles of ``fields`` (solvers.interface.Fields) as a meshio Mesh: points (x, y, z; z = 0 in 2D),
    one vertex cell each, point data ``drho`` and ``velocity`` (3 components; w = 0 in 2D)."""
    import meshio

    n = np.asarray(fields.x).shape[0]
    zero = np.zeros(n)
    z = zero if fields.z is None else np.asarray(fields.z, dtype=np.float64)
    w = zero if fields.w is None else np.asarray(fields.w, dtype=np.float64)
    points = np.column_stack([np.asarray(fields.x, dtype=np.float64), np.asarray(fields.y, dtype=np.float64), z])
    velocity = np.column_stack([np.asarray(fields.u, dtype=np.float64), np.asarray(fields.v, dtype=np.float64), w])
    return meshio.Mesh(
        points,
        [("vertex", np.arange(n, dtype=np.int64)[:, None])],
        point_data={"drho": np.asarray(fields.drho, dtype=np.float64), "velocity": velocity},
    )


def write_vtu(fields, path) -> None:
    """Write ``fields`` to the .vtu ``path``: meshio writes it aside, then it is put in place whole (safeio)."""
    import meshio

    from pcabench.store.safeio import write_file

    with tempfile.TemporaryDirectory() as folder:
        aside = Path(folder) / "fields.vtu"
        meshio.write(aside, mesh_of(fields), file_format="vtu", binary=True)
        data = aside.read_bytes()
    write_file(os.fspath(path), data)
