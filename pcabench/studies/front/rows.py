"""The front study's rows: each run's time to solution against its error, the fronts of the fastest methods, the
predictions beside them, and the fastest method to each error."""

from __future__ import annotations

import numpy as np

from pcabench.reports.tables import label
from pcabench.store.rows import comparable, error_column, is_paper_method, latest, numerics_label
from pcabench.studies.preset import unscored
from solvers import DEFAULT_KERNEL, Scene
from solvers.corrections import DEFAULT_CORRECTION
from solvers.method import Method

FRONT_MODELS = ("linear", "lagrangian")  # fixed solves neither equation: it is in the simplifications' table


def speed_front(df) -> tuple[list[dict], list[dict]]:
    """Error against time to solution at a fixed physical time: every finished run, and each model's front.

    Time to solution is init + SNP + PI + SU (s), without JIT, input and output.
    Every method counts (kernel, h/dx, cutoff, CFL, dx, precision). A run's
    ``error`` is against what its model converges to: the linear pulse for
    `linear`, the isothermal solution for `lagrangian` (its error against the
    linear pulse never falls below the two equations' difference, :func:`pcabench.store.rows.linear_floor`; rows
    from before that was measured are left out). The front of a model at a
    time holds the runs no faster run of that model beats in error, among the runs below their method's
    predicted stable CFL (``past_limit``: at or past it, a run is unstable by prediction whatever its error,
    pcabench/predict/stability.py; it is drawn and listed as such, never on the front).
    """
    from pcabench.predict.stability import assess

    accuracy_runs = ~df.preset.isin(unscored())  # not the runs that measure a stable step (pcabench.studies.preset)
    pts = latest(
        df[(df.status == "ok") & df.protocol.str.startswith("t =") & df.model.isin(FRONT_MODELS) & accuracy_runs]
    )
    points = []
    for _, r in pts.iterrows():
        error = r[error_column(r.model)]
        if error is None or not np.isfinite(error):
            continue
        points.append(
            {
                "config": label(r),
                "method": numerics_label(r),
                "paper_method": is_paper_method(r),
                "kernel": r["kernel"],
                "h_factor": r.h_factor,
                "cfl": r.cfl,
                "integrator": r.integrator,
                "correction": r.get("correction") or DEFAULT_CORRECTION,
                "cutoff_factor": r.cutoff_factor,
                "precision": r.precision,
                "model": r.model,
                "domain": r.domain,
                "dx": r.dx,
                "N": int(r.n_particles),
                "t_final": r.t_final,
                "seconds": r.t_solution,
                "error": float(error),
                "mse": r.mse,
                "strip_height": r.strip_height,
                "solver": r.solver,
                "threads": int(r.threads),
                "commit": str(r.commit),
                "steps": int(r.steps),
                **assess(r),
            }
        )
    return points, fronts([p for p in points if not p["past_limit"]])


def fronts(points) -> list[dict]:
    """Each (time, model)'s front of ``points``: the runs no faster run beats in error."""
    front = []
    for t_final, model in sorted({(p["t_final"], p["model"]) for p in points}):
        best = np.inf
        for p in sorted(
            (p for p in points if p["t_final"] == t_final and p["model"] == model),
            key=lambda p: (p["seconds"], p["error"]),
        ):
            if p["error"] < best:
                best = p["error"]
                front.append(p)
    return front


def unstable_on_front(points) -> list[dict]:
    """The runs past their predicted stable CFL that a front of every run, stable or not, would hold: what
    ignoring the prediction would have picked. Each with ``e_foldings``: its most unstable mode's growth."""
    from pcabench.predict.stability import e_foldings

    return [{**p, "e_foldings": e_foldings(p, p["steps"])} for p in fronts(points) if p["past_limit"]]


def predicted_error(p: dict) -> float:
    """The error the dispersion relation predicts for front point ``p`` (its linear part;
    solvers/reference/dispersion.py)."""
    from solvers.reference.dispersion import predict

    scene = Method.of(p).scene_fields()
    strip = p.get("strip_height")
    strip = None if strip is None or (isinstance(strip, float) and np.isnan(strip)) else strip
    return predict(Scene(dx=p["dx"], t_end=p["t_final"], model="linear", strip_height=strip, **scene)).predicted_error


def predicted_by_model(df, dxs=(0.4, 0.2, 0.1)) -> list[dict]:
    """Measured against predicted error for every model: the paper's method on the strip at t = 10 s."""
    d = latest(paper_method_rows(df[(df.status == "ok") & (df.domain == "strip") & (df.protocol == "t = 10 s")]))
    rows = []
    for model in ("linear", "fixed", "lagrangian"):
        for dx in dxs:
            r = d[(d.model == model) & np.isclose(d.dx.astype(float), dx) & (d.precision == "float64")]
            if r.empty:
                continue
            r = r.sort_values("timestamp").iloc[-1]
            p = {
                "kernel": DEFAULT_KERNEL,
                "h_factor": r.h_factor,
                "cfl": r.cfl,
                "integrator": r.integrator,
                "cutoff_factor": r.cutoff_factor,
                "dx": dx,
                "t_final": r.t_final,
                "strip_height": r.strip_height,
            }
            rows.append(
                {
                    "model": model,
                    "dx": dx,
                    "measured": r.mse,
                    "predicted": predicted_error(p),
                    "isothermal": r.mse_isothermal if model == "lagrangian" else None,
                }
            )
    return rows


def paper_method_rows(df):
    """The rows of the paper's numerics (``is_paper_method``)."""
    return df[[is_paper_method(r) for _, r in df.iterrows()]] if not df.empty else df


def fastest_to(points, targets=(0.10, 0.05, 0.02, 0.01, 0.005)) -> list[dict]:
    """For each time, model and error target: the fastest run reaching it, the fastest run of the paper's
    method reaching it, and how many times faster the first is. Runs past their predicted stable CFL
    (``past_limit``) are never picked."""
    rows = []
    for t_final, model in sorted({(p["t_final"], p["model"]) for p in points}):
        pts = sorted(
            (p for p in points if p["t_final"] == t_final and p["model"] == model and not p.get("past_limit")),
            key=lambda p: p["seconds"],
        )
        for target in targets:
            hit = next((p for p in pts if p["error"] <= target), None)
            paper = hit and next(
                (p for p in pts if p["error"] <= target and p["paper_method"] and comparable(p, hit)), None
            )
            rows.append(
                {
                    "t_final": t_final,
                    "model": model,
                    "target": target,
                    "best": hit,
                    "paper": paper,
                    "speedup": paper["seconds"] / hit["seconds"] if hit and paper else None,
                }
            )
    return rows
