"""The report's PNG figures, drawn from the rows of ``tables.py``.

Each function draws one figure into ``out`` and returns its path, or None
when the store holds no data for it. One variable per visual channel:
colour for the solver configuration or card (never repeated within a figure),
marker for precision, line style for measured (solid) against published
(dashed, grey, hollow markers, "published" in the legend), facets for the
protocol or the kind of run. Legends sit outside the data, and matplotlib's
constrained layout keeps labels from overlapping.
"""
from __future__ import annotations

from contextlib import contextmanager
from pathlib import Path

import numpy as np
from matplotlib.ticker import NullFormatter

from . import tables as T

CLASS_STYLE = {"stable": ("tab:green", "o"), "inaccurate": ("tab:orange", "s"), "unstable": ("tab:red", "X"),
               "timeout": ("tab:gray", "v"), "error": ("black", "x"), "out-of-memory": ("tab:purple", "P"),
               "skipped": ("tab:gray", ".")}
STAGE_COLOURS = {"input": "tab:gray", "init": "tab:brown", "snp": "tab:blue", "pi": "tab:orange",
                 "su": "tab:green", "output": "tab:purple"}
PRECISION_MARKER = {"float64": "o", "float32": "s"}
MODEL_COLOUR = {"linear": "tab:blue", "lagrangian": "tab:red", "fixed": "tab:green"}
PAPER_MARKERS = {"paper-system-1": "^", "paper-system-2": "v", "paper-system-3": "D"}
PUBLISHED = {"color": "0.35", "ls": "--", "mfc": "none", "lw": 1.2}  # the paper's numbers, always this style


def palette(n: int) -> list:
    """``n`` distinct colours (tab10, then tab20 beyond ten series)."""
    import matplotlib

    name = "tab10" if n <= 10 else "tab20"
    cmap = matplotlib.colormaps[name]
    return [cmap(i % cmap.N) for i in range(n)]


