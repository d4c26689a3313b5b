"""Markdown helpers of the reports: a table, text from a store made inert, and numbers written for a reader
('-' for none)."""

from __future__ import annotations

import html
import re

import numpy as np

_ACTIVE = re.compile(r"([\\`*_\[\]!~|])")  # what Markdown reads as syntax here: emphasis, links, images, code


def md_cell(value) -> str:
    """``value`` as one table cell: a ``|`` cannot open another cell, a line break cannot end the row."""
    text = re.sub(r"\s*[\r\n]+\s*", " ", str(value))
    return re.sub(r"(?<!\\)\|", r"\\|", text)


def md_text(value) -> str:
    """Text a report did not write (a stored message: a solver's, a plug-in's) shown as itself: HTML escaped
    (no tag, no remote image stays live), Markdown's syntax characters backslashed, one line."""
    text = html.escape(re.sub(r"\s*[\r\n]+\s*", " ", str(value)), quote=False)
    return _ACTIVE.sub(r"\\\1", text)


def md_table(header, rows) -> str:
    out = ["| " + " | ".join(md_cell(h) for h in header) + " |", "|" + "---|" * len(header)]
    out += ["| " + " | ".join(md_cell(c) for c in row) + " |" for row in rows]
    return "\n".join(out)


def fmt(x, spec=".3g") -> str:
    if x is None or (isinstance(x, float) and not np.isfinite(x)):
        return "-"
    return format(x, spec)


def pct(x) -> str:
    return fmt(None if x is None else 100 * x, ".2f") + (" %" if x is not None and np.isfinite(x) else "")


def first_words(message: str, limit: int = 200) -> str:
    """The message's first line, cut at a word boundary with an ellipsis if longer than ``limit``, as inert
    text (:func:`md_text`)."""
    line = message.splitlines()[0] if message else ""
    return md_text(line if len(line) <= limit else line[:limit].rsplit(" ", 1)[0] + " ...")
