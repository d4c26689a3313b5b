"""Table 5 and Fig. 11: the stages' shares of a step against the paper's CPU."""

from __future__ import annotations

from pcabench.reports.md import fmt, md_table
from pcabench.reports.section import Section
from pcabench.studies.paper import published as P
from pcabench.studies.paper.figures import fig11
from pcabench.studies.paper.rows import table4_of, table5


def text(rows, ctx) -> list[str]:
    if not rows:
        return []
    allpair = any(r["search"] == "all-pair" for r in rows)
    beside = []
    if any(r["device"] == "gpu" for r in rows):
        beside.append("beside a serial float64 GPU row its Table 5 (Tesla K20c, same N)")
    if any(r["device"] == "cpu" and r["search"] == "linked list" for r in rows):
        shares = P.cpu_shares()
        beside.append(
            f"beside a serial float64 linked-list CPU row its Fig. 11 text (serial "
            f"{P.processor('paper-system-1', 'cpu')}, about {shares['snp']:g} % SNP and {shares['pi']:g} % "
            "PI at every N)"
        )
    return [
        "## Table 5 and Fig. 11: share of a step",
        "",
        f"The paper's column compares like with like: {', '.join(beside) or 'none of its shares is of these kinds'}"
        "; '-' elsewhere."
        + (
            " An all-pair row has no neighbour search to time: it visits every pair of particles inside PI, "
            "so its SNP share is 0 % and the paper, whose shares are the linked list's, has none beside it."
            if allpair
            else ""
        ),
        "",
        md_table(
            ["config", "protocol", "N", "SNP %", "PI %", "SU %", "paper, same kind: SNP / PI / SU % (published)"],
            [
                [
                    r["config"],
                    r["protocol"],
                    f"{r['N']:,}",
                    fmt(r["snp"], ".1f"),
                    fmt(r["pi"], ".1f"),
                    fmt(r["su"], ".1f"),
                    f"{' / '.join(f'{v:g}' for v in r['paper'][1])} ({r['paper'][0]})" if r["paper"] else "-",
                ]
                for r in rows
            ],
        ),
        "",
    ]


SECTION = Section(
    "table5",
    lambda ctx: table5(table4_of(ctx)),
    text,
    (lambda rows, ctx: fig11(rows, ctx.out, ctx.name),),
    order=20,
)
