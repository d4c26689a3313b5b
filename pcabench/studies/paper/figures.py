"""The paper study's figures: Figs. 8-11, 13 and 14 beside the paper's published points, and the GPU cards side by
side, drawn with the toolkit pcabench/reports/figures.py."""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.ticker import NullLocator

from pcabench.reports import tables as T
from pcabench.reports.figdata import save_figure_data
from pcabench.reports.figures import (
    FIG10_SIZES,
    MODEL_COLOUR,
    PRECISION_MARKER,
    PUBLISHED,
    channels,
    figure,
    groups,
    nice_log_ticks,
    palette,
    particle_count,
    plain_log_ticks,
    suptitle,
)
from pcabench.store.record import STEP_STAGES
from pcabench.store.safeio import save_figure
from pcabench.studies.paper import published as P
from pcabench.studies.paper.rows import FIG9_LOOP_NAMES, cards_published, fig9_steps, trend
from solvers import STAGES

STAGE_COLOURS = {
    "input": "tab:gray",
    "init": "tab:brown",
    "snp": "tab:blue",
    "pi": "tab:orange",
    "su": "tab:green",
    "output": "tab:purple",
}


SEARCH_COLOUR = {"all-pair": "tab:red", "linked list": "tab:blue"}


PAPER_MARKERS = {"paper-system-1": "^", "paper-system-2": "v", "paper-system-3": "D"}


def _published(ax, rows, marker, label, **style):
    """The paper's rows (from :mod:`pcabench.studies.paper.published`) as one published series: grey, dashed, hollow."""
    pts = sorted((r["N"], r["ms"]) for r in rows)
    ax.plot(*zip(*pts), marker=marker, **{**PUBLISHED, **style}, label=label)


def fig8(series, out: Path, pid: str):
    if not series:
        return None
    protocols = sorted({s["protocol"] for s in series}, key=lambda p: (not p.startswith("t ="), p))
    path = out / "fig8_error_vs_dx.png"
    models = [s["model"] for s in series]
    precisions = [s["precision"] for s in series]
    domains = [s["domain"] for s in series]
    domain = "" if len(set(domains)) > 1 else f", {domains[0]} domain"
    key = channels(colour=("model", models), marker=("precision", precisions), line=("domain", domains))
    with figure(
        path,
        f"Fig. 8: error against dx ({pid}{domain}){key}",
        "dx (m)",
        "relative RMS error of u (paper's MSE)",
        ncols=len(protocols),
        logx=True,
        logy=True,
        size=(5.6 * len(protocols) + 0.6, 4.6 + 0.16 * max(sum(s["protocol"] == p for s in series) for p in protocols)),
        legend="below",
    ) as axes:
        for ax, protocol in zip(axes, protocols):
            dxs, note = [], ""
            for s in (s for s in series if s["protocol"] == protocol):
                f32 = s["precision"] == "float32"
                hidden = s["domain"] == "full" and _under_the_strip(s, series)
                ax.plot(
                    s["dx"],
                    s["mse"],
                    color=MODEL_COLOUR.get(s["model"], "k"),
                    marker=PRECISION_MARKER[s["precision"]],
                    ms=9 if f32 else 5,
                    mfc="none" if f32 else None,
                    mew=1.4 if f32 else 1.0,
                    ls="-" if s["domain"] == "strip" else ":",
                    lw=1.2,
                    zorder=3 if f32 else 2,  # float32 on top: where it tracks float64 it would hide under it
                    label=f"{s['model']} {s['precision']}{'' if domain else ' ' + s['domain']}: {trend(s)}"
                    + (" (under the strip's line)" if hidden else ""),
                )
                dxs += list(s["dx"])
            dx_paper, mse_paper = P.fig8_point()
            if protocol == "100 steps":
                if min(dxs) / dx_paper <= 4:  # drawn only near our runs; else named, not stretched to
                    ax.plot(
                        [dx_paper],
                        [mse_paper],
                        marker="^",
                        ms=15,
                        mew=1.4,
                        zorder=4,
                        **PUBLISHED,
                        label=f"paper, dx = {dx_paper:g}, 100 steps (published)",
                    )
                    dxs.append(dx_paper)
                else:  # named in the panel's title: a note inside the axes would sit on the data
                    note = f"\npaper (published): {mse_paper:g} at dx = {dx_paper:g}, off this axis"
            plain_log_ticks(ax, dxs)
            nice_log_ticks(
                ax,
                [e for s in series if s["protocol"] == protocol for e in s["mse"]]
                + ([mse_paper] if dx_paper in dxs else []),
            )
            ax.set_ylabel("relative RMS error of u (paper's MSE)")  # every panel: their ranges differ
            ax.set_title(
                protocol
                + (" (fixed physical time)" if protocol.startswith("t =") else " (the paper's protocol)")
                + note,
                fontsize=9,
            )
    return path


