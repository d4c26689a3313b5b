"""The report's PNG figures, each drawn from the rows of its section (``tables.py``), never from the store.

Each function draws one figure into ``out`` and returns its path, or None
when the rows hold nothing for it. One variable per visual channel, and a title
names a channel only where it varies (:func:`channels`): colour for the
configuration or card, marker for precision, line style for the domain, facets
for the protocol. The paper's numbers (:mod:`.paper`) are drawn in one style,
grey, dashed, hollow markers, "published" in the legend, with the conversion
they took, and only beside measured series of the same kind. Every label says
the protocol of its series. Legends sit outside the data; constrained layout
keeps labels from overlapping (tests/test_figures.py checks both).
"""

from __future__ import annotations

from contextlib import contextmanager
from pathlib import Path

import numpy as np
from matplotlib.ticker import FixedLocator, NullFormatter, NullLocator

from pcabench.predict.stability import UNSTABLE_BY_PREDICTION
from pcabench.reports import paper as P
from pcabench.reports import tables as T
from pcabench.reports.figdata import save_figure_data
from pcabench.store.safeio import save_figure
from solvers import kernel_names, scene_kind

CLASS_STYLE = {
    "stable": ("tab:green", "o"),
    "inaccurate": ("tab:orange", "s"),
    "unstable": ("tab:red", "X"),
    "timeout": ("tab:gray", "v"),
    "error": ("black", "x"),
    "out-of-memory": ("tab:purple", "P"),
    "skipped": ("tab:gray", "."),
    UNSTABLE_BY_PREDICTION: ("tab:red", "X"),
}
STAGE_COLOURS = {
    "input": "tab:gray",
    "init": "tab:brown",
    "snp": "tab:blue",
    "pi": "tab:orange",
    "su": "tab:green",
    "output": "tab:purple",
}
PRECISION_MARKER = {"float64": "o", "float32": "s"}
MODEL_COLOUR = {"linear": "tab:blue", "lagrangian": "tab:red", "fixed": "tab:green"}
SEARCH_COLOUR = {"all-pair": "tab:red", "linked list": "tab:blue"}
PAPER_MARKERS = {"paper-system-1": "^", "paper-system-2": "v", "paper-system-3": "D"}
PUBLISHED = {"color": "0.35", "ls": "--", "mfc": "none", "lw": 1.2}  # the paper's numbers, always this style


def palette(n: int) -> list:
    """``n`` distinct colours (tab10, then tab20 beyond ten series)."""
    import matplotlib

    name = "tab10" if n <= 10 else "tab20"
    cmap = matplotlib.colormaps[name]
    return [cmap(i % cmap.N) for i in range(n)]


def channels(**named) -> str:
    """The title's key to the channels that vary: ``channels(colour=("model", {...}))`` -> "; colour: model"
    when the set holds more than one value, else nothing (a channel that does not vary is not named)."""
    parts = [f"{ch}: {what}" for ch, (what, values) in named.items() if len(set(values)) > 1]
    return ("; " + ", ".join(parts)) if parts else ""


@contextmanager
def figure(
    path: Path,
    title: str,
    xlabel: str,
    ylabel: str,
    ncols: int = 1,
    nrows: int = 1,
    logx=False,
    logy=False,
    size=None,
    legend="right",
    sharey=False,
):
    """A constrained-layout figure with ``nrows x ncols`` axes, labelled and gridded, saved to ``path`` on exit.

    ``legend``: "right" puts one legend of every labelled series outside the axes, "below" one legend under
    each axes (for panels whose series share styles), "none" draws none.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(
        nrows,
        ncols,
        figsize=size or (6.5 * ncols + 2.5, 4.2 * nrows),
        squeeze=False,
        layout="constrained",
        sharey=sharey,
    )
    axes = list(axes.flat)
    for ax in axes:  # scales first: a figure may set its own ticks inside the block
        if logx:
            ax.set_xscale("log")
        if logy:
            ax.set_yscale("log")
    yield axes
    handles = {}
    for ax in axes:
        if not ax.axison:  # a panel turned into a key (its legend): no labels, no grid
            continue
        if not ax.get_xlabel():
            ax.set_xlabel(xlabel)
        if not ax.get_ylabel() and ax.get_subplotspec().is_first_col():
            ax.set_ylabel(ylabel)
        ax.grid(True, which="major", alpha=0.3)
        for h, lab in zip(*ax.get_legend_handles_labels()):
            handles.setdefault(lab, h)
        if legend == "below" and ax.get_legend_handles_labels()[0]:
            ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.16), fontsize=7, frameon=False)
    if handles and legend == "right":
        labels = sorted(handles, key=lambda lab: "(published)" in lab)  # measured first, the paper's after
        fig.legend([handles[lab] for lab in labels], labels, loc="outside right center", fontsize=7, frameon=False)
    _suptitle(fig, title)
    save_figure(fig, path, dpi=110)  # whole or not at all; a link at its name is replaced, not followed
    save_figure_data(fig, path)  # its data beside it, as a CSV a reader replots
    plt.close(fig)


def _suptitle(fig, title: str) -> None:
    """The figure's title, wrapped to its width (a long title is never cut at the edges)."""
    import textwrap

    fig.suptitle(textwrap.fill(title, width=int(fig.get_figwidth() * 12.5)), fontsize=10)


