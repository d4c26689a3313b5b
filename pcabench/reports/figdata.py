"""A figure's data as a table: what a reader needs to replot it, read back from the drawn figure itself.

Every figure the report draws is saved with a CSV of the same name beside it (:func:`save_figure_data`), one
row per plotted point: the panel (its index and title, its axes' labels), the series (its legend label; the
lines and points without one, such as reference lines, keep matplotlib's name for them), what it is (``line``,
``points`` or ``bar``), and x, y (a bar's end on its value axis, its start in ``base``: a stacked bar's share is
the difference; a bar whose other axis holds names carries its name in ``category``; an image (a field on a
plane) one row per pixel, ``image``, its centre in x, y and its value in a last column, ``value``, which only a
figure with an image has). Taken from the Figure's artists after drawing, so the table is what the PNG shows,
whatever section drew it.
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pandas as pd

COLUMNS = ["panel", "panel_title", "xlabel", "ylabel", "series", "kind", "x", "y", "base", "category"]


def _numbers(values) -> np.ndarray:
    """``values`` as floats (dates and masked points as NaN)."""
    return np.ma.filled(np.ma.asarray(values, dtype=float), np.nan).ravel()


def _tick_names(ax, axis: str) -> dict:
    """{position: name} of an axis whose ticks are names (a bar chart's configurations), else {}."""
    ticks = ax.get_yticks() if axis == "y" else ax.get_xticks()
    labels = ax.get_yticklabels() if axis == "y" else ax.get_xticklabels()
    names = {float(t): lab.get_text() for t, lab in zip(ticks, labels) if lab.get_text()}
    numeric = all(n.replace(".", "", 1).replace("-", "", 1).replace("\u2212", "", 1).isdigit() for n in names.values())
    return {} if numeric else names


def figure_data(fig) -> pd.DataFrame:
    """One row per plotted point of ``fig`` (:data:`COLUMNS`)."""
    from matplotlib.collections import PathCollection
    from matplotlib.patches import Rectangle

    rows = []
    for i, ax in enumerate(fig.axes):
        if not ax.axison:  # a panel turned into a key: no data
            continue
        panel = {"panel": i, "panel_title": ax.get_title() or ax.get_title("left"), "xlabel": ax.get_xlabel()}
        panel["ylabel"] = ax.get_ylabel()
        for line in ax.lines:
            x, y = _numbers(line.get_xdata()), _numbers(line.get_ydata())
            kind = "points" if line.get_linestyle() in ("None", "none", "", " ") else "line"  # markers alone
            rows += [{**panel, "series": line.get_label(), "kind": kind, "x": a, "y": b} for a, b in zip(x, y)]
        for coll in ax.collections:
            if isinstance(coll, PathCollection) and len(coll.get_offsets()):
                xy = np.ma.filled(np.ma.asarray(coll.get_offsets(), dtype=float), np.nan)
                rows += [{**panel, "series": coll.get_label(), "kind": "points", "x": a, "y": b} for a, b in xy]
        names_y, names_x = _tick_names(ax, "y"), _tick_names(ax, "x")
        for container in ax.containers:
            label = container.get_label().lstrip("_")  # a series kept out of the legend is still named
            for patch in getattr(container, "patches", []):
                if not isinstance(patch, Rectangle):
                    continue
                x0, y0, w, h = patch.get_x(), patch.get_y(), patch.get_width(), patch.get_height()
                if container.orientation == "horizontal":  # barh: the value runs along x from its left
                    centre = y0 + h / 2
                    row = {"x": x0 + w, "y": centre, "base": x0, "category": names_y.get(round(centre, 9), "")}
                else:
                    centre = x0 + w / 2
                    row = {"x": centre, "y": y0 + h, "base": y0, "category": names_x.get(round(centre, 9), "")}
                rows.append({**panel, "series": label, "kind": "bar", **row})
        for image in ax.images:
            values = np.ma.filled(np.ma.asarray(image.get_array(), dtype=float), np.nan)
            x0, x1, y0, y1 = image.get_extent()
            ny, nx = values.shape[:2]
            xs = x0 + (np.arange(nx) + 0.5) * (x1 - x0) / nx
            ys = y0 + (np.arange(ny) + 0.5) * (y1 - y0) / ny
            if image.origin == "upper":
                ys = ys[::-1]
            title = panel["panel_title"]
            rows += [
                {**panel, "series": title, "kind": "image", "x": xs[i], "y": ys[j], "value": values[j, i]}
                for j in range(ny)
                for i in range(nx)
            ]
    images = any(r["kind"] == "image" for r in rows)
    return pd.DataFrame(rows, columns=COLUMNS + (["value"] if images else []))


def save_figure_data(fig, path) -> Path:
    """The data of ``fig`` (saved at ``path``, a PNG) as the CSV beside it, written whole or not at all."""
    from pcabench.store.safeio import write_file

    buffer = io.StringIO()
    figure_data(fig).to_csv(buffer, index=False, float_format="%.6g")
    return write_file(Path(path).with_suffix(".csv"), buffer.getvalue())
