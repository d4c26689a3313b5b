"""What a reader checks on a figure, on matplotlib's objects: ``problems(fig)`` lists what is wrong.

- a legend over data (a drawn point or bar inside a legend's box);
- tick labels that overlap, or log ticks written as ``2x10^1``; a title, label or legend cut at the edge;
- a title or legend that names a channel (``colour: X``, ``marker: Y``, ``line: Z``, ``hollow: W``) the
  figure does not use (the channel takes one value among the measured series);
- two series in one legend (or one axes) drawn alike (same colour, marker, fill and line style);
- a published series (its label says "published" or starts with "paper") not drawn in the published
  style (grey, dashed or no line, hollow markers), or a published bar not hatched.

``record()`` hooks ``Figure.savefig``, so that every figure a report writes is checked as it is saved.
"""

from __future__ import annotations

import os
import re
from contextlib import contextmanager

import numpy as np
from matplotlib.colors import to_rgba
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from matplotlib.patches import Rectangle

CHANNEL = re.compile(r"\b(colou?r|marker|line|hollow)\s*:", re.I)
PUBLISHED = re.compile(r"\bpublished\b|^paper\b", re.I)


def _style(line: Line2D) -> tuple:
    marker = line.get_marker()
    marker = None if marker in ("", "None", " ", None) else str(marker)
    ls = line.get_linestyle()
    ls = None if ls in ("None", "", " ", "none") else ls
    hollow = marker is not None and str(line.get_markerfacecolor()) == "none"
    return (tuple(np.round(to_rgba(line.get_color()), 3)), marker, hollow, ls)


def _series(ax) -> list[Line2D]:
    return [ln for ln in ax.get_lines() if not ln.get_label().startswith("_") and len(ln.get_xdata())]


def _points(ax) -> np.ndarray:
    """Display coordinates of every drawn data point of ``ax`` (lines with their segments, scatter, bar
    corners) inside the axes."""
    pts = []
    for ln in ax.get_lines():
        if not len(ln.get_xdata()):
            continue
        xy = ax.transData.transform(np.column_stack([ln.get_xdata(), ln.get_ydata()]).astype(float))
        if ln.get_linestyle() not in ("None", "", " ", "none") and len(xy) > 1:  # the segments too
            t = np.linspace(0, 1, 25)[:, None, None]
            xy = (xy[:-1] + t * (xy[1:] - xy[:-1])).reshape(-1, 2)
        pts.append(xy)
    pts += [
        c.get_offset_transform().transform(c.get_offsets())
        for c in ax.collections
        if len(getattr(c, "get_offsets", lambda: [])())
    ]
    for p in ax.patches:
        if isinstance(p, Rectangle) and p.get_width() and p.get_height():
            pts.append(p.get_window_extent().get_points())
    if not pts:
        return np.zeros((0, 2))
    pts = np.vstack(pts)
    pts = pts[np.isfinite(pts).all(axis=1)]
    box = ax.get_window_extent()
    inside = (pts[:, 0] >= box.x0) & (pts[:, 0] <= box.x1) & (pts[:, 1] >= box.y0) & (pts[:, 1] <= box.y1)
    return pts[inside]


def _legends(fig):
    return [lg for lg in [*fig.legends, *(ax.get_legend() for ax in fig.axes)] if lg is not None]


def _overlap(a, b, pad=0.5) -> bool:
    return a.x0 + pad < b.x1 and b.x0 + pad < a.x1 and a.y0 + pad < b.y1 and b.y0 + pad < a.y1


def _tick_labels(axis):
    ticks = axis._update_ticks()  # the ticks drawn within the view (private, stable since matplotlib 3.1)
    return [t.label1 for t in ticks if t.label1.get_visible() and t.label1.get_text().strip()]