def plain_log_ticks(ax, values, axis="x", spread=1.8):
    """Major ticks at ``values`` written plainly (0.1, 0.05, ...), no minor labels, and no two ticks closer
    than a factor ``spread`` (so tick text never overlaps on a log axis)."""
    kept = []
    for v in sorted(set(values)):
        if not kept or v / kept[-1] >= spread:
            kept.append(v)
    target = ax.xaxis if axis == "x" else ax.yaxis
    target.set_major_locator(FixedLocator(kept))
    target.set_major_formatter(lambda v, _: f"{v:g}")
    target.set_minor_formatter(NullFormatter())


def particle_count(value, _position=None) -> str:
    """A particle count as a tick label: 500, 25K, 1.6M (one style on every panel of a figure)."""
    for scale, suffix in ((1e6, "M"), (1e3, "K")):
        if value >= scale:
            return f"{value / scale:g}{suffix}"
    return f"{value:g}"


def nice_log_ticks(ax, values, axis="y"):
    """Ticks 1, 2, 5 x 10^k (1 x 10^k over two decades or more) covering ``values``, written
    plainly (20, 50, 0.001; never 2x10^1), no minor labels."""
    values = [v for v in values if v and np.isfinite(v) and v > 0]
    lo, hi = min(values), max(values)
    mantissas = (1, 2, 5) if hi / lo < 100 else (1,)
    ticks = [
        m * 10.0**k for k in range(int(np.floor(np.log10(lo))) - 1, int(np.ceil(np.log10(hi))) + 1) for m in mantissas
    ]
    inside = [t for t in ticks if lo / 1.5 <= t <= hi * 1.5]
    plain_log_ticks(ax, inside or [lo, hi], axis=axis, spread=1.5)
    (ax.xaxis if axis == "x" else ax.yaxis).set_minor_locator(NullLocator())


def _published(ax, rows, marker, label, **style):
    """The paper's rows (from :mod:`.paper`) as one published series: grey, dashed, hollow."""
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
                    label=f"{s['model']} {s['precision']}{'' if domain else ' ' + s['domain']}: {T.trend(s)}"
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
    steps = T.fig9_steps(rows)
    if steps is None:
        return None
    rows = [r for r in rows if r["steps"] == steps and (r["allpair_ms"] or r["linkedlist_ms"])]
    path = out / "fig9_allpair_vs_linkedlist.png"
    loop = T.FIG9_LOOP_NAMES.get(rows[0]["linkedlist_loop"], rows[0]["linkedlist_loop"])
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
                marker,  # large and on top: never hidden
                f"paper {search}, {P.CONVERSION['Fig. 9 text']} (published; two sizes, not joined)",
                ms=10,
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


