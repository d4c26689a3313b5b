"""What a page is, and the page registry.

A :class:`Page` is a report page written once across every machine (beside the per-machine reports), an object
in a study's ``page.py`` (``pcabench/studies/<study>/page.py``, found by the registry :data:`PAGES`; a plug-in
through the entry-point group ``pcabench.pages``): ``write(df, out, shared)`` writes it from every machine's runs
of the paper's scene (``df``) into the reports folder ``out`` with the rows the reports computed once across
machines (``shared``), returning the paths written (the page first); ``index`` is its line in reports/README.md.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import pandas as pd

from solvers.plugins import Registry

ENTRY_POINT_GROUP = "pcabench.pages"


@dataclass(frozen=True)
class Page:
    """One page across machines: ``write(df, out, shared)`` -> [page, figures...]; ``index``: its index line."""

    name: str
    write: Callable[[pd.DataFrame, Path, dict], list[Path]]
    index: str
    order: float = 1000.0


def _problem(page: Page) -> str | None:
    return None if callable(page.write) else "a page needs a callable write"


PAGES = Registry(
    "page",
    "pcabench.studies",  # each study's page.py
    Page,
    group=ENTRY_POINT_GROUP,
    order=lambda p: (p.order, p.name),
    problem=_problem,
    role="page",
)


def in_order() -> list[Page]:
    """Every registered page, in index order."""
    return sorted(PAGES.all().values(), key=lambda p: (p.order, p.name))
