"""The closing table of ``pcabench study`` (the README's first command ends in it): the paper's step times where
the study has its timing runs, else each run (pcabench/reports/closing.py)."""

from __future__ import annotations

from pathlib import Path

from pcabench.reports import frame
from pcabench.reports.closing import run_table
from pcabench.reports.md import fmt, md_table
from pcabench.studies.paper.rows import table4
from solvers import DEFAULT_SCENE


def summary(results_dir: Path, profile: str, run_ids=None) -> str:
    """A study's closing table for the terminal, of its own runs (``run_ids``; None: every run of this machine):
    where it has the paper's timing runs (its scene, a fixed step count), their step times (Table 4's SNP / PI /
    SU columns) and a line counting the rest; else each run, its method, status, error and step time."""
    df = frame.load(results_dir)
    if not df.empty:
        df = df[df.profile_id == profile]
        if run_ids is not None:
            df = df[df.run_id.isin(set(run_ids))]
    if df.empty:
        return ""
    timing = (df.scene == DEFAULT_SCENE) & df.protocol.str.endswith(" steps")
    rows = table4(df[timing]) if timing.any() else []
    if not rows:
        return run_table(df)
    rest = int((~timing).sum())
    more = f"\n... and {rest} more runs (accuracy, other scenes): the report's tables, `pcabench runs`" if rest else ""
    heading = "Step times on this machine, ms per step (the paper's scene; the report has every table):\n"
    return heading + step_table(rows) + more


def step_table(rows) -> str:
    """Table 4's step-time columns (ms) of ``rows``."""
    return md_table(
        ["config", "protocol", "N", "SNP", "PI", "SU", "step"],
        [
            [
                r["config"],
                r["protocol"],
                f"{r['N']:,}",
                fmt(r["snp"], ".3f"),
                fmt(r["pi"], ".3f"),
                fmt(r["su"], ".3f"),
                fmt(r["snp"] + r["pi"] + r["su"], ".3f"),
            ]
            for r in rows
        ],
    )
