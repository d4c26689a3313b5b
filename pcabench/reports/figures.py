"""The figure toolkit: what every study's figures (pcabench/studies/<study>/figures.py) are drawn with, each
figure from the rows of its section, never from the store.

A study's figure function draws one figure into ``out`` and returns its path,
or None when the rows hold nothing for it. One variable per visual channel, and a title
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

from pcabench.reports.figdata import save_figure_data
from pcabench.store.safeio import save_figure

PRECISION_MARKER = {"float64": "o", "float32": "s"}
MODEL_COLOUR = {"linear": "tab:blue", "lagrangian": "tab:red", "fixed": "tab:green"}
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

    ``legend``: "right" puts one legend of every labelled series outside the axes, "bottom" the same under them
    all (two columns: the axes keep the figure's width), "below" one legend under each axes (for panels whose
    series share styles), "none" draws none.
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
    if handles and legend in ("right", "bottom"):
        labels = sorted(handles, key=lambda lab: "(published)" in lab)  # measured first, the paper's after
        where = {"loc": "outside right center"} if legend == "right" else {"loc": "outside lower center", "ncol": 2}
        fig.legend([handles[lab] for lab in labels], labels, **where, fontsize=7, frameon=False, handlelength=3)
    suptitle(fig, title)
    save_figure(fig, path, dpi=110)  # whole or not at all; a link at its name is replaced, not followed
    save_figure_data(fig, path)  # its data beside it, as a CSV a reader replots
    plt.close(fig)


def suptitle(fig, title: str) -> None:
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


FIG10_SIZES = 2  # a panel is drawn where one of its series has this many sizes: a line against N, not a dot


def groups(rows, keys):
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