def _under_the_strip(s, series, tolerance: float = 0.03) -> bool:
    """Whether full-domain series ``s`` has a strip twin (model, precision, protocol) within ``tolerance`` at
    every dx of ``s``: drawn under it, so the legend says so."""
    for t in series:
        if (t["domain"], t["model"], t["precision"], t["protocol"]) == (
            "strip",
            s["model"],
            s["precision"],
            s["protocol"],
        ):
            strip = dict(zip(t["dx"], t["mse"]))
            shared = [(e, strip[d]) for d, e in zip(s["dx"], s["mse"]) if d in strip]
            if len(shared) == len(s["dx"]) and all(b and abs(a / b - 1) <= tolerance for a, b in shared):
                return True
    return False


def fig9(rows, out: Path, pid: str):
    steps = fig9_steps(rows)
    if steps is None:
        return None
    rows = [r for r in rows if r["steps"] == steps and (r["allpair_ms"] or r["linkedlist_ms"])]
    path = out / "fig9_allpair_vs_linkedlist.png"
    loop = FIG9_LOOP_NAMES.get(rows[0]["linkedlist_loop"], rows[0]["linkedlist_loop"])
    pub = [r for r in P.step_times() if r["source"] == "Fig. 9 text"]
    with figure(
        path,
        f"Fig. 9: all-pair against linked list, serial CPU, float64, {steps}-step runs ({pid})",
        "particles N",
        "",
        ncols=2,
        logx=True,
        logy=True,
        size=(13, 4.4),
    ) as (a, b):
        for key, search, label in (
            ("allpair_ms", "all-pair", "all-pair (measured)"),
            ("linkedlist_ms", "linked list", f"linked list, {loop} (measured)"),
        ):
            pts = [(r["N"], r[key]) for r in rows if r[key]]
            if pts:
                a.plot(*zip(*pts), marker="o", color=SEARCH_COLOUR[search], label=label)
        for search, marker in (("all-pair", "^"), ("linked list", "v")):
            _published(
                a,
                [r for r in pub if r["search"] == search],
                marker,  # on top, hollow, in the colour of the measured line it goes with: apart where close
                f"paper {search}, {P.CONVERSION['Fig. 9 text']} (published; two sizes, not joined)",
                ms=7,
                mec=SEARCH_COLOUR[search],
                mew=1.5,
                zorder=4,
                ls="none",  # the paper gives two sizes 2.4 decades apart: a line would invent the ones between
            )
        skipped = sorted(r["N"] for r in rows if r["allpair_status"] == "skipped")
        measured = sorted((r["N"], r["allpair_ms"]) for r in rows if r["allpair_ms"])
        if skipped and len(measured) >= 2:  # where it would be: the measured a N^b, as the sweep predicted it
            b_exp, log_a = np.polyfit(np.log([n for n, _ in measured]), np.log([ms for _, ms in measured]), 1)
            n_pred = [measured[-1][0], *skipped]
            a.plot(
                n_pred,
                np.exp(log_a) * np.asarray(n_pred, float) ** b_exp,
                color=SEARCH_COLOUR["all-pair"],
                ls=":",
                marker="o",
                mfc="none",
                markevery=list(range(1, len(n_pred))),
                label=f"all-pair, predicted (N^{b_exp:.2f} fit; skipped: past the run budget)",
            )
        a.set_ylabel("one step (ms)")
        a.set_title("runtime", fontsize=9)
        pts = [(r["N"], r["eta"]) for r in rows if r["eta"]]
        if pts:
            b.plot(*zip(*pts), marker="o", color="tab:purple", label="speedup eta (measured)")
        ap = {r["N"]: r["ms"] for r in pub if r["search"] == "all-pair"}
        ll = {r["N"]: r["ms"] for r in pub if r["search"] == "linked list"}
        b.plot(
            sorted(ap),
            [ap[n] / ll[n] for n in sorted(ap)],
            marker="D",
            **{**PUBLISHED, "ls": "none"},
            label="speedup eta (paper, published; two sizes, not joined)",
        )
        b.set_ylabel("eta = t_all-pair / t_linked-list")
        b.set_title("speedup (eq. 12)", fontsize=9)
    return path


