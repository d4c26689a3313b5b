"""Advice from the stored runs: the fastest run on one machine that reaches an error at a physical time, within
the margin of its stable CFL (stability.MARGIN), beside the fastest run of the paper's method that compares
with it; where none does, the prediction's search (search.py) names the study that would. ``pcabench
advise`` (pcabench/cli/advise.py) prints it."""

from __future__ import annotations

import numpy as np

from pcabench.predict.search import suggest
from pcabench.predict.stability import assess, e_foldings, margin
from pcabench.spec import scene_from_row
from pcabench.store.rows import comparable, default_numerics, error_column, latest, numerics_label
from solvers import (
    DEFAULT_KERNEL,
    Scene,
)


def scene_of(r) -> dict:
    """A stored run's method and domain (the frame has brought rows that predate a parameter to its default)."""
    return {
        "kernel": r["kernel"],
        "h_factor": r["h_factor"],
        "cutoff_factor": r["cutoff_factor"],
        "cfl": r["cfl"],
        "integrator": r["integrator"],
        "correction": r.get("correction") or Scene.default("correction"),
        "dx": r["dx"],
        "strip_height": r["strip_height"],
    }


def command(r, t_end: float | None = None) -> str:
    """The ``pcabench run`` command line that makes stored run ``r`` (a row of the reports' frame) again, from
    its whole stored scene (:mod:`pcabench.commands`: every parameter away from its default, quoted for the
    shell). ``t_end`` is the run's own (kept for callers)."""
    from pcabench.commands import line_of, words_of

    scene = scene_from_row(r)
    return line_of(*words_of(str(r["solver"]), scene, int(r["threads"]), str(r.get("pair_loop") or "")))


def reaching(df, t_end: float, model: str):
    """Finished runs of ``model`` that ended at ``t_end`` (the newest of each configuration), fastest first."""
    d = df[(df.status == "ok") & (df.model == model) & df.t_final.notna()]
    d = d[np.isclose(d.t_final.astype(float), t_end, rtol=1e-6)]
    return latest(d).sort_values("t_solution") if not d.empty else d


def paper_configuration(df):
    """Rows of the paper's numerics: default integrator, CFL, h/dx and cutoff, and the Gaussian kernel."""
    d = default_numerics(df)
    return d[d["kernel"] == DEFAULT_KERNEL] if "kernel" in d else d


def unstable_row(r, column: str) -> dict:
    """A run that reached the error past its predicted stable CFL: what it was, never advised."""
    a = assess(r)
    return {
        "method": numerics_label(r),
        "dx": float(r.dx),
        "cfl": float(r.cfl),
        "fraction": a["fraction"],
        "past_limit": bool(a["past_limit"]),
        "stable_cfl": a["stable_cfl"],
        "limit_from": a["limit_from"],
        "error": float(r[column]),
        "seconds": float(r.t_solution),
        "steps": int(r.steps),
        "e_foldings": e_foldings(r, int(r.steps)),
    }


def unstable_rows(runs, column: str, most: int = 3) -> list[dict]:
    """The fastest ``most`` methods (kernel, h/dx, cutoff, CFL, dx) of ``runs`` (fastest first), once each."""
    rows, seen = [], set()
    for _, r in runs.iterrows():
        row = unstable_row(r, column)
        if (row["method"], row["dx"]) not in seen and len(rows) < most:
            seen.add((row["method"], row["dx"]))
            rows.append(row)
    return rows


def advise(
    df,
    error: float,
    t_end: float,
    model: str = "linear",
    domain: str | None = None,
    scene: str = Scene.default("name"),
    problem: tuple[str, ...] = (),
    suggest_missing: bool = True,
) -> dict:
    """The fastest stored run of ``scene`` reaching ``error`` at ``t_end`` (on ``domain``, ``strip`` or ``full``,
    if given) within the margin of its stable CFL, the fastest run of the paper's configuration reaching it that
    compares with it, and the ratio. Like is compared with like (``store.rows.comparable``): the same kind of domain (a
    strip holds fewer particles than the full domain; on a strip each method runs on the thinnest strip its
    support allows), the same threads and the same commit. A run past the margin of its method's stable CFL
    (pcabench/predict/stability.py ``MARGIN``, the one rule: at or past the limit it is unstable by prediction) is
    never advised, whatever its error: ``not_advised`` lists those faster than the advice (or all of them,
    fastest first, where none within the margin reaches the error). ``problem``: the study options of the problem
    asked about (``--open x``), for the study command :func:`suggest` names; ``suggest_missing`` False leaves
    the search out where no run answers (``suggestion`` None: the caller asks another machine's runs first)."""
    runs = reaching(df, t_end, model)
    if domain is not None and not runs.empty:
        runs = runs[runs.domain == domain]
    column = error_column(model)
    hits = runs[runs[column] <= error] if not runs.empty else runs
    past = np.array([assess(r)["past_margin"] for _, r in hits.iterrows()], bool)  # the one margin rule
    unstable, hits = hits[past], hits[~past]
    out = {
        "error_target": error,
        "t_end": t_end,
        "model": model,
        "runs_considered": int(len(runs)),
        "margin": margin(model),
        "problem": list(problem),
        "error_against": "the isothermal solution"
        if column == "mse_isothermal"
        else "the linear pulse"
        if scene == Scene.default("name")
        else "the exact linear solution",
    }
    if hits.empty:
        out["found"] = False
        out["not_advised"] = unstable_rows(unstable, column)
        out["suggestion"] = suggest(error, t_end, model, scene, problem, domain) if suggest_missing else None
        return out
    best = hits.iloc[0]
    faster = unstable[unstable.t_solution < best.t_solution]
    limit = assess(best)
    stable = limit["stable_cfl"]
    paper = paper_configuration(hits[[comparable(r, best) for _, r in hits.iterrows()]])
    paper_best = paper.iloc[0] if not paper.empty else None
    out.update(
        found=True,
        command=command(best, t_end),
        error=float(best[column]),
        seconds=float(best.t_solution),
        machine=str(best.machine),
        solver=str(best.solver),
        domain=str(best.domain),
        precision=str(best.precision),
        commit=str(best.commit)[:12],
        threads=int(best.threads),
        n_particles=int(best.n_particles),
        steps=int(best.steps),
        **scene_of(best),
        stable_cfl=stable,
        cfl_fraction=float(best.cfl) / stable,
        limit_from=limit["limit_from"],
        paper_seconds=None if paper_best is None else float(paper_best.t_solution),
        paper_error=None if paper_best is None else float(paper_best[column]),
        paper_command=None if paper_best is None else command(paper_best, t_end),
        not_advised=unstable_rows(faster, column),
    )
    out["is_paper_configuration"] = paper_best is not None and out["paper_command"] == out["command"]
    out["speedup_over_paper"] = out["paper_seconds"] / out["seconds"] if out["paper_seconds"] else None
    return out
