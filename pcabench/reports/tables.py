"""The numbers behind every table and figure, computed from the reports' DataFrame (``frame.load``).

Pure functions: a DataFrame in, lists of dicts out (one per table row), so the
values can be tested without drawing anything. Times are s in the store and
ms per step in the tables; errors are the paper's relative RMS ("MSE") of u.
Every row names its protocol (:func:`protocol`: run length, domain, pair loop,
threads), and rows of different protocols are never merged: a newest-run
choice is always made within one protocol. The paper's numbers come from
:mod:`.paper`, beside rows of the same kind only (device, search, serial, float64).
"""

from __future__ import annotations

from functools import lru_cache

import pandas as pd

from pcabench.store.record import STEP_STAGES
from solvers import Scene
from solvers.method import Method

# The scene's numerics unless a study varies them (Scene's defaults: Verlet, CFL, h/dx, cutoff).
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


def latest(df: pd.DataFrame) -> pd.DataFrame:
    """One row per configuration and machine, the newest: reruns and overlapping presets count once."""
    return df if df.empty else newest_per(df, ["profile_id", "solver", "threads", "pair_loop", "scene_key"])


def default_numerics(df: pd.DataFrame) -> pd.DataFrame:
    """The rows of ``df`` whose method is the paper's (:meth:`solvers.method.Method.is_paper`)."""
    return df[[Method.of(r).is_paper() for _, r in df.iterrows()]] if not df.empty else df


def paper_scene(df: pd.DataFrame) -> pd.DataFrame:
    """Finished runs of the paper's timing scene: lagrangian, full domain, default numerics."""
    d = default_numerics(df[(df.status == "ok") & (df.model == "lagrangian") & (df.domain == "full")])
    return latest(d)


def per_step_ms(r) -> dict:
    steps = max(int(r["steps"]), 1)
    return {s: 1e3 * r[f"t_{s}"] / steps for s in STEP_STAGES}


def newest_per(df, keys):
    return df.sort_values("timestamp").drop_duplicates(keys, keep="last")


# ---------------------------------------------------------------- Figs. 9 and 10
FIG9_LOOP_NAMES = {"gather": "the paper's gather loop", "list": "the pair list"}  # by ``linkedlist_loop``


# ---------------------------------------------------------------- speed against accuracy
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
