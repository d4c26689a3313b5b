"""The report's PNG figures, drawn from the rows of ``tables.py``.

Each function draws one figure into ``out`` and returns its path, or None
when the store holds no data for it. Published numbers are drawn in black
and labelled as the paper's.
"""
from __future__ import annotations

from contextlib import contextmanager
from pathlib import Path

import numpy as np

from . import tables as T

CLASS_STYLE = {"stable": ("tab:green", "o"), "inaccurate": ("tab:orange", "s"), "unstable": ("tab:red", "X"),
               "timeout": ("tab:gray", "v"), "error": ("black", "x"), "out-of-memory": ("tab:purple", "P"),
               "skipped": ("tab:gray", ".")}
STAGE_COLOURS = {"input": "tab:gray", "init": "tab:brown", "snp": "tab:blue", "pi": "tab:orange",
                 "su": "tab:green", "output": "tab:purple"}


@contextmanager
def figure(path: Path, title: str, xlabel: str, ylabel: str, ncols: int = 1, logx=False, logy=False, size=None):
    """A figure with ``ncols`` axes, labelled, gridded, saved to ``path`` on exit."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, ncols, figsize=size or (6 * ncols, 4.2), squeeze=False)
    axes = list(axes[0])
    for ax in axes:  # scales first: a figure may set its own ticks inside the block
        if logx:
            ax.set_xscale("log")
        if logy:
            ax.set_yscale("log")
    yield axes
    for ax in axes:
        if not ax.get_xlabel():
            ax.set_xlabel(xlabel)
        if not ax.get_ylabel():
            ax.set_ylabel(ylabel)
        ax.grid(True, which="both", alpha=0.3)
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=6)
    fig.suptitle(title, fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def fig8(df, out: Path, pid: str):
    series = T.error_series(df)
    if not series:
        return None
    protocols = sorted({s["protocol"] for s in series}, key=lambda p: (not p.startswith("t ="), p))
    path = out / "fig8_error_vs_dx.png"
    with figure(path, f"Fig. 8: error against dx ({pid})", "dx (m)", "relative RMS error of u (paper's MSE)",
                ncols=len(protocols), logx=True, logy=True) as axes:
        for ax, protocol in zip(axes, protocols):
            for s in (s for s in series if s["protocol"] == protocol):
                how = (f"stops falling at dx = {s['stops_falling']:g}" if s["stops_falling"]
                       else f"order {s['order']:.2f}")
                ax.plot(s["dx"], s["mse"], "o-", label=f"{s['model']} {s['precision']} {s['domain']} ({how})")
            if protocol == "100 steps":
                ax.plot([0.004], [T.published()["text"]["fig8_mse_100_steps_dx_0.004"]], "k^",
                        label="paper, dx = 0.004 (published)")
            ax.set_title(protocol, fontsize=8)
    return path


def fig9(df, out: Path, pid: str):
    rows = [r for r in T.fig9(df) if r["allpair_ms"] or r["linkedlist_ms"]]
    if not any(r["allpair_ms"] for r in rows):
        return None
    text = T.published()["text"]
    path = out / "fig9_allpair_vs_linkedlist.png"
    with figure(path, f"Fig. 9: all-pair against linked list, serial CPU ({pid})", "particles N", "",
                ncols=2, logx=True, logy=True) as (a, b):
        for key, name in (("allpair_ms", "all-pair"), ("linkedlist_ms", "linked list")):
            pts = [(r["N"], r[key]) for r in rows if r[key]]
            a.plot(*zip(*pts), "o-", label=f"{name} (measured)")
        skipped = [r["N"] for r in rows if r["allpair_status"] == "skipped"]
        for n in skipped:
            a.axvline(n, color="tab:gray", ls=":", lw=1)
        a.plot([int(n) for n in text["fig9_allpair_s"]], [1e3 * v / 10 for v in text["fig9_allpair_s"].values()],
               "k^--", label="paper all-pair, run / 10 steps (published)")
        a.plot([int(n) for n in text["fig9_linkedlist_s"]],
               [1e3 * v / 10 for v in text["fig9_linkedlist_s"].values()], "kv--",
               label="paper linked list, run / 10 steps (published)")
        a.set_ylabel("one step (ms)")
        a.set_title("runtime" + (" (dotted: all-pair predicted past the budget, skipped)" if skipped else ""),
                    fontsize=8)
        pts = [(r["N"], r["eta"]) for r in rows if r["eta"]]
        if pts:
            b.plot(*zip(*pts), "o-", label="measured")
        b.plot([int(n) for n in text["fig9_allpair_s"]],
               [text["fig9_allpair_s"][n] / text["fig9_linkedlist_s"][n] for n in text["fig9_allpair_s"]],
               "k^--", label="paper (published)")
        b.set_ylabel("speedup eta = t_all-pair / t_linked-list")
        b.set_title("speedup (eq. 12)", fontsize=8)
    return path


def fig10(df, out: Path, pid: str):
    runs = T.paper_scene(df)
    if runs.empty:
        return None
    t4 = T.published()["table4"]["rows"]
    path = out / "fig10_runtime_vs_N.png"
    with figure(path, f"Fig. 10: runtime per step against N ({pid})", "particles N", "one step SNP+PI+SU (ms)",
                logx=True, logy=True) as (ax,):
        for (solver, precision, threads), g in runs.groupby(["solver", "precision", "threads"]):
            g = g.sort_values("n_particles").drop_duplicates("n_particles", keep="last")
            ax.plot(g.n_particles, 1e3 * g.t_step, "o-",
                    label=f"{solver} {precision}" + (f" x{threads}" if threads > 1 else ""))
        ax.plot([int(k) for k in t4], [sum(v[2:5]) for v in t4.values()], "k^--",
                label="paper, Tesla K20c (Table 4, published)")
    return path


def _stacked(ax, labels, shares, stages):
    bottom = np.zeros(len(labels))
    for s in stages:
        vals = np.array([sh[s] for sh in shares])
        ax.bar(range(len(labels)), vals, bottom=bottom, color=STAGE_COLOURS[s], label=s.upper())
        bottom += vals
    ax.set_xticks(range(len(labels)))
    ax.set_xticklabels(labels, rotation=60, ha="right", fontsize=6)
    ax.set_ylim(0, 100)


def _shares(path, title, ylabel, rows, published, stages):
    """Stacked bars: our rows (config, N), then the paper's ``(label, shares)`` pairs."""
    labels = [f"{r['config']}\nN={r['N']:,}" for r in rows] + [label for label, _ in published]
    shares = [dict(r) for r in rows] + [sh for _, sh in published]
    with figure(path, title, "", ylabel) as (ax,):
        _stacked(ax, labels, shares, stages)
    return path


