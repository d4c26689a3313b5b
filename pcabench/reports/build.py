"""Write the Markdown reports: one per measured profile, the card comparison, and the index.

reports/<profile>/report.md   each study's sections (registry ``section.SECTIONS``), figures inline
reports/cards.md              Table 6 and Fig. 14 across systems, GPU cards side by side
reports/README.md             the index
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Callable

from pcabench import store
from pcabench.errors import NoResults
from pcabench.machine import profiles
from pcabench.reports import frame
from pcabench.reports.md import fmt, md_table
from pcabench.reports.section import Context, in_order
from pcabench.store import runs
from pcabench.store.safeio import own_folder, write_file
from pcabench.studies.paper import published as P
from pcabench.studies.paper.figures import cards_figure, fig14
from pcabench.studies.paper.rows import card_ceilings, card_ratios, cards, table4, table6
from pcabench.studies.paper.table6 import table6_md
from solvers import DEFAULT_SCENE


def _machine(pid: str) -> str:
    prof = profiles.stored().get(pid)
    if not prof:
        return "profile not stored"
    cpu = prof.get("cpu") or {}
    gpu = prof.get("gpu") or {}
    text = f"CPU {cpu.get('model', '?')} ({cpu.get('cores_usable', cpu.get('logical_cores', '?'))} cores usable)"
    if gpu:
        text += (
            f"; GPU {gpu.get('name')} ({fmt(gpu.get('memory_bytes', 0) / 2**30, '.0f')} GiB, "
            f"CC {gpu.get('compute_capability')})"
        )
    return text


def anchor(title: str) -> str:
    """The link anchor GitHub gives a Markdown heading ``title``: lower case, punctuation dropped, spaces -> "-"."""
    return re.sub(r"[^\w\- ]", "", title.strip().lower()).replace(" ", "-")


def contents(body: list[str]) -> list[str]:
    """A contents list of the report's sections (its "## " headings), each a link to its place."""
    titles = [line[3:].strip() for line in body if line.startswith("## ")]
    return ["Contents:", "", *(f"- [{t}](#{anchor(t)})" for t in titles), ""] if titles else []


def figure_lines(paths: list[Path]) -> list[str]:
    """Each figure inline, under the section that drew it, with a link to its data (the CSV beside it)."""
    lines = []
    for p in paths:
        lines += [f"![{p.stem}]({p.name})", ""]
        if p.with_suffix(".csv").exists():
            lines += [f"Data: [{p.stem}.csv]({p.stem}.csv) (one row per plotted point: replot it)", ""]
    return lines


def report_for(ctx: Context, progress: Callable[[str], None] | None = None) -> Path:
    """The report of one machine's runs (``ctx.name``: its profile id, with its host where a profile has
    several): each section's rows computed once, then its Markdown and its figures from them, the figures inline
    under their section with their data beside them; ``progress`` is told each section as it starts."""
    out, df = ctx.out, ctx.df_scenes if ctx.df_scenes is not None else ctx.df
    own_folder(out, "report folder", within=out.parent)  # a link is refused: nothing written or deleted there
    body, figs = [], []
    chosen = [s for s in in_order() if not ctx.df.empty or s.all_scenes]  # else: other scenes only
    for i, section in enumerate(chosen, 1):  # read at each report: a section registered since is in it
        if progress:
            progress(f"report {ctx.name}: section {i} of {len(chosen)}, {section.name}")
        rows = section.rows(ctx)
        drawn = [p for p in (draw(rows, ctx) for draw in section.figures) if p is not None]
        body += section.text(rows, ctx) + figure_lines(drawn)
        figs += drawn
    kept = set(figs) | {p.with_suffix(".csv") for p in figs}
    for stale in (set(out.glob("*.png")) | set(out.glob("*.csv"))) - kept:  # a figure whose data is gone: gone
        stale.unlink()
    counts = df.status.value_counts().to_dict()
    keys = runs.codes(df)
    commits = sorted(
        {
            c[:12] + ("+dirty" if c.endswith("+dirty") else "") + (f" (code {k[:8]})" if k else "")
            for c, k in zip(df.commit.astype(str), keys)
        }
    )
    hosts = sorted({str(h) for h in df.host.fillna("") if h}) or ["not recorded"]
    lines = [
        f"# pcabench report: {ctx.name}",
        "",
        f"Machine: {_machine(ctx.pid)}; host {', '.join(hosts)}.",
        "",
        f"Runs: {len(df)} ({', '.join(f'{v} {k}' for k, v in sorted(counts.items()))}); commits (with the code "
        "key that made their runs, where recorded): "
        f'{", ".join(commits)}. Every row below is from this machine (a table headed "across machines" names '
        "the other one) and names its protocol; Table 4 names the commit of each row. Regenerate with "
        "`pcabench report`.",
        "",
        *contents(body),
        *body,
    ]
    return write_file(out / "report.md", "\n".join(lines) + "\n")


