"""What a report section is, and the section registry.

A :class:`Section` is an object in a study's ``section.py`` (``pcabench/studies/<study>/section.py``, found by
the registry :data:`SECTIONS`; a plug-in through the entry-point group ``pcabench.sections``): ``rows(ctx)`` computes
its numbers once per report, ``text(rows, ctx)`` writes its Markdown from them, and ``figures`` draw its PNGs
(with the toolkit ``figures.py``) from the same rows; ``order`` places it in the report. Rows shared by several
sections (Table 4 for Table 5 and Fig. 13; Table 6 across every machine and the cards page: the paper study's
``table4_of``, ``table6_of``) are computed once through :meth:`Context.once`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np
import pandas as pd

from pcabench.reports.md import fmt
from solvers.plugins import Registry

ENTRY_POINT_GROUP = "pcabench.sections"


@dataclass
class Context:
    """One machine's report: its runs (``df``), every machine's (``df_all``), its name and folder, and the
    rows computed once per report or once per set of reports (``shared``)."""

    df: pd.DataFrame
    df_all: pd.DataFrame
    name: str
    out: Path
    shared: dict = field(default_factory=dict)
    cache: dict = field(default_factory=dict)
    df_scenes: pd.DataFrame | None = None  # every scene's runs of this machine (``df`` holds the paper's scene's)
    # the open-edges study's runs too (``pcabench study --open``: open edges, their closed contrasts and cost
    # baselines), which only the "Open edges" section reads: the other sections' scenes are the closed ones
    df_open: pd.DataFrame | None = None
    # the runs of the presets the section being written declares (``Section.reads``), handed to it by the report
    runs: pd.DataFrame | None = None

    def runs_of(self, presets: tuple, all_scenes: bool = True) -> pd.DataFrame | None:
        """This machine's runs of ``presets`` (names; one ending in ``*`` names every preset it begins:
        ``walls-cost-*``, a study's rounds): of every scene (:meth:`every_run`), or with ``all_scenes`` False of
        the paper's scene (``df``), as the section reads; None where there are no runs."""
        df = self.every_run() if all_scenes else self.df
        if df is None or df.empty or "preset" not in df:
            return None
        names = {p for p in presets if not p.endswith("*")}
        stems = tuple(p[:-1] for p in presets if p.endswith("*"))
        tags = df.preset.astype(str)
        return df[tags.isin(names) | (tags.str.startswith(stems) if stems else False)]

    def every_run(self):
        """This machine's runs with the open-edges study's (open edges, the cylinder's), for the sections that read
        them: ``df_open``, else every scene's, else the paper scene's."""
        for df in (self.df_open, self.df_scenes, self.df):
            if df is not None:
                return df
        return None

    @property
    def pid(self) -> str:
        df = self.df_scenes if self.df_scenes is not None else self.df
        return str(df.profile_id.iloc[0])

    def once(self, key: str, compute: Callable[[], Any], across_machines: bool = False):
        """``compute()`` the first time ``key`` is asked for in this report (or in every report)."""
        cache = self.shared if across_machines else self.cache
        if key not in cache:
            cache[key] = compute()
        return cache[key]


@dataclass(frozen=True)
class Section:
    """A part of the report: ``rows(ctx)``, ``text(rows, ctx)`` (Markdown lines, [] when the rows hold
    nothing) and ``figures`` (each ``figure(rows, ctx)`` -> a PNG path or None)."""

    name: str
    rows: Callable[[Context], Any]
    text: Callable[[Any, Context], list[str]]
    figures: tuple[Callable[[Any, Context], Path | None], ...] = ()
    all_scenes: bool = False  # reads ``ctx.df_scenes``; the others read the paper's scene only
    # the rows only this section reads (a mask of the report's frame), kept out of every other section's frames
    apart: Callable[[pd.DataFrame], Any] | None = None
    order: float = 1000.0  # its place in the report (the built-ins' are 10, 20, ...; the default: last)
    # the presets whose runs it reads (``ctx.runs``, handed to it by the report: no section slices the store by
    # preset itself); () reads the frames of the context as they are
    reads: tuple = ()


def _problem(section: Section) -> str | None:
    if not (callable(section.rows) and callable(section.text) and all(map(callable, section.figures))):
        return "a section needs callable rows, text and figures"
    if section.apart is not None and not callable(section.apart):
        return "a section's apart must be callable"
    return None


SECTIONS = Registry(
    "section",
    "pcabench.studies",  # each study's section.py
    Section,
    group=ENTRY_POINT_GROUP,
    order=lambda s: (s.order, s.name),
    problem=_problem,
    role="section",
)


def in_order() -> list[Section]:
    """Every registered section, in report order (read at each report: one registered since is in it)."""
    return sorted(SECTIONS.all().values(), key=lambda s: (s.order, s.name))


def stored_measure(r, name: str) -> float | None:
    """A scene's stored error measure ``name`` of a report row (``err_<name>``), None where not a finite number."""
    v = r.get(f"err_{name}")
    return None if v is None or not np.isfinite(v) else float(v)


def limit_words(stable_cfl: float) -> str:
    return f"{stable_cfl:.3g}" if stable_cfl > 0 else "none (grows at every CFL)"


OUTCOME_COLUMNS = ["bounded up to CFL", "blew up at CFL", "e-foldings"]  # the header of :func:`outcome_cells`


def outcome_cells(r) -> list[str]:
    """A long-run row's outcome in a table's cells: bounded to (the largest CFL that stayed bounded), blew up at
    (each CFL, with its step), the e-foldings of the growth."""
    blew = "; ".join(f"{c:g}" + (f" (step {st})" if st else "") for c, st in r["blew_up_at"]) or "none"
    return [
        fmt(r["bounded_to"], "g") if r["bounded_to"] is not None else "none",
        blew,
        fmt(r["e_foldings"], ".2g") if r["e_foldings"] is not None else "-",
    ]
