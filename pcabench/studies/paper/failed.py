"""The runs that did not finish, each with its status, step and message."""

from __future__ import annotations

import numpy as np

from pcabench.reports import tables as T
from pcabench.reports.md import first_words, fmt, md_table
from pcabench.reports.section import Section
from pcabench.store.rows import latest


def rows(ctx):
    return latest(ctx.df[ctx.df.status != "ok"])


def text(bad, ctx) -> list[str]:
    if bad.empty:
        return []
    rows = [
        [
            r.solver,
            r.precision,
            r.model,
            r.integrator,
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
            ["solver", "precision", "model", "integrator", "dx", "N", "protocol", "CFL", "status", "step", "message"],
            rows,
        ),
        "",
    ]


SECTION = Section("failed", rows, text, order=130)
