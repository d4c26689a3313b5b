"""The runs that did not finish, each with its scene, method (kernel, h, correction, body), status, step and
message."""

from __future__ import annotations

import numpy as np

from pcabench.reports import tables as T
from pcabench.reports.md import first_words, fmt, md_table
from pcabench.reports.section import Section
from pcabench.store.rows import latest
from solvers.corrections import DEFAULT_CORRECTION


def rows(ctx):
    return latest(ctx.df[ctx.df.status != "ok"])


def wall(r) -> str:
    """A run's body's wall model ('' without a body), as its scene resolves it (the default with a correction
    is not standard SPH's)."""
    from pcabench.spec import scene_from_row

    try:
        scene = scene_from_row(r.to_dict())
    except Exception:  # noqa: BLE001 - a row its scene cannot be rebuilt from: no wall named
        return ""
    return scene.boundary_method_used if scene.body is not None else ""


def text(bad, ctx) -> list[str]:
    if bad.empty:
        return []
    rows = [
        [
            r.solver,
            r.scene + (f" ({wall(r)} wall)" if wall(r) else ""),
            r.precision,
            r.model,
            r.integrator,
            r.kernel,
            fmt(r.h_factor, ".3g"),
            "-" if r.correction in (None, DEFAULT_CORRECTION) else r.correction,
            f"{r.dx:g}",
            f"{int(r.n_particles):,}",
            T.protocol(r),
            fmt(r.cfl, "g"),
            r.status,
            "-" if r.failed_step is None or not np.isfinite(r.failed_step) else int(r.failed_step),
            first_words(str(r.message)) if r.message else "",
        ]
        for _, r in bad.sort_values(["status", "solver", "dx"]).iterrows()
    ]
    return [
        "## Runs that did not finish",
        "",
        md_table(
            [
                "solver",
                "scene",
                "precision",
                "model",
                "integrator",
                "kernel",
                "h/dx",
                "correction",
                "dx",
                "N",
                "protocol",
                "CFL",
                "status",
                "step",
                "message",
            ],
            rows,
        ),
        "",
    ]


SECTION = Section("failed", rows, text, order=130)
