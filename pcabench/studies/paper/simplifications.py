"""What each simplification costs in accuracy: fixed particles, float32, the strip."""

from __future__ import annotations

from pcabench.reports.md import fmt, md_table, pct
from pcabench.reports.section import Section
from pcabench.studies.paper.rows import simplifications


def text(rows, ctx) -> list[str]:
    if not rows:
        return []
    return [
        "## The cost of each simplification",
        "",
        "Each row changes one thing and keeps the rest (its runs name the protocol): what the change buys in "
        "time to solution and what it costs (or gains) in error against the linear analytic pulse.",
        "",
        md_table(
            ["simplification", "runs", "dx", "N", "time (s)", "speedup", "error"],
            [
                [
                    r["simplification"],
                    r["runs"],
                    f"{r['dx']:g}",
                    f"{r['N'][0]:,} -> {r['N'][1]:,}",
                    f"{fmt(r['seconds'][0])} -> {fmt(r['seconds'][1])}",
                    fmt(r["speedup"], ".2f"),
                    f"{pct(r['mse'][0])} -> {pct(r['mse'][1])}",
                ]
                for r in rows
            ],
        ),
        "",
    ]


SECTION = Section("simplifications", lambda ctx: simplifications(ctx.df), text, order=90)
