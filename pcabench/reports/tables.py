"""What the studies' tables say of a run, from the reports' DataFrame (``frame.load``): what ran, how it was
timed, the paper's timing scene.

Every row of a table names its protocol (:func:`protocol`: run length, domain, pair loop, threads), and rows
of different protocols are never merged: a newest-run choice is always made within one protocol. Times are s
in the store and ms per step in the tables. Each study's rows are in its folder (pcabench/studies/<study>/);
what every stored run's row answers (the newest of each, its method, its error) is pcabench/store/rows.py.
"""

from __future__ import annotations

import pandas as pd

from pcabench.store.record import STEP_STAGES
from pcabench.store.rows import default_numerics, latest

# What makes two runs the same measurement: a newest-run choice is made within one of these.
PROTOCOL = ["protocol", "domain", "loop", "threads"]


def label(r) -> str:
    """``solver precision``: what ran (its protocol is :func:`protocol`)."""
    return f"{r['solver']} {r['precision']}"


def where(threads, device: str) -> str:
    """What ran the pairs: ``GPU``, or the CPU threads (``1 thread``, ``2 threads``)."""
    threads = int(threads)
    return "GPU" if device == "gpu" else f"{threads} thread{'s' if threads > 1 else ''}"


def protocol(r) -> str:
    """How a run was timed: its length (steps or t), domain, pair loop and CPU threads (or GPU), e.g.
    ``20 steps, full, gather, 1 thread``."""
    return f"{r['protocol']}, {r['domain']}, {r['loop']}, {where(r['threads'], r['device'])}"


def paper_scene(df: pd.DataFrame) -> pd.DataFrame:
    """Finished runs of the paper's timing scene: lagrangian, full domain, default numerics."""
    d = default_numerics(df[(df.status == "ok") & (df.model == "lagrangian") & (df.domain == "full")])
    return latest(d)


def per_step_ms(r) -> dict:
    steps = max(int(r["steps"]), 1)
    return {s: 1e3 * r[f"t_{s}"] / steps for s in STEP_STAGES}