def cards_page(df_all, reports_dir: Path, ours: list[dict]) -> list[Path]:
    """Table 6 and Fig. 14 across every system (``ours``: Table 6's rows), and the GPU cards side by side."""
    card_rows = cards(df_all)
    lines = [
        "# Systems and GPU cards side by side",
        "",
        "Regenerated by `pcabench report` from every results store and stored profile.",
        "",
        "## Table 6: CPU against GPU per step",
        "",
        "Measured, each GPU against its own host's CPU (one thread), at the same N and run length:",
        "",
    ]
    same = [r for r in ours if r["same_machine"]]
    other = [r for r in ours if not r["same_machine"]]
    lines += [
        table6_md(same, gpu_column=True)
        if same
        else "No GPU has been measured with its own host's CPU at the same N yet."
    ]
    if other:
        lines += [
            "",
            "Across machines (a GPU against another machine's CPU; not a speedup of one machine):",
            "",
            table6_md(other, across=True, gpu_column=True),
        ]
    lines += [
        "",
        f"Published (the paper's Table 6: whole runs of {P.TABLE6_STEPS} steps, serial CPU; its runtime "
        "unit is printed as min, but Table 4 makes seconds the consistent reading, so the runtimes are "
        "given here as printed and read as s):",
        "",
        md_table(
            [
                "system",
                "card",
                "N",
                "CPU runtime (printed min, read as s)",
                "GPU runtime (printed min, read as s)",
                "speedup per step",
            ],
            [
                [r["system"], r["card"], f"{r['N']:,}", str(r["cpu"]), str(r["gpu"]), str(r["speedup"])]
                for r in P.table6()
            ],
        ),
        "",
    ]
    lines += ["## GPU cards: one lagrangian step (SNP + PI + SU)", ""]
    if card_rows:
        lines += [
            md_table(
                [
                    "card",
                    "precision",
                    "protocol",
                    "N",
                    "step ms",
                    "SNP %",
                    "PI %",
                    "SU %",
                    "ns per particle-step",
                    "ps per pair",
                ],
                [
                    [
                        r["card"],
                        r["precision"],
                        r["protocol"],
                        f"{r['N']:,}",
                        fmt(r["step_ms"], ".3f"),
                        fmt(r["snp_pct"], ".1f"),
                        fmt(r["pi_pct"], ".1f"),
                        fmt(r["su_pct"], ".1f"),
                        fmt(r["ns_per_particle_step"], ".2f"),
                        fmt(r["ps_per_pair"], ".2f"),
                    ]
                    for r in card_rows
                ],
            ),
            "",
            "ps per pair counts both sweeps of a Verlet step (2 x N x mean neighbours pairs).",
            "",
        ]
        ceilings = card_ceilings(card_rows)
        if ceilings:
            lines += [
                "### Each card's measured ceilings",
                "",
                md_table(
                    ["card", "copy bandwidth TB/s", "FP32 FMA TFLOP/s", "FP64 FMA TFLOP/s"],
                    [
                        [c["card"], fmt(c["copy_bandwidth_tbs"]), fmt(c["fp32_fma_tflops"]), fmt(c["fp64_fma_tflops"])]
                        for c in ceilings
                    ],
                ),
                "",
            ]
        ratios = card_ratios(card_rows)
        if ratios:
            lines += [
                "### Two cards against the ratio of their ceilings",
                "",
                "Step-time ratio at the same N, precision and protocol beside the ratio of each measured "
                "ceiling: a kernel bound by memory follows the bandwidth ratio, one bound by instruction "
                "issue follows the FMA ratio.",
                "",
                md_table(
                    ["cards (A / B)", "precision", "protocol", "N", "step time B / A", "bandwidth A / B", "FMA A / B"],
                    [
                        [
                            f"{r['a']} / {r['b']}",
                            r["precision"],
                            r["protocol"],
                            f"{r['N']:,}",
                            fmt(r["speed_ratio"]),
                            fmt(r["bandwidth_ratio"]),
                            fmt(r["fma_ratio"]),
                        ]
                        for r in ratios
                    ],
                ),
                "",
            ]
    else:
        lines += ["No GPU runs stored yet: run `pcabench gpu-check` on a GPU machine and merge its results.", ""]
    lines += [
        "The figure sets the paper's cards beside ours, one source each: the K20c's Table 4 (one step), "
        f"the Quadro M4000's and GeForce GT730's Table 6 ({P.CONVERSION['Table 6']}).",
        "",
    ]
    figs = [fig14(ours, reports_dir, "all systems"), cards_figure(card_rows, reports_dir)]
    lines += [f"![{p.stem}]({p.name})\n" for p in figs]
    path = write_file(reports_dir / "cards.md", "\n".join(lines) + "\n")
    return [path, *figs]


CLOSING_ROWS = 30  # runs a study's closing table lists at most (the report and `pcabench runs` have them all)


