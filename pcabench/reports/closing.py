"""A study's closing table for the terminal when it has no table of its own: each run, its method, status, error
and step time."""

from __future__ import annotations

from pcabench.reports.md import fmt, md_table

CLOSING_ROWS = 30  # runs a study's closing table lists at most (the report and `pcabench runs` have them all)


def run_table(df) -> str:
    """This study's runs, one line each (at most CLOSING_ROWS): scene, dx, N, method, model, status, the
    headline error and the step time."""
    lines = []
    for _, r in df.sort_values(["scene", "dx"], ascending=[True, False]).head(CLOSING_ROWS).iterrows():
        method = f"{r.kernel} h {float(r.h_factor):.3g} dx" + (
            "" if r.correction in ("none", None) else f", {r.correction}"
        )
        error = r.headline if r.headline == r.headline and r.headline is not None else r.mse
        lines.append(
            [
                r.scene,
                f"{float(r.dx):g}",
                f"{int(r.n_particles):,}",
                method,
                f"{r.model}/{r.integrator} CFL {float(r.cfl):g}",
                r.status
                + (f" (step {int(r.failed_step)})" if r.failed_step == r.failed_step and r.failed_step else ""),
                fmt(error, ".4g"),
                fmt(1e3 * r.t_step, ".3f"),
            ]
        )
    more = len(df) - CLOSING_ROWS
    return (
        "This study's runs on this machine (the report has every table and figure):\n"
        + md_table(["scene", "dx (m)", "N", "method", "model", "status", "error", "ms/step"], lines)
        + (f"\n... and {more} more (`pcabench runs` lists them all)" if more > 0 else "")
    )
