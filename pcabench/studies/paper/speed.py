"""Speed: the time per particle and step of every solver."""

from __future__ import annotations

from pcabench.reports.md import fmt, md_table
from pcabench.reports.section import Section
from pcabench.studies.paper.rows import speed


def text(rows, ctx) -> list[str]:
    if not rows:
        return []
    return [
        "## Speed per particle-step and per neighbour pair (the paper's domain)",
        "",
        "One step (SNP + PI + SU) per particle, and per neighbour pair (two sweeps over N x mean neighbours "
        "pairs per Verlet step). Pair loops: `list`, each pair once per search with its kernel factors; "
        "`gather`, the paper's loop over each particle's stencil in every sweep. An all-pair run visits every "
        "pair of particles, not a neighbour list, so it has no time per neighbour pair ('-').",
        "",
        md_table(
            ["config", "protocol", "model", "N", "ns per particle-step", "ns per neighbour pair", "SNP %", "commit"],
            [
                [
                    r["config"],
                    r["protocol"],
                    r["model"],
                    f"{r['N']:,}",
                    fmt(r["ns_per_particle_step"], ".0f"),
                    fmt(r["ns_per_pair"], ".2f"),
                    fmt(r["snp_pct"], ".1f"),
                    r["commit"],
                ]
                for r in rows
            ],
        ),
        "",
    ]


SECTION = Section("speed", lambda ctx: speed(ctx.df), text, order=40)
