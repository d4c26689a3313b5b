"""Table 6 and Fig. 14: the speed-up of each solver over the serial CPU, on this machine."""

from __future__ import annotations

from pcabench.reports.md import fmt, md_table
from pcabench.reports.section import Section
from pcabench.studies.paper.figures import fig14
from pcabench.studies.paper.rows import table6_of


def table6_md(rows, across: bool = False, gpu_column: bool = False) -> str:
    """Table 6's rows, named and rounded alike in every report and the cards page: a "speedup" for a GPU against
    its own host's CPU, a "ratio" ``across`` machines (two computers, not what a GPU buys one of them)."""
    word = "ratio" if across else "speedup"
    return md_table(
        (["GPU profile"] if gpu_column else [])
        + [
            "N",
            "protocol",
            "GPU precision",
            "GPU ms/step",
            "CPU profile, loop",
            "CPU ms/step (1 thread)",
            word,
            f"{word} vs all cores (threads)",
        ],
        [
            ([r["gpu_profile"]] if gpu_column else [])
            + [
                f"{r['N']:,}",
                r["protocol"],
                r["precision"],
                fmt(r["gpu_ms"], ".3f"),
                f"{r['cpu_profile']}, {r['cpu_loop']}",
                fmt(r["cpu_ms"], ".1f"),
                fmt(r["speedup"], ".1f"),
                "-" if r["speedup_all_cores"] is None else f"{r['speedup_all_cores']:.1f} (x{r['cpu_threads']})",
            ]
            for r in rows
        ],
    )


def text(rows, ctx) -> list[str]:
    if not rows:
        return []
    same = [r for r in rows if r["same_machine"]]
    other = [r for r in rows if not r["same_machine"]]
    lines = [
        "## Table 6: CPU against GPU, one step",
        "",
        "Speedups from one machine only: this GPU against its own host's CPU (linked list, float64), one "
        "thread (as the paper's) and every core (the honest peer), at the same N and run length. See "
        "[cards.md](../cards.md) for every system.",
        "",
    ]
    lines += [
        table6_md(same)
        if same
        else "No CPU run of the paper's scene on this GPU's host yet: no same-machine speedup to show "
        "(`pcabench gpu-check` times the host's CPU too).",
        "",
    ]
    if other:
        lines += [
            "### Across machines (not a speedup of one machine)",
            "",
            "This GPU's times against a CPU measured on another machine, named per row: a comparison of "
            "two computers, not what a GPU buys one of them.",
            "",
            table6_md(other, across=True),
            "",
        ]
    return lines


SECTION = Section(
    "table6",
    lambda ctx: [r for r in table6_of(ctx) if r["gpu_profile"] == ctx.pid],
    text,
    # drawn where this GPU was measured with its own host's CPU: the paper's lines alone are the cards page's
    (lambda rows, ctx: fig14(rows, ctx.out, ctx.pid) if any(r["same_machine"] for r in rows) else None,),
    order=50,
)
