"""Fig. 10: run time against the number of particles."""

from __future__ import annotations

from pcabench.reports.section import Section
from pcabench.studies.paper import published as P
from pcabench.studies.paper.figures import fig10
from pcabench.studies.paper.rows import runtime_series


def text(rows, ctx) -> list[str]:
    if not rows:
        return []
    kinds = {(r["device"], r["search"]) for r in rows if r["precision"] == "float64"}
    paper = []
    if ("cpu", "linked list") in kinds:
        paper.append(
            f"its serial CPU from Table 6 ({P.CONVERSION['Table 6']}) and the 400K step of its text, "
            "two series never joined (they come from different runs and do not lie on one line)"
        )
    if ("gpu", "linked list") in kinds:
        paper.append("its K20c from Table 4 (one step)")
    return [
        "## Fig. 10: one step against N",
        "",
        "A panel per run length, a line per configuration (pair loop and threads in its label). "
        + (
            f"The paper's step times are drawn beside our lines of the same kind only: {'; '.join(paper)}."
            if paper
            else "The paper has no step times of these kinds."
        ),
        "",
    ]


SECTION = Section(
    "fig10",
    lambda ctx: runtime_series(ctx.df),
    text,
    (lambda rows, ctx: fig10(rows, ctx.out, ctx.name),),
    order=30,
)
