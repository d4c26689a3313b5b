"""Write the Markdown reports: one per measured profile, the card comparison, and the index.

reports/<profile>/report.md   each study's sections (registry ``section.SECTIONS``), figures inline
reports/cards.md              Table 6 and Fig. 14 across systems, GPU cards side by side
reports/README.md             the index
"""

from __future__ import annotations

import dataclasses
import re
from pathlib import Path
from typing import Callable

from pcabench import store
from pcabench.errors import NoResults
from pcabench.machine import profiles
from pcabench.reports import frame
from pcabench.reports import page as pages
from pcabench.reports.md import fmt
from pcabench.reports.section import Context, in_order
from pcabench.store import runs
from pcabench.store.safeio import own_folder, write_file
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
        own = dataclasses.replace(ctx, runs=ctx.runs_of(section.reads, section.all_scenes)) if section.reads else ctx
        rows = section.rows(own)
        drawn = [p for p in (draw(rows, own) for draw in section.figures) if p is not None]
        body += section.text(rows, own) + figure_lines(drawn)
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


def apart(df):
    """Which rows only their own section reads (each section's ``apart``: the open-edges study's open edges,
    closed contrasts and cost baselines), kept out of every other section's frames."""
    mask = df.index != df.index
    if df.empty:
        return mask
    for section in in_order():
        if section.apart is not None:
            mask = mask | section.apart(df)
    return mask


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
    everything, df_all = df_all, df_all[~apart(df_all)]  # the open-edges study's runs: its section only
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
        for name, g in everything[~apart(everything)].groupby("machine")
    ]
    written = [(page, page.write(paper, reports_dir, shared)) for page in pages.in_order()]  # across machines
    paths += [p for _, ps in written for p in ps]
    index = [
        "# Reports",
        "",
        f"Regenerated by `pcabench report` from the stores in `{Path(results_dir).name}/`; "
        "one report per machine (hardware profile, and host where one profile has several).",
        "",
    ]
    index += [f"- [{ps[0].name}]({ps[0].name}): {page.index}" for page, ps in written if ps]
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
