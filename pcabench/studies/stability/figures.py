"""The stability study's figure: the stability map (CFL against each method, each run classed)."""

from __future__ import annotations

from pathlib import Path

from matplotlib.ticker import FixedLocator, NullLocator

from pcabench.predict.stability import UNSTABLE_BY_PREDICTION
from pcabench.reports.figures import (
    figure,
)

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


def stability_map(points, limits, out: Path, pid: str, inaccurate_above: float):
    """Each method's runs by CFL, in the classes of the section's table (``stability/rows.py``'s ``stability``), and the
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