def summary(results_dir: Path, profile: str, run_ids=None) -> str:
    """A study's closing table for the terminal, of its own runs (``run_ids``; None: every run of this machine):
    where it has the paper's timing runs (its scene, a fixed step count), their step times (Table 4's SNP / PI /
    SU columns) and a line counting the rest; else each run, its method, status, error and step time."""
    df = frame.load(results_dir)
    if not df.empty:
        df = df[df.profile_id == profile]
        if run_ids is not None:
            df = df[df.run_id.isin(set(run_ids))]
    if df.empty:
        return ""
    timing = (df.scene == DEFAULT_SCENE) & df.protocol.str.endswith(" steps")
    rows = table4(df[timing]) if timing.any() else []
    if not rows:
        return run_table(df)
    rest = int((~timing).sum())
    more = f"\n... and {rest} more runs (accuracy, other scenes): the report's tables, `pcabench runs`" if rest else ""
    heading = "Step times on this machine, ms per step (the paper's scene; the report has every table):\n"
    return heading + step_table(rows) + more


def step_table(rows) -> str:
    """Table 4's step-time columns (ms) of ``rows``."""
    return md_table(
        ["config", "protocol", "N", "SNP", "PI", "SU", "step"],
        [
            [
                r["config"],
                r["protocol"],
                f"{r['N']:,}",
                fmt(r["snp"], ".3f"),
                fmt(r["pi"], ".3f"),
                fmt(r["su"], ".3f"),
                fmt(r["snp"] + r["pi"] + r["su"], ".3f"),
            ]
            for r in rows
        ],
    )


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


def open_study(df):
    """Which rows are the open-edges study's: open edges, or the preset's own closed runs (``open``,
    ``open-cost-<round>``: contrasts scored once the pulse has gone, and cost baselines)."""
    from pcabench.studies.open_edges.plan import OPEN, open_cost_round

    if df.empty:
        return df.index == df.index
    edges = df["open"].fillna("") != "" if "open" in df else False
    return edges | (df.preset == OPEN) | df.preset.map(lambda p: open_cost_round(p) is not None)


def write_reports(
    results_dir: Path, reports_dir: Path, scene: str | None = None, progress: Callable[[str], None] | None = None
) -> list[Path]:
    """Every report from the stores in ``results_dir`` (only ``scene``'s runs, if given) into ``reports_dir``;
    ``progress`` (a callable taking one line) is told each machine's sections as they start."""
    df_all = frame.load(results_dir)
    if scene is not None and not df_all.empty:
        df_all = df_all[df_all.scene == scene]
    if df_all.empty:
        raise NoResults(
            f"no results in {results_dir}"
            + (f" of the {scene} scene" if scene else "")
            + ": run `pcabench study --quick` first"
        )
    reports_dir = own_folder(reports_dir, "report folder")  # never a link: nothing written or deleted where it points
    shared = {}  # rows computed once for every report (Table 6)
    # a machine's name becomes a folder: checked (store.validate made it so) so that nothing lands outside
    everything, df_all = df_all, df_all[~open_study(df_all)]  # the open-edges study's runs: its section only
    paper = df_all[df_all.scene == DEFAULT_SCENE]  # the paper's tables and figures: its scene only
    paths = [
        report_for(
            Context(
                g[g.scene == DEFAULT_SCENE],
                paper,
                str(name),
                reports_dir / store.check_name(str(name), "machine"),
                shared,
                df_scenes=g,
                df_open=everything[everything.machine == name],
            ),
            progress,
        )
        for name, g in everything[~open_study(everything)].groupby("machine")
    ]
    rows6 = shared.get("table6")  # Table 6 across machines, as the reports computed it (table6_of)
    paths += cards_page(paper, reports_dir, rows6 if rows6 is not None else table6(paper))
    index = [
        "# Reports",
        "",
        f"Regenerated by `pcabench report` from the stores in `{Path(results_dir).name}/`; "
        "one report per machine (hardware profile, and host where one profile has several).",
        "",
        "- [cards.md](cards.md): Table 6, Fig. 14 and the GPU cards side by side, every system",
    ]
    index += [
        f"- [{p.parent.name}]({p.parent.name}/report.md): {_machine(p.parent.name.split('--')[0])}"
        for p in paths
        if p.name == "report.md"
    ]
    gpu = sorted((reports_dir / "gpu").glob("*.md")) if (reports_dir / "gpu").is_dir() else []
    if gpu:  # the committed reference has them; a user's results do not: link only pages that exist
        index += [
            "",
            "GPU check tables, notes and Nsight Compute profiles: "
            + ", ".join(f"[gpu/{p.name}](gpu/{p.name})" for p in gpu)
            + ".",
        ]
    write_file(reports_dir / "README.md", "\n".join(index) + "\n")
    return paths + [reports_dir / "README.md"]
