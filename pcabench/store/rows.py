"""Stored runs as rows (a DataFrame of the store, pcabench/reports/frame.py): the newest run of each configuration,
a run's method and whether it is the paper's, the error its model is scored by, and whether two runs' times
compare. What advise and every study's rows share."""

from __future__ import annotations

from functools import lru_cache

import pandas as pd

from solvers import Scene
from solvers.method import Method


def latest(df: pd.DataFrame) -> pd.DataFrame:
    """One row per configuration and machine, the newest: reruns and overlapping presets count once."""
    return df if df.empty else newest_per(df, ["profile_id", "solver", "threads", "pair_loop", "scene_key"])


def default_numerics(df: pd.DataFrame) -> pd.DataFrame:
    """The rows of ``df`` whose method is the paper's (:meth:`solvers.method.Method.is_paper`)."""
    return df[[Method.of(r).is_paper() for _, r in df.iterrows()]] if not df.empty else df


def newest_per(df, keys):
    """The newest row (by its timestamp) of each value of ``keys``."""
    return df.sort_values("timestamp").drop_duplicates(keys, keep="last")


def numerics_label(r) -> str:
    """The method of a run (:attr:`solvers.method.Method.label`): kernel, h/dx, cutoff (a truncated kernel's only),
    CFL, and the integrator and correction where not the defaults."""
    return Method.of(r).label


def is_paper_method(r) -> bool:
    """The paper's numerics (:meth:`solvers.method.Method.is_paper`)."""
    return Method.of(r).is_paper()


@lru_cache(maxsize=64)
def linear_floor(name: str, mach: float, t_final: float) -> float | None:
    """The exact linear solution's relative RMS distance from the isothermal one (no discretisation) for scene
    ``name`` at ``mach`` and ``t_final``, sampled on a 0.1 m lattice: the `linear` model's error floor against
    the isothermal physics, and the `lagrangian` model's against the linear pulse (the scene kind's
    ``linear_floor``; None where the scene has no isothermal reference)."""
    scene = Scene(dx=0.1, name=name, mach=mach, t_end=t_final, model="linear")
    return scene.kind.linear_floor(scene)


def error_column(model: str) -> str:
    """What "error" means for ``model``: against the linear pulse, or for lagrangian against the isothermal
    solution, the equations it solves (its error against the linear pulse never falls below their difference,
    :func:`linear_floor`)."""
    return "mse_isothermal" if model == "lagrangian" else "mse"


def comparable(a, b) -> bool:
    """Two runs whose times compare: the same kind of domain (on a strip each method has its own thinnest
    strip), the same threads, and the same code (commit): speed changes from commit to commit."""
    return a["domain"] == b["domain"] and int(a["threads"]) == int(b["threads"]) and a["commit"] == b["commit"]