def _run_order(run: str):
    """Run lengths in order: "10 steps", "100 steps", then "t = 5 s", "t = 10 s"."""
    words = run.split()
    return (run.startswith("t ="), float(words[2] if run.startswith("t =") else words[0]))


def fig10(series, out: Path, pid: str):
    """One step against N: a panel per run length, a colour per configuration (solver, precision, pair loop,
    threads), the paper's step times of the same kind in every panel."""
    if not series:
        return None
    path = out / "fig10_runtime_vs_N.png"
    # a panel draws a line against N: a run length none of whose series has FIG10_SIZES sizes is left out
    runs = sorted({s["run"] for s in series if len(s["N"]) >= FIG10_SIZES}, key=_run_order)
    if not runs:
        return None
    series = [s for s in series if s["run"] in runs]
    paper_panel = "100 steps" if "100 steps" in runs else runs[0]  # the paper's step times drawn once, here
    configs = sorted({(s["config"], s["loop"], s["threads"]) for s in series})
    colours = dict(zip(configs, palette(len(configs))))
    kinds = {(s["device"], s["search"]) for s in series if s["precision"] == "float64"}
    key = channels(colour=("configuration", configs), marker=("precision", [s["precision"] for s in series]))
    ncols = min(len(runs), 2)
    nrows = -(-len(runs) // ncols)
    spare = nrows * ncols > len(runs)  # an empty slot holds the legend: the figure keeps its width
    under = not spare and ncols > 1  # else under two panels or more: a key at their right would squeeze them
    with figure(
        path,
        f"Fig. 10: one step against N ({pid}, full domain), a panel per run length{key}; grey "
        f"dashed: the paper's, same kind ({paper_panel})",
        "particles N",
        "one step SNP+PI+SU (ms)",
        ncols=ncols,
        nrows=nrows,
        logx=True,
        logy=True,
        sharey=True,
        size=(
            4.6 * ncols + (4.6 if ncols == 1 else 0.6),
            3.4 * nrows + 0.6 + (0.16 * (-(-(len(configs) + 3) // 2)) if under else 0),
        ),
        legend="none" if spare else "bottom" if under else "right",
    ) as axes:
        for ax in axes[len(runs) :]:
            ax.set_visible(False)
        for ax, run in zip(axes, runs):
            for s in (s for s in series if s["run"] == run):
                c = (s["config"], s["loop"], s["threads"])
                ax.plot(
                    s["N"],
                    s["ms"],
                    marker=PRECISION_MARKER[s["precision"]],
                    color=colours[c],
                    label=f"{s['config']}, {s['loop']}, {T.where(s['threads'], s['device'])}",
                )
            ax.set_title(f"runs to t = {run[4:]}" if run.startswith("t =") else f"runs of {run}", fontsize=9)
            if run == paper_panel and ("cpu", "linked list") in kinds:
                cpu = [
                    r
                    for r in P.step_times()
                    if (r["system"], r["device"], r["search"]) == ("paper-system-1", "cpu", "linked list")
                ]
                for source, marker in (("Table 6", "v"), ("text, 400K", "<")):
                    pts = [r for r in cpu if r["source"] == source]
                    _published(
                        ax,
                        pts,
                        marker,
                        f"paper CPU, {pts[0]['processor']}, serial linked list, {source}: "
                        f"{pts[0]['conversion']} (published)",
                        ls="--" if len(pts) > 1 else "none",
                    )
            if run == paper_panel and ("gpu", "linked list") in kinds:
                pts = [r for r in P.step_times() if r["device"] == "gpu" and r["source"] == "Table 4"]
                _published(ax, pts, "^", f"paper GPU, {pts[0]['processor']}, Table 4: one step (published)")
            # ticks at every N drawn on the panel (the paper's points too, which run past a small study's)
            sizes = [float(n) for line in ax.get_lines() for n in line.get_xdata()]
            if max(sizes) / min(sizes) < 100:  # under two decades: ticks at the sizes drawn, never 2x10^5
                plain_log_ticks(ax, sizes, axis="x", spread=3.0)
                ax.xaxis.set_minor_locator(NullLocator())
            ax.xaxis.set_major_formatter(particle_count)  # every panel writes N alike: 1K, 25K, 1M
        if spare:
            handles = {}
            for ax in axes[: len(runs)]:
                for h, lab in zip(*ax.get_legend_handles_labels()):
                    handles.setdefault(lab, h)
            key_ax = axes[-1]
            key_ax.set_visible(True)
            key_ax.axis("off")
            key_ax.legend(list(handles.values()), list(handles), loc="center", fontsize=7, frameon=False)
    return path


def _shares(path, title, xlabel, rows, published, stages):
    """Horizontal stacked bars: our rows above, the paper's (hatched) in their own panel below, if any."""
    ours = [(f"{r['config']}, {r['protocol']}, N={r['N']:,}", r) for r in rows]
    panels = [(ours, None, "measured")] + ([(published, "//", "paper (published)")] if published else [])
    heights = [max(len(items), 1) for items, _, _ in panels]
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(
        len(panels),
        1,
        figsize=(10.5, 1.5 + 0.26 * sum(heights)),
        layout="constrained",
        gridspec_kw={"height_ratios": heights},
        sharex=True,
        squeeze=False,
    )
    axes = list(axes.flat)
    for ax, (items, hatch, name) in zip(axes, panels):
        left = np.zeros(len(items))
        for s in stages:
            vals = np.array([sh[s] for _, sh in items])
            ax.barh(
                range(len(items)),
                vals,
                left=left,
                color=STAGE_COLOURS[s],
                hatch=hatch,
                edgecolor="white" if hatch is None else "0.25",
                lw=0.4,
                label=s.upper() if ax is axes[0] else f"_{s.upper()}",  # "_": out of the legend, in the data
            )
            left += vals
        ax.set_yticks(range(len(items)))
        ax.set_yticklabels([label for label, _ in items], fontsize=7)
        ax.invert_yaxis()
        ax.set_xlim(0, 100)
        ax.set_title(name, fontsize=9, loc="left")
        ax.grid(True, axis="x", alpha=0.3)
    axes[-1].set_xlabel(xlabel)
    fig.legend(loc="outside lower center", ncols=len(stages), fontsize=8, frameon=False)
    suptitle(fig, title)
    save_figure(fig, path, dpi=110)  # whole or not at all; a link at its name is replaced, not followed
    save_figure_data(fig, path)  # its data beside it, as a CSV a reader replots
    plt.close(fig)
    return path


def _one_run(rows, prefer):
    """The rows of one run length: ``prefer(runs)`` picks it among those present."""
    runs = sorted({r["run"] for r in rows}, key=_run_order)
    run = prefer(runs, rows)
    return run, [r for r in rows if r["run"] == run]


def fig11(rows, out: Path, pid: str):
    """Shares of a step in runs of one length: the paper's 100 steps where measured, else the most common;
    the paper's shares beside rows of the same kind only (``table5``'s ``paper``)."""
    if not rows:
        return None
    run, rows = _one_run(
        rows,
        lambda runs, rows: (
            "100 steps" if "100 steps" in runs else max(runs, key=lambda x: sum(r["run"] == x for r in rows))
        ),
    )
    paper = {}
    for r in rows:
        if r["paper"]:
            source, values = r["paper"]
            name = f"paper {source}" + (f", N={r['N']:,}" if "Table 5" in source else ", every N")
            paper[name] = dict(zip(STEP_STAGES, values))
    return _shares(
        out / "fig11_step_shares.png",
        f"Fig. 11 / Table 5: share of a step by stage, runs of {run} ({pid}; Table 5 has every run length)",
        "% of one step (SNP + PI + SU)",
        rows,
        list(paper.items()),
        STEP_STAGES,
    )


def fig13(rows, out: Path, pid: str):
    """Shares of a run of one step, rebuilt from the shortest runs measured: input + init + their mean step +
    output; the paper's K20c one-step runs (Table 4) beside GPU rows only."""
    if not rows:
        return None
    run, rows = _one_run(rows, lambda runs, rows: runs[0])
    paper = []
    if any(r["device"] == "gpu" for r in rows):
        paper = [
            (
                f"paper GPU Tesla K20c, N={n:,} (Table 4, one-step run)",
                {s: 100 * x / sum(v) for s, x in zip(STAGES, v)},
            )
            for n, v in P.table4().items()
        ]
    spread = max(r.get("init_spread", 1.0) for r in rows)
    noisy = (
        f"; init (timed once per run; stored reruns of one configuration differ in it by up to {spread:.1f}x) "
        "is the shortest rerun's"
        if spread >= 1.5
        else ""
    )
    return _shares(
        out / "fig13_task_shares.png",
        f"Fig. 13: share of a one-step run by task ({pid}): input + init + one step + output, the step "
        f"being the mean step of runs of {run}{noisy}",
        "% of a run of one step",
        rows,
        paper,
        STAGES,
    )


def fig14(rows, out: Path, title: str):
    """Speedup per step of each GPU over its own host's CPU, beside the paper's three systems (Table 6); a GPU
    measured only against another machine's CPU is drawn apart (dash-dotted, hollow, "across machines", with
    its commit): a measured card, not one machine's speedup."""
    across = [r for r in rows if not r["same_machine"]]
    rows = [r for r in rows if r["same_machine"]]
    path = out / "fig14_speedup_vs_N.png"
    pub = P.table6()
    keys = sorted({(r["gpu_profile"], r["precision"], r["protocol"]) for r in rows})
    colours = palette(len(keys))
    values = (
        [r["speedup"] for r in pub]
        + [r["speedup"] for r in rows + across]
        + [r["speedup_all_cores"] for r in rows if r["speedup_all_cores"]]
    )
    with figure(
        path,
        "Fig. 14: GPU speedup per step over one CPU core, its own host's"
        + (" or, dash-dotted, another machine's" if across else "")
        + f" ({title})",
        "particles N",
        "speedup per step",
        logx=True,
        logy=True,
        size=(10.5, 4.6),
    ) as (ax,):
        for system in P.SYSTEMS:
            pts = [(r["N"], r["speedup"]) for r in pub if r["system"] == system]
            card = next(r["card"] for r in pub if r["system"] == system)
            ax.plot(
                *zip(*pts),
                marker=PAPER_MARKERS[system],
                **PUBLISHED,
                label=f"{system}: {card} vs one core of its host, Table 6 (published)",
            )
        for colour, (gp, prec, how) in zip(colours, keys):
            pts = [r for r in rows if (r["gpu_profile"], r["precision"], r["protocol"]) == (gp, prec, how)]
            _speedup_line(ax, pts, "speedup", colour, f"{gp} {prec} vs one core of its host, {how}")
            multi = [r for r in pts if r["speedup_all_cores"]]
            if multi:
                label = f"{gp} {prec} vs all cores of its host, {how}"
                _speedup_line(ax, multi, "speedup_all_cores", colour, label, ls=":", mfc="none")
        by = ("gpu_profile", "precision", "protocol", "cpu_profile")
        others = groups(sorted(across, key=lambda r: tuple(r[k] for k in by)), by)
        for colour, ((gp, prec, how, cp), pts) in zip(palette(len(keys) + len(others))[len(keys) :], others):
            commits = ", ".join(sorted({r["gpu_commit"] for r in pts}))
            label = f"{gp.split('__')[0]} {prec} vs one core of {cp}\n(across machines; GPU at {commits}; {how})"
            _speedup_line(ax, pts, "speedup", colour, label, ls="-.", mfc="none")
        nice_log_ticks(ax, values)
        if not rows and not across:
            ax.text(
                0.02,
                0.95,
                "no GPU measured yet: only the paper's lines",
                transform=ax.transAxes,
                fontsize=8,
                color="0.3",
            )
    return path


def _speedup_line(ax, pts, key: str, colour, label: str, **style) -> None:
    """One GPU's Table 6 rows ``pts`` as a line of ``key`` (speedup) against N, marked by their precision."""
    ax.plot(
        [r["N"] for r in pts],
        [r[key] for r in pts],
        marker=PRECISION_MARKER[pts[0]["precision"]],
        color=colour,
        label=label,
        **style,
    )


def cards_figure(rows, out: Path):
    """One GPU step against N: each measured card and precision, beside the paper's three cards (grey)."""
    pub = cards_published()
    path = out / "cards_step_vs_N.png"
    cards = sorted({p["card"] for p in rows})
    colours = dict(zip(cards, palette(len(cards))))
    key = channels(colour=("card", cards), marker=("precision", [p["precision"] for p in rows]))
    with figure(
        path,
        "GPU cards side by side: one lagrangian step (SNP+PI+SU) against N"
        + key
        + "; grey dashed, marker by card: the paper's",
        "particles N",
        "one step (ms)",
        logx=True,
        logy=True,
        size=(10.5, 4.6),
    ) as (ax,):
        for (system, card, source), pts in groups(pub, ("system", "processor", "source")):
            _published(ax, pts, PAPER_MARKERS[system], f"{card}, {source}: {pts[0]['conversion']} (published)")
        for (_, precision, how), pts in groups(rows, ("profile", "precision", "protocol")):
            ax.plot(
                [p["N"] for p in pts],
                [p["step_ms"] for p in pts],
                marker=PRECISION_MARKER[precision],
                color=colours[pts[0]["card"]],
                label=f"{pts[0]['card']} {precision}, {how} (measured)",
            )
        if not rows:
            ax.text(
                0.02,
                0.95,
                "no GPU card measured yet: only the paper's",
                transform=ax.transAxes,
                fontsize=8,
                color="0.3",
            )
    return path