def problems(fig: Figure) -> list[str]:
    """What is wrong with ``fig`` (empty if nothing), one line each."""
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    out = []
    title = fig._suptitle.get_text() if fig._suptitle else ""
    texts = [title, *(ax.get_title() for ax in fig.axes)]
    for lg in _legends(fig):
        box = lg.get_window_extent(renderer)
        for ax in fig.axes:
            pts = _points(ax)
            if (
                len(pts)
                and ((pts[:, 0] > box.x0) & (pts[:, 0] < box.x1) & (pts[:, 1] > box.y0) & (pts[:, 1] < box.y1)).any()
            ):
                out.append(f"a legend lies over the data of '{ax.get_title() or title}'")
        labels = [t.get_text() for t in lg.get_texts()]
        texts += labels
        seen = {}
        for handle, label in zip(lg.legend_handles, labels):
            if isinstance(handle, Line2D):
                if PUBLISHED.search(label) and not _published_style(handle):
                    out.append(f"published series '{label}' is not drawn in the published style")
                key = _style(handle)
                if key in seen and seen[key] != label:
                    out.append(f"legend entries '{seen[key]}' and '{label}' are drawn alike")
                seen.setdefault(key, label)
    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            boxes = [(t.get_text(), t.get_window_extent(renderer)) for t in _tick_labels(axis)]
            out += [
                f"tick label '{t}' in 'a x 10^b' form on a log axis of '{ax.get_title() or title}'"
                for t, _ in boxes
                if re.search(r"\d\s*\\times\s*10\^", t)
            ]
            for i, (ta, a) in enumerate(boxes):
                for tb, b in boxes[i + 1 :]:
                    if _overlap(a, b):
                        out.append(f"tick labels '{ta}' and '{tb}' overlap in '{ax.get_title() or title}'")
        seen = {}
        for ln in _series(ax):
            key = _style(ln)
            if key in seen and seen[key] != ln.get_label():
                out.append(f"series '{seen[key]}' and '{ln.get_label()}' are drawn alike")
            seen.setdefault(key, ln.get_label())
            if PUBLISHED.search(ln.get_label()) and not _published_style(ln):
                out.append(f"published series '{ln.get_label()}' is not drawn in the published style")
        if PUBLISHED.search(ax.get_title()):
            if any(isinstance(p, Rectangle) and p.get_width() and not p.get_hatch() for p in ax.patches):
                out.append(f"the published bars of '{ax.get_title()}' are not hatched")
    canvas = fig.bbox
    for text in [
        fig._suptitle,
        *(t for ax in fig.axes for t in (ax.title, ax._left_title, ax.xaxis.label, ax.yaxis.label)),
        *_legends(fig),
    ]:
        if text is not None and text.get_visible() and (not hasattr(text, "get_text") or text.get_text()):
            box = text.get_window_extent(renderer)
            if box.x0 < canvas.x0 - 1 or box.x1 > canvas.x1 + 1 or box.y0 < canvas.y0 - 1 or box.y1 > canvas.y1 + 1:
                what = text.get_text() if hasattr(text, "get_text") else "a legend"
                out.append(f"'{what[:60]}' is cut at the figure's edge")
    out += _channels(fig, texts)
    return sorted(set(out))


def _published_style(line: Line2D) -> bool:
    r, g, b, _ = to_rgba(line.get_color())
    grey = max(r, g, b) - min(r, g, b) < 0.02
    marker = line.get_marker() not in ("", "None", " ", None)
    hollow = not marker or str(line.get_markerfacecolor()) == "none"
    return grey and hollow and line.get_linestyle() in ("--", "None", "none", "")


def _channels(fig, texts) -> list[str]:
    """A channel named in a title or legend must take more than one value among the data series."""
    lines = [ln for ax in fig.axes for ln in _series(ax) if not PUBLISHED.search(ln.get_label())]
    values = {
        "colour": {_style(ln)[0] for ln in lines},
        "marker": {_style(ln)[1] for ln in lines},
        "line": {_style(ln)[3] for ln in lines},
        "hollow": {_style(ln)[2] for ln in lines},
    }
    values["colour"] |= {
        tuple(np.round(c, 3)) for ax in fig.axes for coll in ax.collections for c in coll.get_facecolors()
    }
    out = []
    for text in texts:
        for m in CHANNEL.finditer(text or ""):
            name = m.group(1).lower().replace("color", "colour")
            if len(values[name]) < 2:
                out.append(f"'{text}' names channel {name}, which the figure does not vary")
    return out


@contextmanager
def record():
    """Check every figure saved inside the block: yields a dict, file name -> its problems."""
    found = {}
    original = Figure.savefig

    def savefig(self, fname, *args, **kwargs):
        found[os.fspath(fname)] = problems(self)
        return original(self, fname, *args, **kwargs)

    Figure.savefig = savefig
    try:
        yield found
    finally:
        Figure.savefig = original
