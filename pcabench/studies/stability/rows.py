"""The stability study's rows: each run classed against its predicted stable CFL (the map), and each method's
limit as long runs measured it."""

from __future__ import annotations

import numpy as np

from pcabench.store.rows import latest
from solvers import DEFAULT_KERNEL, Scene
from solvers.kernels import truncated


# ---------------------------------------------------------------- stability
def _step_or_none(x):
    return None if x is None or not np.isfinite(x) else int(x)


def classify(r, inaccurate_above: float, past_limit: bool = False) -> str:
    """stable (below its predicted stable CFL, bounded, accurate) / inaccurate (the same, error above the bar) /
    unstable (it blew up) / unstable by prediction (at or past the predicted limit, ended bounded: too few
    steps for round-off to grow), or the failed run's status."""
    from pcabench.predict.stability import UNSTABLE_BY_PREDICTION

    if r["status"] == "ok":
        if past_limit:
            return UNSTABLE_BY_PREDICTION
        return "stable" if r["mse"] <= inaccurate_above else "inaccurate"
    return r["status"]


def cfl_ranges(cfls, swept) -> str:
    """``cfls`` (a subset of the sorted ``swept``) as runs of neighbours in ``swept``: "0.1-4.5, 6"."""
    swept = sorted(swept)
    chosen = sorted(set(cfls))
    parts, start, prev = [], None, None
    for c in chosen:
        if start is not None and swept.index(c) == swept.index(prev) + 1:
            prev = c
            continue
        if start is not None:
            parts.append(f"{start:g}" if start == prev else f"{start:g}-{prev:g}")
        start = prev = c
    if start is not None:
        parts.append(f"{start:g}" if start == prev else f"{start:g}-{prev:g}")
    return ", ".join(parts)


def stability(df, inaccurate_above: float) -> tuple[list[dict], list[dict]]:
    """The stability map's points and one summary per configuration, both from the same classes.

    Built from the prediction (pcabench/predict/stability.py): a run at or past its
    method's predicted stable CFL is unstable, by its blow-up or, where it
    ended bounded, by prediction (``e_foldings``: how far its most unstable
    mode grew in its steps, too little for round-off to show). ``df``: the runs of the
    stability preset and of the quick study (the section's ``reads``), of which a quick study's CFL sweep
    (three CFLs or more of one method) counts.
    """
    from pcabench.predict.stability import UNSTABLE_BY_PREDICTION, assess, e_foldings

    if df is None or df.empty:
        return [], []
    runs = latest(df[df.protocol.str.startswith("t =") & (df.model == "linear") & (df.domain == "strip")])
    keys = ["integrator", "kernel", "h_factor", "cutoff_factor", "precision", "protocol", "dx"]
    if not runs.empty:
        sweeps = runs.groupby(keys + ["preset"]).cfl.transform("nunique")
        runs = runs[(runs.preset == "stability") | (sweeps >= 3)]
    points, limits = [], []
    for (integ, kern, h, cut, precision, protocol, dx), g in runs.groupby(keys):
        g = g.sort_values("cfl")
        method = f"{integ}, h = {h:g} dx" + (f", {kern}" if kern != DEFAULT_KERNEL else "")
        if truncated(kern) and not np.isclose(cut, Scene.default("cutoff_factor")):
            method += f", {cut:g}h"
        name = f"{method}, {precision}, {protocol}"
        mine = []
        for _, r in g.iterrows():
            a = assess(r)
            cls = classify(r, inaccurate_above, a["past_limit"])
            steps = r.steps if r.status == "ok" else r.steps_requested
            mine.append(
                {
                    "config": name,
                    "cfl": float(r.cfl),
                    "class": cls,
                    "mse": r.mse,
                    "failed_step": _step_or_none(r.failed_step),
                    "steps": _step_or_none(steps),
                    "stable_cfl": a["stable_cfl"],
                    "past_limit": a["past_limit"],
                    "limit_from": a["limit_from"],
                    "predicted": a["predicted"],
                    "e_foldings": e_foldings(r, int(r.steps)) if cls == UNSTABLE_BY_PREDICTION else None,
                }
            )
        points += mine
        limits.append(
            {
                "config": name,
                "integrator": integ,
                "kernel": kern,
                "h_factor": h,
                "precision": precision,
                "protocol": protocol,
                "dx": dx,
                "cfls": [p["cfl"] for p in mine],
                "stable_cfl": mine[0]["stable_cfl"],
                "limit_from": mine[0]["limit_from"],
                "predicted": mine[0]["predicted"],
                "accurate_at": [p["cfl"] for p in mine if p["class"] == "stable"],
                "inaccurate_at": [(p["cfl"], p["mse"]) for p in mine if p["class"] == "inaccurate"],
                "blew_up_at": [(p["cfl"], p["failed_step"]) for p in mine if p["class"] == "unstable"],
                "bounded_past_limit": [
                    (p["cfl"], p["steps"], p["e_foldings"]) for p in mine if p["class"] == UNSTABLE_BY_PREDICTION
                ],
                "blew_up_below_limit": [p["cfl"] for p in mine if p["class"] == "unstable" and not p["past_limit"]],
                "other": [
                    (p["cfl"], p["class"])
                    for p in mine
                    if p["class"] not in ("stable", "inaccurate", "unstable", UNSTABLE_BY_PREDICTION)
                ],
            }
        )
    return points, limits