FIG10_SIZES = 2  # a panel is drawn where one of its series has this many sizes: a line against N, not a dot


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
        size=(4.6 * ncols + (0.6 if spare else 4.6), 3.4 * nrows + 0.6),
        legend="none" if spare else "right",
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
            sizes = [n for s in series if s["run"] == run for n in s["N"]]
            if max(sizes) / min(sizes) < 100:  # under two decades: ticks at the sizes run, never 2x10^5
                plain_log_ticks(ax, sizes, axis="x", spread=3.0)
                ax.xaxis.set_minor_locator(NullLocator())
            ax.xaxis.set_major_formatter(particle_count)  # every panel writes N alike: 1K, 25K, 1M
            if run != paper_panel:
                continue
            if ("cpu", "linked list") in kinds:
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
            if ("gpu", "linked list") in kinds:
                pts = [r for r in P.step_times() if r["device"] == "gpu" and r["source"] == "Table 4"]
                _published(ax, pts, "^", f"paper GPU, {pts[0]['processor']}, Table 4: one step (published)")
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
    _suptitle(fig, title)
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
            paper[name] = dict(zip(T.STEP_STAGES, values))
    return _shares(
        out / "fig11_step_shares.png",
        f"Fig. 11 / Table 5: share of a step by stage, runs of {run} ({pid}; Table 5 has every run length)",
        "% of one step (SNP + PI + SU)",
        rows,
        list(paper.items()),
        T.STEP_STAGES,
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
                {s: 100 * x / sum(v) for s, x in zip(T.STAGES, v)},
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
        T.STAGES,
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
        others = _groups(sorted(across, key=lambda r: tuple(r[k] for k in by)), by)
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


def _groups(rows, keys):
    seen = {}
    for r in rows:
        seen.setdefault(tuple(r[k] for k in keys), []).append(r)
    return list(seen.items())


TAB10 = (
    "tab:blue",
    "tab:orange",
    "tab:green",
    "tab:red",
    "tab:purple",
    "tab:brown",
    "tab:pink",
    "tab:gray",
    "tab:olive",
    "tab:cyan",
)


def kernel_colour(kernel: str) -> str:
    """A kernel's colour by its place in the registry (the Gaussian, the paper's, blue; the others in the
    registry's order); grey for a stored kernel not registered here."""
    names = kernel_names()
    return TAB10[names.index(kernel) % len(TAB10)] if kernel in names else "grey"


def speed_vs_accuracy(points, front, out: Path, pid: str):
    """Time to solution against error at the time most runs ended at, one panel per model: every run (colour:
    kernel; hollow: float32), the paper's method starred, each model's front, and the prediction beside it."""
    if not points:
        return None
    times = [p["t_final"] for p in points]
    t_main = max(set(times), key=times.count)  # one physical time: the one most runs ended at (10 s in the presets)
    panels = [
        (t_main, m)
        for m in T.FRONT_MODELS  # a few points are no front
        if sum((q["t_final"], q["model"]) == (t_main, m) for q in points) >= 4
    ]
    if not panels:
        return None
    here_all = [p for p in points if (p["t_final"], p["model"]) in panels]
    key = channels(
        colour=("kernel", [p["kernel"] for p in here_all]),
        **{"hollow triangle": ("float32", [p["precision"] for p in here_all])},
    )
    path = out / "speed_vs_accuracy.png"
    with figure(
        path,
        f"Time to solution against error ({pid}){key}; black line: the fastest run to each error",
        "time to solution (s: init + steps, no JIT)",
        "relative RMS error of u at t (lagrangian: vs isothermal)",
        ncols=len(panels),
        logx=True,
        logy=True,
        size=(5.2 * len(panels) + 3.8, 4.6),
    ) as axes:
        for ax, (t_final, model) in zip(axes, panels):
            here = [p for p in points if (p["t_final"], p["model"]) == (t_final, model)]
            for (kern, precision), pts in _groups(
                [p for p in here if not p.get("past_limit")], ("kernel", "precision")
            ):
                colour = kernel_colour(kern)
                single = precision == "float32"  # a hollow triangle over the filled float64 circle: both show
                ax.plot(
                    [p["seconds"] for p in pts],
                    [p["error"] for p in pts],
                    ls="none",
                    marker="^" if single else "o",
                    ms=6.5 if single else 4.5,
                    color=colour,
                    mfc="none" if single else colour,
                    mew=1.0,
                    alpha=0.85 if single else 0.7,
                    zorder=4 if single else 3,
                    label=f"{kern}, {precision}",
                )
            past = [p for p in here if p.get("past_limit")]
            if past:
                ax.plot(
                    [p["seconds"] for p in past],
                    [p["error"] for p in past],
                    ls="none",
                    marker="X",
                    ms=6,
                    mfc="none",
                    mec="tab:purple",
                    mew=1.0,
                    label="unstable by prediction (CFL at or past its stable CFL), any kernel: never on the front",
                )
            paper = [p for p in here if p["paper_method"]]
            ax.plot(
                [p["seconds"] for p in paper],
                [p["error"] for p in paper],
                ls="none",
                marker="*",
                ms=11,
                mfc="none",
                mec="black",
                mew=1.1,
                label="the paper's method (Gaussian, h 2.13dx, 3h, CFL 0.2)",
            )
            fp = [p for p in front if (p["t_final"], p["model"]) == (t_final, model)]
            ax.step(
                [p["seconds"] for p in fp],
                [p["error"] for p in fp],
                color="black",
                where="post",
                lw=1.3,
                label="front: fastest run to each error",
            )
            ax.step(  # a dashed line, not marks: the runs under it stay in sight
                [p["seconds"] for p in fp],
                [T.predicted_error(p) for p in fp],
                color="crimson",
                where="post",
                lw=1.1,
                ls="--",
                zorder=2,
                label="the front runs' error, predicted (dispersion relation, linear part)",
            )
            ax.set_title(f"{model}, t = {t_final:g} s ({len(here)} runs)", fontsize=9)
            # plain ticks: a narrow log range would label its minor ticks too, and they collide
            nice_log_ticks(ax, [p["seconds"] for p in here], axis="x")
            nice_log_ticks(ax, [p["error"] for p in here] + [T.predicted_error(p) for p in fp], axis="y")
    return path


def stability_map(points, limits, out: Path, pid: str, inaccurate_above: float):
    """Each method's runs by CFL, in the classes of the section's table (``tables.stability``), and the
    predicted stable CFL of each row as a black bar; a tick at every CFL swept."""
    if not points:
        return None
    configs = [lim["config"] for lim in limits]
    path = out / "stability_map.png"
    with figure(
        path,
        f"Stability map ({pid}): each method's runs by CFL",  # the key is the legend's: a short title
        "CFL = dt c0 / dx",
        "",
        logx=True,
        size=(11.5, max(3.0, 1.5 + 0.32 * len(configs))),
    ) as (ax,):
        words = {
            "inaccurate": f"inaccurate (bounded,\nrelative RMS > {100 * inaccurate_above:g} %)",
            "unstable": "unstable (number: the step\nit blew up at)",
            UNSTABLE_BY_PREDICTION: "unstable by prediction (past the stable\nCFL, ended bounded: too few steps\n"
            "for round-off to grow)",
        }
        for cls, (colour, marker) in CLASS_STYLE.items():
            pts = [p for p in points if p["class"] == cls]
            if pts:
                hollow = cls == UNSTABLE_BY_PREDICTION
                ax.scatter(
                    [p["cfl"] for p in pts],
                    [configs.index(p["config"]) for p in pts],
                    c="white" if hollow else colour,
                    edgecolors=colour if hollow else None,
                    marker=marker,
                    s=40,
                    linewidths=1.2 if hollow else None,
                    label=words.get(cls, cls),
                    zorder=3,
                )  # above the limit bar
        for p in points:
            if p["class"] == "unstable" and p["failed_step"]:
                ax.annotate(
                    f"{int(p['failed_step'])}",
                    (p["cfl"], configs.index(p["config"])),
                    fontsize=6,
                    xytext=(3, 3),
                    textcoords="offset points",
                )
        cfls = [p["cfl"] for p in points]
        drawn = False
        for i, lim in enumerate(limits):
            if lim["stable_cfl"] > 0:
                ax.plot(
                    [lim["stable_cfl"]] * 2,
                    [i - 0.38, i + 0.38],
                    color="black",
                    lw=1.5,
                    solid_capstyle="butt",
                    label=None if drawn else "the stable CFL (predicted;\nlong runs where lower)",
                )
                drawn = True
            else:
                ax.annotate(
                    "predicted: grows at every CFL",
                    (min(cfls), i),
                    xytext=(-4, 6),
                    textcoords="offset points",
                    fontsize=6,
                    color="0.3",
                    ha="left",
                )
        ax.set_xlim(min(cfls) / 1.25, max(cfls + [lim["stable_cfl"] for lim in limits]) * 1.1)
        ax.xaxis.set_major_locator(FixedLocator(sorted(set(cfls))))
        ax.xaxis.set_major_formatter(lambda v, _: f"{v:g}")
        ax.xaxis.set_minor_locator(NullLocator())
        ax.tick_params(axis="x", labelsize=7, labelrotation=90)
        ax.set_yticks(range(len(configs)))
        ax.set_yticklabels(configs, fontsize=7)
        ax.set_ylim(-0.6, len(configs) - 0.4)
    return path


def cards_figure(rows, out: Path):
    """One GPU step against N: each measured card and precision, beside the paper's three cards (grey)."""
    pub = T.cards_published()
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
        for (system, card, source), pts in _groups(pub, ("system", "processor", "source")):
            _published(ax, pts, PAPER_MARKERS[system], f"{card}, {source}: {pts[0]['conversion']} (published)")
        for (_, precision, how), pts in _groups(rows, ("profile", "precision", "protocol")):
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


FRONT_PANEL_RUNS = 8  # a scene's panel needs this many runs at the default amplitude: fewer draw no front


def front_of(pts: list[dict]) -> list[dict]:
    """The runs no faster run beats in error (the lower-left envelope), fastest first; runs past their stable
    CFL are never on it."""
    front, best = [], np.inf
    for p in sorted((p for p in pts if not p["past_stable"]), key=lambda p: (p["seconds"], p["error"])):
        if p["error"] < best:
            front.append(p)
            best = p["error"]
    return front


def scene_fronts(points, out: Path, pid: str):
    """Time to solution against error, one panel per scene at its default amplitude (t = 10 s) with at least
    FRONT_PANEL_RUNS runs: each model a colour, its front a step line, runs past their predicted stable CFL
    drawn as crosses (never on a front). A scene with fewer runs (the walls: their own figure) has no panel."""
    counts = {}
    for p in points:
        if np.isclose(p["mach"], 0.05):
            counts[p["scene"]] = counts.get(p["scene"], 0) + 1
    scenes = sorted((s for s, n in counts.items() if n >= FRONT_PANEL_RUNS), key=lambda s: (s != "plane-pulse", s))
    if len(scenes) < 2:
        return None
    path = out / "scene_fronts.png"
    past = " x: past the predicted stable CFL," if any(p["past_stable"] for p in points) else ""
    ncols = min(len(scenes), 2)
    nrows = -(-len(scenes) // ncols)
    with figure(
        path,
        f"Time to solution against error on each scene, t = 10 s, Mach 0.05 ({pid});{past} colour: model; "
        "each stepped line is a model's front (no faster run has a smaller error)",
        "time to solution, s",
        "relative RMS error",
        ncols=ncols,
        nrows=nrows,
        logx=True,
        logy=True,
        size=(6.0 * ncols + 2.5, 4.3 * nrows),
    ) as axes:
        for ax in axes[len(scenes) :]:
            ax.set_visible(False)
        for ax, scene in zip(axes, scenes):
            mine = [p for p in points if p["scene"] == scene and np.isclose(p["mach"], 0.05)]
            for model in ("linear", "lagrangian"):
                for past in (False, True):
                    pts = [p for p in mine if p["model"] == model and p["past_stable"] == past]
                    if not pts:
                        continue
                    ax.scatter(
                        [p["seconds"] for p in pts],
                        [p["error"] for p in pts],
                        s=14 if not past else 22,
                        marker="x" if past else "o",
                        color=MODEL_COLOUR[model],
                        alpha=0.55 if not past else 0.5,
                        label=f"{model}" + (" (past the stable CFL)" if past else ""),
                    )
                line = front_of([p for p in mine if p["model"] == model])
                if len(line) > 1:
                    ax.step(
                        [p["seconds"] for p in line],
                        [p["error"] for p in line],
                        where="post",
                        color=MODEL_COLOUR[model],
                        lw=1.6,
                        label=f"{model} front",
                    )
            errors = [p["error"] for p in mine]
            nice_log_ticks(ax, errors)
            nice_log_ticks(ax, [p["seconds"] for p in mine], axis="x")
            ax.set_ylabel(f"relative RMS error of {scene_kind(scene).primary}")
            ax.set_title(scene, fontsize=9)
    return path


def phase_direction(curves, fronts, out: Path, pid: str):
    """The lattice's anisotropy: the predicted phase speed error's change from its value along the axis, against
    the direction of travel, one colour per method, at the pulse's wavenumber and at a short wave (a panel
    each); where 2D runs stored it, their wave front speed error along the axis and the diagonal, measured
    against predicted, each run in its method's colour (grey: a method with no curve)."""
    if not curves:
        return None
    path = out / "phase_direction.png"
    colours = palette(len(curves))
    colour_of = {c["label"].removesuffix(" (paper's)"): colour for c, colour in zip(curves, colours)}
    fronts = [f for f in fronts if f["predicted"][0] is not None]
    with figure(
        path,
        f"Phase speed against the direction of travel, predicted at dx = 0.25 m ({pid}); colour: method",
        "direction, degrees from the lattice's x axis",
        "phase speed error minus its value along the axis, %",
        ncols=3 if fronts else 2,
        size=(15.5 if fronts else 11.0, 5.2),
    ) as axes:
        for ax, key, title in (
            (axes[0], "error", "the pulse's wavenumber k = 1/b"),
            (axes[1], "short", "a short wave, 8 particles per wavelength"),
        ):
            for i, (c, colour) in enumerate(zip(curves, colours)):
                values = 100 * np.asarray(c[key])
                style = ("-", "--", ":", "-.")[i % 4]  # a curve under another still shows
                ax.plot(c["angles"], values - values[0], color=colour, ls=style, lw=1.8, label=c["label"])
            ax.set_xticks([0, 15, 30, 45])
            ax.set_title(title, fontsize=10)
        if fronts:
            ax = axes[2]
            ax.set_xlabel("predicted front speed error, %")
            ax.set_ylabel("measured front speed error, %")
            ax.set_title("2D runs: the front along the axis (o) and the diagonal (^)", fontsize=10)
            values = []
            for f in fronts:
                colour = colour_of.get(f["method"], "0.5")
                for k, marker in ((0, "o"), (1, "^")):
                    ax.scatter(
                        100 * f["predicted"][k],
                        100 * f["measured"][k],
                        marker=marker,
                        facecolors="none",
                        edgecolors=colour,
                        s=36,
                        label=None if f["method"] in colour_of else "runs of other methods",
                    )
                    values += [100 * f["predicted"][k], 100 * f["measured"][k]]
            lo, hi = min(values), max(values)
            pad = 0.05 * (hi - lo or 1.0)
            ax.plot(
                [lo - pad, hi + pad], [lo - pad, hi + pad], color="0.6", lw=0.8, ls=":", label="measured = predicted"
            )
    return path


def wall_errors(rows, out: Path, pid: str):
    """The error near the wall and in the bulk against dx at t = 10 s, a panel per wall scene (``rows``: the walls
    section's accuracy rows): measured as markers (hollow: lagrangian), the linear prediction as lines."""
    scenes = sorted({r["scene"] for r in rows if r["wall_rms"] is not None})
    if not scenes:
        return None
    where = {
        "near the wall": ("wall_rms", "predicted_wall", "tab:red"),
        "bulk": ("bulk_rms", "predicted_bulk", "tab:blue"),
    }
    models = {r["model"] for r in rows}
    path = out / "walls_error.png"
    with figure(
        path,
        f"Error near the wall and in the bulk against dx, t = 10 s, the paper's method ({pid}); "
        f"colour: where{'; hollow: lagrangian (against the linear solution)' if len(models) > 1 else ''}; "
        "lines: the linear prediction on the mirror extension (the linear runs sit on it)",
        "dx, m",
        "RMS error / RMS of the exact field over the domain",
        ncols=len(scenes),
        logx=True,
        logy=True,
        size=(4.6 * len(scenes) + 3.2, 4.2),
    ) as axes:
        for ax, scene in zip(axes, scenes):
            mine = [r for r in rows if r["scene"] == scene and r["wall_rms"] is not None]
            values = []
            for label, (key, pkey, colour) in where.items():
                for model in ("linear", "lagrangian"):
                    pts = sorted((r["dx"], r[key]) for r in mine if r["model"] == model)
                    if pts:
                        ax.plot(
                            *zip(*pts),
                            ls="none",
                            marker="o",
                            ms=6,
                            color=colour,
                            mfc=colour if model == "linear" else "none",
                            label=f"{label}, {model} (measured)",
                        )
                        values += [v for _, v in pts]
                pred = sorted((r["dx"], r[pkey]) for r in mine if r["model"] == "linear" and r[pkey] is not None)
                if pred:
                    ax.plot(*zip(*pred), ls="-", lw=1.1, color=colour, label=f"{label}, linear (predicted)")
                    values += [v for _, v in pred]
            plain_log_ticks(ax, [r["dx"] for r in mine])
            nice_log_ticks(ax, values)
            ax.set_title(f"{scene} (error of {'u' if scene == 'plane-wall' else 'drho'})", fontsize=9)
    return path
