"""The paper study's page across machines: reports/cards.md (cards.py)."""

from __future__ import annotations

from pathlib import Path

from pcabench.reports.page import Page
from pcabench.studies.paper.cards import cards_page
from pcabench.studies.paper.rows import table6


def write(df, out: Path, shared: dict) -> list[Path]:
    """Table 6 as the reports computed it across machines (``shared["table6"]``: ``table6_of``), else from ``df``."""
    rows6 = shared.get("table6")
    return cards_page(df, out, rows6 if rows6 is not None else table6(df))


CARDS = Page("cards", write, "Table 6, Fig. 14 and the GPU cards side by side, every system", order=10)
