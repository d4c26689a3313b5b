"""Fig. 9: the all-pair search against the cell list."""

from __future__ import annotations

from pcabench.reports.md import first_words, fmt, md_table
from pcabench.reports.section import Section
from pcabench.studies.paper import published as P
from pcabench.studies.paper.figures import fig9
from pcabench.studies.paper.rows import FIG9_LOOP_NAMES, fig9_rows, fig9_steps


def text(rows, ctx) -> list[str]:
    if not any(r["allpair_ms"] or r["allpair_status"] == "skipped" for r in rows):
        return []
    steps = fig9_steps(rows)
    pub = [p for p in P.step_times() if p["source"] == "Fig. 9 text"]
    return [
        "## Fig. 9: all-pair against linked list (serial, float64, paper's scene)",
        "",
        f"Linked list: {FIG9_LOOP_NAMES.get(rows[0]['linkedlist_loop'], rows[0]['linkedlist_loop'])}, "
        "the loop measured beside the most all-pair runs, one loop throughout"
        + (
            "."
            if rows[0]["linkedlist_loop"] == "gather"
            else " (`--pair-loop gather` at the same N measures the paper's)."
        )
        + " Both sides of a row made the same number of steps"
        + (f"; the figure draws the {steps}-step runs." if steps else "."),
        "",
        md_table(
            ["steps", "N", "all-pair ms/step", "linked list ms/step", "eta = t_AP / t_LL", "all-pair status"],
            [
                [
                    r["steps"],
                    f"{r['N']:,}",
                    fmt(r["allpair_ms"], ".2f"),
                    fmt(r["linkedlist_ms"], ".2f"),
                    fmt(r["eta"], ".1f"),
                    r["allpair_status"] + (f": {first_words(r['allpair_note'])}" if r["allpair_note"] else ""),
                ]
                for r in rows
            ],
        ),
        "",
        f"Paper (published, whole runs to the 10th step, drawn as {P.CONVERSION['Fig. 9 text']}): "
        + "; ".join(f"{p['search']} {p['ms'] * P.FIG9_STEPS / 1e3:g} s at {p['N']:,}" for p in pub)
        + ".",
        "",
    ]


SECTION = Section(
    "fig9", lambda ctx: fig9_rows(ctx.df), text, (lambda rows, ctx: fig9(rows, ctx.out, ctx.name),), order=60
)
