"""Each method's stable CFL as long runs measured it (a toolkit of the report: the stability study's long runs,
the walls' and the open edges' read it the same way)."""

from __future__ import annotations

import numpy as np

from pcabench.store.rows import latest


def _step_or_none(x):
    return None if x is None or not np.isfinite(x) else int(x)


def _fold(x: float) -> float:
    """e-foldings with the round-off of the step matrix's spectral radius (~1e-13 over a run) as 0."""
    return 0.0 if x < 1e-9 else x


def long_run_limits(df, preset: str = "stability-long") -> list[dict]:
    """Each model's stable CFL measured by the long runs of ``preset`` (``pcabench study --stability long``; the
    walls preset's at the wall) beside the prediction of its linear part and the limit pcabench/predict/stability.py
    holds for it (what advise uses).

    Per model and method: the CFLs run, the largest that ended bounded below the first blow-up, the smallest
    that blew up (and its step), the steps run, and the e-foldings of the most unstable linear mode over the
    run at the largest bounded CFL (0 below the predicted limit).
    """
    from pcabench.predict.stability import assess, e_foldings, measured_limit

    runs = latest(df[df.preset == preset]) if "preset" in df else df.iloc[:0]
    keys = [
        "scene",
        "mach",
        "model",
        "kernel",
        "h_factor",
        "cutoff_factor",
        "integrator",
        "correction",
        "precision",
        "dx",
        "protocol",
    ]
    out = []
    for key, g in runs.groupby(keys, sort=False):
        row = dict(zip(keys, key))
        g = g.sort_values("cfl")
        blew = [(float(r.cfl), _step_or_none(r.failed_step)) for _, r in g.iterrows() if r.status == "unstable"]
        first_blow = blew[0][0] if blew else None
        bounded = [
            float(r.cfl) for _, r in g.iterrows() if r.status == "ok" and (first_blow is None or r.cfl < first_blow)
        ]
        top = g[g.cfl == max(bounded)].iloc[0] if bounded else None
        held = measured_limit(row)
        row.update(
            cfls=[float(c) for c in g.cfl],
            predicted=assess({**row, "cfl": 1.0})["predicted"],
            bounded_to=max(bounded) if bounded else None,
            blew_up_from=first_blow,
            first_step=blew[0][1] if blew else None,
            blew_up_at=blew,
            steps=int(g.steps.max()),
            other=[(float(r.cfl), r.status) for _, r in g.iterrows() if r.status not in ("ok", "unstable")],
            e_foldings=_fold(e_foldings(top, int(top.steps))) if top is not None else None,
            held=held,
        )
        out.append(row)
    return out