def fig11(df, out: Path, pid: str):
    rows = T.table5(df)
    if not rows:
        return None
    text = T.published()["text"]["fig11_cpu_step_shares_pct"]
    paper = [("paper CPU\n(Fig. 11 text)", {"snp": text["snp"], "pi": text["pi"],
                                             "su": 100 - text["snp"] - text["pi"]})]
    paper += [(f"paper K20c\nN={int(n):,}", dict(zip(T.STEP_STAGES, v)))
              for n, v in sorted(T.published()["table5"]["rows"].items(), key=lambda kv: int(kv[0]))]
    return _shares(out / "fig11_step_shares.png", f"Figs. 11 / Table 5: share of a step ({pid})",
                   "% of one step (SNP+PI+SU)", rows, paper, T.STEP_STAGES)


def fig13(df, out: Path, pid: str):
    rows = T.one_step_shares(df)
    if not rows:
        return None
    paper = [(f"paper K20c\nN={int(n):,}", {s: 100 * x / sum(v) for s, x in zip(T.STAGES, v)})
             for n, v in sorted(T.published()["table4"]["rows"].items(), key=lambda kv: int(kv[0]))]
    return _shares(out / "fig13_task_shares.png", f"Fig. 13: share of a one-step run by task ({pid})",
                   "% of a one-step run", rows, paper, T.STAGES)