@contextmanager
def figure(path: Path, title: str, xlabel: str, ylabel: str, ncols: int = 1, nrows: int = 1, logx=False,
           logy=False, size=None, legend="right", sharey=False):
    """A constrained-layout figure with ``nrows x ncols`` axes, labelled and gridded, saved to ``path`` on exit.

    ``legend``: "right" puts one legend of every labelled series outside the axes, "none" draws none.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(nrows, ncols, figsize=size or (6.5 * ncols + 2.5, 4.2 * nrows), squeeze=False,
                             layout="constrained", sharey=sharey)
    axes = list(axes.flat)
    for ax in axes:  # scales first: a figure may set its own ticks inside the block
        if logx:
            ax.set_xscale("log")
        if logy:
            ax.set_yscale("log")
    yield axes
    handles = {}
    for ax in axes:
        if not ax.get_xlabel():
            ax.set_xlabel(xlabel)
        if not ax.get_ylabel() and ax is axes[0]:
            ax.set_ylabel(ylabel)
        ax.grid(True, which="major", alpha=0.3)
        for h, lab in zip(*ax.get_legend_handles_labels()):
            handles.setdefault(lab, h)
    if handles and legend == "right":
        fig.legend(list(handles.values()), list(handles), loc="outside right center", fontsize=7, frameon=False)
    fig.suptitle(title, fontsize=10)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plain_log_ticks(ax, values, axis="x", spread=1.8):
    """Major ticks at ``values`` written plainly (0.1, 0.05, ...), no minor labels, and no two ticks closer
    than a factor ``spread`` (so tick text never overlaps on a log axis)."""
    from matplotlib.ticker import FixedLocator, NullFormatter

    kept = []
    for v in sorted(set(values)):
        if not kept or v / kept[-1] >= spread:
            kept.append(v)
    values = kept
    target = ax.xaxis if axis == "x" else ax.yaxis
    target.set_major_locator(FixedLocator(values))
    target.set_major_formatter(lambda v, _: f"{v:g}")
    target.set_minor_formatter(NullFormatter())


def fig8(df, out: Path, pid: str):
    series = T.error_series(df)
    if not series:
        return None
    protocols = sorted({s["protocol"] for s in series}, key=lambda p: (not p.startswith("t ="), p))
    path = out / "fig8_error_vs_dx.png"
    with figure(path, f"Fig. 8: error against dx ({pid}); colour: model, marker: precision, "
                f"line: domain", "dx (m)", "relative RMS error of u (paper's MSE)",
                ncols=len(protocols), logx=True, logy=True, size=(5.2 * len(protocols) + 3.2, 4.4)) as axes:
        for ax, protocol in zip(axes, protocols):
            dxs = []
            for s in (s for s in series if s["protocol"] == protocol):
                how = (f"stops falling at dx = {s['stops_falling']:g}" if s["stops_falling"]
                       else f"fitted order {s['order']:.2f}")
                f32 = s["precision"] == "float32"
                ax.plot(s["dx"], s["mse"], color=MODEL_COLOUR.get(s["model"], "k"),
                        marker=PRECISION_MARKER[s["precision"]], ms=9 if f32 else 5, mfc="none" if f32 else None,
                        ls="-" if s["domain"] == "strip" else ":", lw=1.2,
                        label=f"{protocol}: {s['model']} {s['precision']} {s['domain']} ({how})")
                dxs += list(s["dx"])
            if protocol == "100 steps":
                ax.plot([0.004], [T.published()["text"]["fig8_mse_100_steps_dx_0.004"]], marker="^", ms=8,
                        **PUBLISHED, label="paper, dx = 0.004, 100 steps (published)")
                dxs.append(0.004)
            plain_log_ticks(ax, dxs)
            ax.set_title(protocol + (" (fixed physical time)" if protocol.startswith("t =")
                                     else " (the paper's protocol)"), fontsize=9)
    return path


def fig9(df, out: Path, pid: str):
    rows = [r for r in T.fig9(df) if r["allpair_ms"] or r["linkedlist_ms"]]
    if not any(r["allpair_ms"] for r in rows):
        return None
    text = T.published()["text"]
    path = out / "fig9_allpair_vs_linkedlist.png"
    colours = {"all-pair": "tab:red", "linked list": "tab:blue"}
    with figure(path, f"Fig. 9: all-pair against linked list, serial CPU, float64 ({pid})", "particles N", "",
                ncols=2, logx=True, logy=True, size=(13, 4.4)) as (a, b):
        loop = T.FIG9_LOOP_NAMES[rows[0]["linkedlist_loop"]]
        for key, name, label in (("allpair_ms", "all-pair", "all-pair (measured)"),
                                 ("linkedlist_ms", "linked list", f"linked list, {loop} (measured)")):
            pts = [(r["N"], r[key]) for r in rows if r[key]]
            a.plot(*zip(*pts), marker="o", color=colours[name], label=label)
        for name, key, marker in (("all-pair", "fig9_allpair_s", "^"), ("linked list", "fig9_linkedlist_s", "v")):
            a.plot([int(n) for n in text[key]], [1e3 * v / 10 for v in text[key].values()], marker=marker,
                   **dict(PUBLISHED, color=colours[name]), label=f"paper {name}, run / 10 steps (published)")
        skipped = [r["N"] for r in rows if r["allpair_status"] == "skipped"]
        for n in skipped:
            a.axvline(n, color="tab:gray", ls=":", lw=1)
        a.set_ylabel("one step (ms)")
        a.set_title("runtime" + (" (dotted: all-pair predicted past the budget, skipped)" if skipped else ""),
                    fontsize=9)
        pts = [(r["N"], r["eta"]) for r in rows if r["eta"]]
        if pts:
            b.plot(*zip(*pts), marker="o", color="tab:purple", label="speedup eta (measured)")
        b.plot([int(n) for n in text["fig9_allpair_s"]],
               [text["fig9_allpair_s"][n] / text["fig9_linkedlist_s"][n] for n in text["fig9_allpair_s"]],
               marker="^", **dict(PUBLISHED, color="tab:purple"), label="speedup eta (paper, published)")
        b.set_ylabel("eta = t_all-pair / t_linked-list")
        b.set_title("speedup (eq. 12)", fontsize=9)
    return path


def fig10(df, out: Path, pid: str):
    runs = T.paper_scene(df)
    if runs.empty:
        return None
    path = out / "fig10_runtime_vs_N.png"
    groups = list(runs.groupby(["solver", "precision", "threads", "pair_loop"]))
    colours = palette(len(groups) + 2)
    with figure(path, f"Fig. 10: runtime per step against N ({pid}); paper's CPU beside our CPUs, "
                f"its GPU beside our GPUs", "particles N", "one step SNP+PI+SU (ms)",
                logx=True, logy=True, size=(10, 4.6)) as (ax,):
        for colour, ((solver, precision, threads, loop), g) in zip(colours, groups):
            g = g.sort_values("n_particles").drop_duplicates("n_particles", keep="last")
            ax.plot(g.n_particles, 1e3 * g.t_step, marker=PRECISION_MARKER[precision], color=colour,
                    label=T.label({"solver": solver, "precision": precision, "threads": threads,
                                   "pair_loop": loop}))
        has_gpu = (runs.solver == "linkedlist-gpu").any()
        has_cpu = (runs.solver != "linkedlist-gpu").any()
        if has_cpu:
            pts = T.paper_cpu_step_ms()
            ax.plot(list(pts), list(pts.values()), marker="v", **dict(PUBLISHED, color=colours[-2]),
                    label="paper CPU (Xeon E5-2680, serial; published)")
        if has_gpu:
            t4 = T.published()["table4"]["rows"]
            ax.plot([int(k) for k in t4], [sum(v[2:5]) for v in t4.values()], marker="^",
                    **dict(PUBLISHED, color=colours[-1]), label="paper GPU (Tesla K20c, Table 4; published)")
    return path


def _shares(path, title, xlabel, rows, published, stages):
    """Horizontal stacked bars: our rows (config, N) above, the paper's (hatched) in their own panel below."""
    ours = [(f"{r['config']}, N={r['N']:,}", r) for r in rows]
    heights = [max(len(ours), 1), max(len(published), 1)]
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 1, figsize=(10, 1.4 + 0.26 * sum(heights)), layout="constrained",
                             gridspec_kw={"height_ratios": heights}, sharex=True)
    for ax, items, hatch, name in ((axes[0], ours, None, "measured"),
                                   (axes[1], published, "//", "paper (published)")):
        left = np.zeros(len(items))
        for s in stages:
            vals = np.array([sh[s] for _, sh in items])
            ax.barh(range(len(items)), vals, left=left, color=STAGE_COLOURS[s], hatch=hatch,
                    edgecolor="white" if hatch is None else "0.25", lw=0.4,
                    label=s.upper() if ax is axes[0] else None)
            left += vals
        ax.set_yticks(range(len(items)))
        ax.set_yticklabels([label for label, _ in items], fontsize=7)
        ax.invert_yaxis()
        ax.set_xlim(0, 100)
        ax.set_title(name, fontsize=9, loc="left")
        ax.grid(True, axis="x", alpha=0.3)
    axes[1].set_xlabel(xlabel)
    fig.legend(loc="outside lower center", ncols=len(stages), fontsize=8, frameon=False)
    fig.suptitle(title, fontsize=10)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def fig11(df, out: Path, pid: str):
    rows = T.table5(df)
    if not rows:
        return None
    text = T.published()["text"]["fig11_cpu_step_shares_pct"]
    paper = [("paper CPU, serial (Fig. 11 text)", {"snp": text["snp"], "pi": text["pi"],
                                                    "su": 100 - text["snp"] - text["pi"]})]
    paper += [(f"paper GPU Tesla K20c, N={int(n):,} (Table 5)", dict(zip(T.STEP_STAGES, v)))
              for n, v in sorted(T.published()["table5"]["rows"].items(), key=lambda kv: int(kv[0]))]
    return _shares(out / "fig11_step_shares.png", f"Fig. 11 / Table 5: share of a step by stage ({pid})",
                   "% of one step (SNP + PI + SU)", rows, paper, T.STEP_STAGES)


