"""Markdown helpers of the reports: a table, and numbers written for a reader ('-' for none)."""
from __future__ import annotations

import numpy as np


def md_table(header, rows) -> str:
    out = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    out += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(out)


def fmt(x, spec=".3g") -> str:
    if x is None or (isinstance(x, float) and not np.isfinite(x)):
        return "-"
    return format(x, spec)


def pct(x) -> str:
    return fmt(None if x is None else 100 * x, ".2f") + (" %" if x is not None and np.isfinite(x) else "")


def first_words(message: str, limit: int = 200) -> str:
    """The message's first line, cut at a word boundary with an ellipsis if longer than ``limit``."""
    line = message.splitlines()[0] if message else ""
    return line if len(line) <= limit else line[:limit].rsplit(" ", 1)[0] + " ..."