def fig14(df_all, out: Path, title: str):
    rows = T.table6(df_all)
    path = out / "fig14_speedup_vs_N.png"
    with figure(path, f"Fig. 14: GPU speedup over one serial CPU core, per step ({title})", "particles N",
                "speedup per step", logx=True, logy=True) as (ax,):
        pub = T.table6_published()
        for system in T.PAPER_SYSTEMS:
            pts = [(r["N"], r["speedup"]) for r in pub if r["system"] == system]
            card = next(r["card"] for r in pub if r["system"] == system)
            ax.plot(*zip(*pts), "k--", marker="^vs"[T.PAPER_SYSTEMS.index(system)],
                    label=f"{system}: {card} (published)")
        for (gp, cp, prec), _ in _groups(rows, ("gpu_profile", "cpu_profile", "precision")):
            pts = [(r["N"], r["speedup"]) for r in rows if (r["gpu_profile"], r["cpu_profile"], r["precision"])
                   == (gp, cp, prec)]
            ax.plot(*zip(*pts), "o-", label=f"{gp} {prec} vs CPU of {cp}")
    return path


def _groups(rows, keys):
    seen = {}
    for r in rows:
        seen.setdefault(tuple(r[k] for k in keys), []).append(r)
    return list(seen.items())


def speed_vs_accuracy(df, out: Path, pid: str):
    points, front = T.speed_front(df)
    if not points:
        return None
    path = out / "speed_vs_accuracy.png"
    with figure(path, f"Speed against accuracy at a fixed physical time ({pid})",
                "time to solution (s: init + steps, no JIT)", "relative RMS error of u",
                logx=True, logy=True) as (ax,):
        for (config, model, domain, t_final), pts in _groups(points, ("config", "model", "domain", "t_final")):
            ax.plot([p["seconds"] for p in pts], [p["mse"] for p in pts], "o",
                    label=f"{config} {model} {domain}, t = {t_final:g} s")
        for (t_final,), pts in _groups(front, ("t_final",)):
            ax.step([p["seconds"] for p in pts], [p["mse"] for p in pts], "k-", where="post", lw=1,
                    label=f"front of the linear runs (fastest to each error), t = {t_final:g} s")
    return path


def stability_map(df, out: Path, pid: str, inaccurate_above: float):
    points, limits = T.stability(df, inaccurate_above)
    if not points:
        return None
    configs = [lim["config"] for lim in limits]
    path = out / "stability_map.png"
    with figure(path, f"Stability map ({pid}): inaccurate = bounded but relative RMS > "
                f"{100 * inaccurate_above:g} %; numbers: the step where an unstable run stopped",
                "CFL = dt c0 / dx", "", logx=True, size=(9, 1.6 + 0.32 * len(configs))) as (ax,):
        for cls, (colour, marker) in CLASS_STYLE.items():
            pts = [p for p in points if p["class"] == cls]
            if pts:
                ax.scatter([p["cfl"] for p in pts], [configs.index(p["config"]) for p in pts], c=colour,
                           marker=marker, s=40, label=cls)
        for p in points:
            if p["class"] == "unstable" and p["failed_step"]:
                ax.annotate(f"{int(p['failed_step'])}", (p["cfl"], configs.index(p["config"])), fontsize=5,
                            xytext=(3, 3), textcoords="offset points")
        from matplotlib.ticker import NullFormatter

        cfls = sorted({p["cfl"] for p in points})
        ax.set_xticks(cfls)
        ax.set_xticklabels([f"{c:g}" for c in cfls], fontsize=7)
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_yticks(range(len(configs)))
        ax.set_yticklabels(configs, fontsize=7)
        ax.set_ylim(-0.6, len(configs) - 0.4)
    return path


def cards_figure(df_all, out: Path):
    rows, pub = T.cards(df_all), T.cards_published()
    path = out / "cards_step_vs_N.png"
    with figure(path, "GPU cards side by side: one lagrangian step (SNP+PI+SU) against N", "particles N",
                "one step (ms)", logx=True, logy=True) as (ax,):
        for (system, card, source), pts in _groups(pub, ("system", "card", "source")):
            ax.plot([p["N"] for p in pts], [p["step_ms"] for p in pts], "k--", marker="^",
                    alpha=0.35 if "Table 6" in source else 0.9, label=f"{card} ({source}, published)")
        for (profile, precision), pts in _groups(rows, ("profile", "precision")):
            ax.plot([p["N"] for p in pts], [p["step_ms"] for p in pts], "o-", label=f"{pts[0]['card']} {precision}")
    return path