def fig13(df, out: Path, pid: str):
    rows = T.one_step_shares(df)
    if not rows:
        return None
    paper = [(f"paper GPU Tesla K20c, N={int(n):,} (Table 4)", {s: 100 * x / sum(v) for s, x in zip(T.STAGES, v)})
             for n, v in sorted(T.published()["table4"]["rows"].items(), key=lambda kv: int(kv[0]))]
    return _shares(out / "fig13_task_shares.png", f"Fig. 13: share of a one-step run by task ({pid})",
                   "% of a one-step run", rows, paper, T.STAGES)


def fig14(df_all, out: Path, title: str):
    rows = [r for r in T.table6(df_all) if r["same_machine"]]
    path = out / "fig14_speedup_vs_N.png"
    pub = T.table6_published()
    keys = sorted({(r["gpu_profile"], r["precision"]) for r in rows})
    colours = palette(len(keys))
    with figure(path, f"Fig. 14: GPU speedup per step over its own host's CPU ({title})", "particles N",
                "speedup per step", logx=True, logy=True, size=(10, 4.6)) as (ax,):
        for system in T.PAPER_SYSTEMS:
            pts = [(r["N"], r["speedup"]) for r in pub if r["system"] == system]
            card = next(r["card"] for r in pub if r["system"] == system)
            ax.plot(*zip(*pts), marker=PAPER_MARKERS[system], **PUBLISHED,
                    label=f"{system}: {card} vs one core of its host (published)")
        for colour, (gp, prec) in zip(colours, keys):
            pts = [r for r in rows if (r["gpu_profile"], r["precision"]) == (gp, prec)]
            ax.plot([r["N"] for r in pts], [r["speedup"] for r in pts], marker=PRECISION_MARKER[prec], color=colour,
                    label=f"{gp} {prec} vs one core of its host")
            multi = [r for r in pts if r["speedup_all_cores"]]
            if multi:
                ax.plot([r["N"] for r in multi], [r["speedup_all_cores"] for r in multi],
                        marker=PRECISION_MARKER[prec], color=colour, ls=":", mfc="none",
                        label=f"{gp} {prec} vs all cores of its host")
        if not rows:
            ax.text(0.02, 0.95, "no GPU measured with its own host's CPU yet: only the paper's lines",
                    transform=ax.transAxes, fontsize=8, color="0.3")
    return path


