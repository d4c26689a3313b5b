"""Stored runs as tables (pandas): list and filter them, and compare two machines or two commits.

    pcabench runs --solver linkedlist-cpu --status ok
    pcabench runs --compare amd-epyc h100-80gb-hbm3__intel-xeon      # two machines
    pcabench runs --compare 0ff5d9e 92b452f                          # two commits
"""
from __future__ import annotations

import pandas as pd

COLUMNS = ["machine", "commit", "solver", "threads", "pair_loop", "precision", "model", "integrator", "domain",
           "protocol", "dx", "n_particles", "steps", "status", "step_ms", "mse", "timestamp"]
CONFIG = ["solver", "threads", "pair_loop", "scene_key"]  # the same run on two machines or commits


def table(df: pd.DataFrame, **filters) -> pd.DataFrame:
    """The runs of ``df`` (from ``store.load``) as a readable table, filtered by column prefix matches."""
    if df.empty:
        return pd.DataFrame(columns=COLUMNS)
    out = df.assign(step_ms=1e3 * df.t_step, commit=df.commit.astype(str).str[:7])
    for column, value in filters.items():
        if value:
            out = out[out[column].astype(str).str.startswith(str(value))]
    return out.sort_values(["machine", "timestamp"])[COLUMNS]


def side(df: pd.DataFrame, key: str) -> tuple[str, pd.DataFrame]:
    """The runs ``key`` names: a machine (exact) or else a commit (prefix); ('', empty) if neither."""
    if key in set(df.machine):
        return "machine", df[df.machine == key]
    hit = df[df.commit.astype(str).str.startswith(key)]
    return ("commit", hit) if not hit.empty else ("", hit)


def compare(df: pd.DataFrame, a: str, b: str) -> pd.DataFrame:
    """The configurations both ``a`` and ``b`` ran (ok, newest of each): step times, their ratio, errors."""
    ok = df[df.status == "ok"]
    kind_a, ra = side(ok, a)
    kind_b, rb = side(ok, b)
    for key, kind in ((a, kind_a), (b, kind_b)):
        if not kind:
            raise KeyError(f"--compare: {key!r} is neither a machine nor a commit of a finished run in the store")
    newest = [c for c in CONFIG if c in ok]
    ra = ra.sort_values("timestamp").drop_duplicates(newest, keep="last")
    rb = rb.sort_values("timestamp").drop_duplicates(newest, keep="last")
    both = ra.merge(rb, on=newest, suffixes=("_a", "_b"))
    out = pd.DataFrame({"solver": both.solver, "threads": both.threads, "pair_loop": both.pair_loop,
                        "precision": both.precision_a, "model": both.model_a, "domain": both.domain_a,
                        "protocol": both.protocol_a, "N": both.n_particles_a,
                        f"step_ms {a}": 1e3 * both.t_step_a, f"step_ms {b}": 1e3 * both.t_step_b,
                        "b / a": both.t_step_b / both.t_step_a,
                        f"mse {a}": both.mse_a, f"mse {b}": both.mse_b, "mse b - a": both.mse_b - both.mse_a})
    return out.sort_values(["solver", "threads", "precision", "model", "N"]).reset_index(drop=True)
