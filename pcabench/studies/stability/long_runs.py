"""Long runs: each model's own stable CFL over runs long enough for round-off to grow."""

from __future__ import annotations

from pcabench.reports.long_runs import long_run_limits
from pcabench.reports.md import fmt, md_table
from pcabench.reports.section import OUTCOME_COLUMNS, Section, limit_words, outcome_cells


def text(rows, ctx) -> list[str]:
    if not rows:
        return []
    table = []
    for r in rows:
        method = f"{r['kernel']}, h = {r['h_factor']:g} dx, {r['integrator']}"
        table.append(
            [
                r["scene"],
                f"{r['mach']:g}",
                r["model"],
                method,
                f"{r['dx']:g}",
                f"{r['protocol']} (up to {r['steps']} steps)",
                ", ".join(f"{c:g}" for c in r["cfls"]),
                limit_words(r["predicted"]),
                *outcome_cells(r),
                fmt(r["held"], "g") if r["held"] is not None else "prediction",
            ]
        )
    lines = [
        "## Stability over long runs",
        "",
        "`pcabench study --stability long`: each model of the paper's method at the CFLs around the predicted "
        "limit (of the linear part, on a periodic lattice), to t = 300 s: on the paper's plane pulse (a strip "
        "with free ends in x, at an amplitude that does not break before 300 s; the pulse leaves by the free "
        "end long before, so these runs test the ends) and on the 2D acoustic pulse in a 20 m periodic square "
        "(the sound neither leaves nor breaks, so the moving models' nonlinear terms act for the whole run). "
        "The linear model is the control: on a periodic lattice the prediction is exact for it. 'e-foldings' "
        "is how far the most unstable mode of the periodic lattice grew at the largest bounded CFL over the "
        "run (0 below the predicted limit; round-off needs about 37 to reach the pulse's size). The last "
        "column is the limit advise, the front and the tables use for that scene and model "
        "(pcabench/predict/measured_limits.csv, where lower than the prediction).",
        "",
        md_table(
            [
                "scene",
                "Mach",
                "model",
                "method",
                "dx",
                "run",
                "CFLs run",
                "predicted stable CFL",
                *OUTCOME_COLUMNS,
                "limit used",
            ],
            table,
        ),
        "",
    ]
    for r in rows:
        if r["blew_up_from"] is not None and r["blew_up_from"] < r["predicted"]:
            cause = (
                "the prediction is exact for this model on a periodic lattice, so the scene's edges set this limit"
                if r["model"] == "linear"
                else "its nonlinear terms or the scene's edges set its limit"
            )
            lines.append(
                f"- **{r['model']}** on {r['scene']} blew up below the predicted {r['predicted']:.3g}, "
                f"from CFL {r['blew_up_from']:g}: {cause}"
                + (
                    f"; advise takes it as {r['held']:g}."
                    if r["held"] is not None
                    else "; advise still uses the prediction for it (add it to pcabench/predict/measured_limits.csv)."
                )
            )
    return lines + [""]


SECTION = Section(
    "long-runs",
    lambda ctx: long_run_limits(ctx.df_scenes if ctx.df_scenes is not None else ctx.df),
    text,
    all_scenes=True,
    order=110,
)