def _groups(rows, keys):
    seen = {}
    for r in rows:
        seen.setdefault(tuple(r[k] for k in keys), []).append(r)
    return list(seen.items())


KERNEL_COLOURS = {"gaussian": "tab:blue", "wendland-c2": "tab:orange", "wendland-c4": "tab:green"}


def speed_vs_accuracy(df, out: Path, pid: str):
    """Time to solution against error at the time most runs ended at, one panel per model: every run (colour:
    kernel; hollow: float32), the paper's method starred, each model's front, and the prediction beside it."""
    points, front = T.speed_front(df)
    if not points:
        return None
    times = [p["t_final"] for p in points]
    t_main = max(set(times), key=times.count)  # one physical time: the one most runs ended at (10 s in the presets)
    panels = [(t_main, m) for m in T.FRONT_MODELS  # a few points are no front
              if sum((q["t_final"], q["model"]) == (t_main, m) for q in points) >= 4]
    if not panels:
        return None
    path = out / "speed_vs_accuracy.png"
    with figure(path, f"Time to solution against error ({pid}): every finished run; black line: the fastest run "
                "to each error", "time to solution (s: init + steps, no JIT)",
                "relative RMS error of u at t (lagrangian: vs isothermal)",
                ncols=len(panels), logx=True, logy=True, size=(5.2 * len(panels) + 3.8, 4.6)) as axes:
        for ax, (t_final, model) in zip(axes, panels):
            here = [p for p in points if (p["t_final"], p["model"]) == (t_final, model)]
            for (kern, precision), pts in _groups(here, ("kernel", "precision")):
                colour = KERNEL_COLOURS.get(kern, "grey")
                ax.plot([p["seconds"] for p in pts], [p["error"] for p in pts], ls="none", marker="o", ms=4.5,
                        color=colour, mfc="none" if precision == "float32" else colour, alpha=0.75,
                        label=f"{kern}, {precision}")
            paper = [p for p in here if p["paper_method"]]
            ax.plot([p["seconds"] for p in paper], [p["error"] for p in paper], ls="none", marker="*", ms=11,
                    mfc="none", mec="black", mew=1.1, label="the paper's method (Gaussian, h 2.13dx, 3h, CFL 0.2)")
            fp = [p for p in front if (p["t_final"], p["model"]) == (t_final, model)]
            ax.step([p["seconds"] for p in fp], [p["error"] for p in fp], color="black", where="post", lw=1.3,
                    label="front: fastest run to each error")
            ax.plot([p["seconds"] for p in fp], [T.predicted_error(p) for p in fp], ls="none", marker="x", ms=6,
                    color="crimson", label="front runs, predicted (dispersion relation, linear part)")
            ax.set_title(f"{model}, t = {t_final:g} s ({len(here)} runs)", fontsize=9)
            for axis in (ax.xaxis, ax.yaxis):  # a narrow log range labels its minor ticks too, and they collide
                axis.set_minor_formatter(NullFormatter())
    return path


