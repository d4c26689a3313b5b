"""Table 4: the time of each stage of one step, and Fig. 13, each stage's share."""

from __future__ import annotations

from pcabench.reports.md import fmt, md_table
from pcabench.reports.section import Section
from pcabench.studies.paper import published as P
from pcabench.studies.paper.figures import fig13
from pcabench.studies.paper.rows import one_step_shares, table4_of


def paper_cell(r) -> str:
    if r["paper_stages"]:
        return "K20c " + " / ".join(f"{v:g}" for v in r["paper_stages"]) + " (Table 4)"
    return (
        "; ".join(f"{p['ms']:.3g} ms/step, {p['processor']} ({p['source']}: {p['conversion']})" for p in r["paper"])
        or "-"
    )


def paper_sizes(rows) -> str:
    """Where the paper has numbers of the kinds these rows are: by device and search, its N."""
    kinds = sorted({(r["device"], r["search"]) for r in rows})
    parts = []
    for device, search in kinds:
        ns = sorted({p["N"] for p in P.step_times() if (p["device"], p["search"]) == (device, search)})
        if ns:
            parts.append(f"{device.upper()} {search} at N = {', '.join(f'{n:,}' for n in ns)}")
    return "; ".join(parts)


def text(rows, ctx) -> list[str]:
    if not rows:
        return []
    return [
        "## Table 4: stage times (the paper's scene: lagrangian, full domain)",
        "",
        "input, init and output in ms per run; SNP, PI and SU in ms per step (the mean step of the run). "
        "Each row names its protocol (run length, domain, pair loop, threads); rows of different protocols "
        "stand apart, never averaged or replaced. The paper's column holds its published numbers of the same "
        "kind only: same N, same device, same search, serial and float64 (the paper's codes are "
        "single-thread and double precision), each with the conversion it took "
        f"(pcabench/studies/paper/published.py). The paper has them for {paper_sizes(rows)}.",
        "",
        md_table(
            [
                "config",
                "protocol",
                "N",
                "input",
                "init",
                "SNP",
                "PI",
                "SU",
                "output",
                "commit",
                "paper, same kind (published)",
            ],
            [
                [
                    r["config"],
                    r["protocol"],
                    f"{r['N']:,}",
                    fmt(r["input"], ".2f"),
                    fmt(r["init"], ".2f"),
                    fmt(r["snp"], ".3f"),
                    fmt(r["pi"], ".3f"),
                    fmt(r["su"], ".3f"),
                    fmt(r["output"], ".2f"),
                    r["commit"],
                    paper_cell(r),
                ]
                for r in rows
            ],
        ),
        "",
    ]


def draw_fig13(rows, ctx):
    return fig13(one_step_shares(rows), ctx.out, ctx.name)


SECTION = Section("table4", table4_of, text, (draw_fig13,), order=10)