def stability_map(df, out: Path, pid: str, inaccurate_above: float):
    points, limits = T.stability(df, inaccurate_above)
    if not points:
        return None
    configs = [lim["config"] for lim in limits]
    path = out / "stability_map.png"
    with figure(path, f"Stability map ({pid}): inaccurate = bounded but relative RMS > "
                f"{100 * inaccurate_above:g} %; numbers: the step where an unstable run stopped",
                "CFL = dt c0 / dx", "", logx=True, size=(11, 1.8 + 0.32 * len(configs))) as (ax,):
        for cls, (colour, marker) in CLASS_STYLE.items():
            pts = [p for p in points if p["class"] == cls]
            if pts:
                ax.scatter([p["cfl"] for p in pts], [configs.index(p["config"]) for p in pts], c=colour,
                           marker=marker, s=40, label=cls)
        for p in points:
            if p["class"] == "unstable" and p["failed_step"]:
                ax.annotate(f"{int(p['failed_step'])}", (p["cfl"], configs.index(p["config"])), fontsize=6,
                            xytext=(3, 3), textcoords="offset points")
        plain_log_ticks(ax, [p["cfl"] for p in points])
        ax.tick_params(axis="x", labelsize=7)
        ax.set_yticks(range(len(configs)))
        ax.set_yticklabels(configs, fontsize=7)
        ax.set_ylim(-0.6, len(configs) - 0.4)
    return path


def cards_figure(df_all, out: Path):
    rows, pub = T.cards(df_all), T.cards_published()
    path = out / "cards_step_vs_N.png"
    cards = sorted({p["card"] for p in rows})
    colours = dict(zip(cards, palette(len(cards))))
    with figure(path, "GPU cards side by side: one lagrangian step (SNP+PI+SU) against N; colour: card, "
                "marker: precision", "particles N", "one step (ms)", logx=True, logy=True, size=(10, 4.6)) as (ax,):
        for (system, card, source), pts in _groups(pub, ("system", "card", "source")):
            ax.plot([p["N"] for p in pts], [p["step_ms"] for p in pts], marker=PAPER_MARKERS[system],
                    **dict(PUBLISHED, alpha=0.5 if "Table 6" in source else 1.0),
                    label=f"{card} ({source}; published)")
        for (profile, precision), pts in _groups(rows, ("profile", "precision")):
            ax.plot([p["N"] for p in pts], [p["step_ms"] for p in pts], marker=PRECISION_MARKER[precision],
                    color=colours[pts[0]["card"]], label=f"{pts[0]['card']} {precision} (measured)")
    return path
