"""The report's "Sound at a rigid wall" section (``pcabench study --walls``): the error at the wall against
its prediction, the stable CFL at the wall over long runs beside the free scenes' own, and the time per step with
and without the wall at the same N.

Wall scenes are the scene kinds with ``walls`` (solvers/scenes/); each has a free counterpart (the same pulse
without the wall: ``FREE_COUNTERPART``, walls/plan.py) whose long runs and step times it is compared with.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from pcabench.reports.long_runs import long_run_limits
from pcabench.reports.md import fmt, md_table
from pcabench.reports.section import OUTCOME_COLUMNS, Section, outcome_cells, stored_measure
from pcabench.spec import scene_from_row
from pcabench.store.rows import is_paper_method, latest
from pcabench.studies.protocols import FRONT_T_END as T_FINAL
from pcabench.studies.protocols import LONG_T_END
from pcabench.studies.walls.figures import wall_errors
from pcabench.studies.walls.plan import FREE_COUNTERPART, WALL_COST_TAG, WALLS, cost_round
from solvers import Scene, scenes
from solvers.method import Method


def wall_scenes() -> tuple[str, ...]:
    """The registered scene kinds with a rigid wall."""
    return tuple(name for name, kind in scenes().items() if kind.walls)


def accuracy(df) -> list[dict]:
    """Every finished run of a wall scene at t = 10 s with the paper's method at the default amplitude (newest of
    each): its relative RMS error over the domain, near the walls (``wall_rms``: within a cutoff of a wall) and in
    the bulk, beside the same three predicted for the `linear` model (solvers/reference/dispersion.py on the mirror
    extension; for a moving model its linear part), and ``gap``, measured over predicted minus 1."""
    from solvers.reference.dispersion import predict

    d = df[
        (df.status == "ok")
        & df.scene.isin(wall_scenes())
        & np.isclose(df.t_final.astype(float), T_FINAL)
        & np.isclose(df.mach.astype(float), Scene.default("mach"))
    ]
    d = latest(d)
    rows = []
    for _, r in d.iterrows():
        if not is_paper_method(r):
            continue
        p = predict(scene_from_row(r).replace(model="linear"))
        measures = p.measures or {}
        rows.append(
            {
                "scene": r.scene,
                "model": r.model,
                "dx": float(r.dx),
                "N": int(r.n_particles),
                "domain": r.domain,
                "mse": float(r.mse),
                "wall_rms": stored_measure(r, "wall_rms"),
                "bulk_rms": stored_measure(r, "bulk_rms"),
                "predicted": p.predicted_error,
                "predicted_wall": measures.get("wall_rms"),
                "predicted_bulk": measures.get("bulk_rms"),
                "gap": float(r.mse) / p.predicted_error - 1.0,
                "commit": str(r.commit)[:7],
            }
        )
    return sorted(rows, key=lambda r: (r["scene"], r["model"] != "linear", -r["dx"]))


def stability(df) -> list[dict]:
    """The walls preset's long runs (t = LONG_T_END) per wall scene, model and method, as the long-run table
    measures them (the stability study's ``long_run_limits``: the CFLs run, bounded up to, blew up from, the
    prediction, the limit held), each with ``free``: the same model and method's long runs on the free counterpart scene
    (``pcabench study --stability long``), None where there are none."""
    long = df[(df.preset == WALLS) & np.isclose(df.t_final.astype(float), LONG_T_END)] if "preset" in df else df
    rows = long_run_limits(long, preset=WALLS)
    free = {
        (r["scene"], r["model"], r["kernel"], r["h_factor"], r["integrator"]): r
        for r in long_run_limits(df, preset="stability-long")
    }
    for r in rows:
        r["free_scene"] = FREE_COUNTERPART.get(r["scene"])
        r["free"] = free.get((r["free_scene"], r["model"], r["kernel"], r["h_factor"], r["integrator"]))
        r["below_prediction"] = r["blew_up_from"] is not None and r["blew_up_from"] < r["predicted"]
    return sorted(
        rows,
        key=lambda r: (r["scene"], r["kernel"], r["h_factor"], ("linear", "fixed", "lagrangian").index(r["model"])),
    )


def cost(df) -> list[dict]:
    """Time per step with and without the wall (``walls-cost-<round>`` runs): per wall scene and dx, at the newest
    commit that has both, the best (smallest) step time of each side over the rounds, their ratio, and the
    spread of the ratios within each round (the two runs of a round ran one after the other)."""
    d = df[(df.status == "ok") & df.preset.map(lambda p: cost_round(p) is not None)] if "preset" in df else df
    if d.empty:
        return []
    d = d.assign(round=d.preset.map(cost_round))
    rows = []
    for wall, free in FREE_COUNTERPART.items():
        for (dx, n), g in d[d.scene.isin((wall, free))].groupby(["dx", "n_particles"]):
            commits = [c for c, h in g.groupby("commit") if set(h.scene) == {wall, free}]
            if not commits:
                continue
            g = g[g.commit == max(commits, key=lambda c: g[g.commit == c].timestamp.max())]
            a, b = g[g.scene == wall], g[g.scene == free]
            per_round = [
                float(a[a["round"] == i].t_step.min() / b[b["round"] == i].t_step.min())
                for i in sorted(set(a["round"]) & set(b["round"]))
            ]
            rows.append(
                {
                    "scene": wall,
                    "free_scene": free,
                    "dx": float(dx),
                    "N": int(n),
                    "domain": g.domain.iloc[0],
                    "model": g.model.iloc[0],
                    "steps": int(a.steps.iloc[0]),
                    "rounds": len(per_round),
                    "wall_ms": 1e3 * float(a.t_step.min()),
                    "free_ms": 1e3 * float(b.t_step.min()),
                    "ratio": float(a.t_step.min() / b.t_step.min()),
                    "round_ratios": per_round,
                    "wall_neighbours": float(a.mean_neighbours.iloc[0]),
                    "free_neighbours": float(b.mean_neighbours.iloc[0]),
                    "commit": str(g.commit.iloc[0])[:7],
                }
            )
    return sorted(rows, key=lambda r: (r["scene"], -r["dx"]))


def rows(df, runs=None) -> dict | None:
    """The section's three tables: the accuracy from one machine's runs of every scene ``df``, the long runs and
    the cost from its presets' runs ``runs`` (the report's ``ctx.runs``; None: ``df``'s); None where it has no
    wall run."""
    if df.empty or not df.scene.isin(wall_scenes()).any():
        return None
    own = df if runs is None else runs
    return {"accuracy": accuracy(df), "stability": stability(own), "cost": cost(own)}


# ---------------------------------------------------------------- the section's Markdown
def _ratio_words(measured, predicted) -> str:
    return "-" if measured is None or not predicted else f"{measured:.4g} / {predicted:.4g}"


def _gap_words(gap: float) -> str:
    return f"{gap:+.2e}" if abs(gap) < 1e-3 else f"{100 * gap:+.2f} %"


ROUND_OFF_GAP = 1e-9  # |measured / predicted - 1| below this is round-off (the linear runs reach 1e-14)


def free_end_moved() -> tuple[float, float]:
    """(x_min, the largest |measured / predicted - 1|) of plane-wall's linear runs with the free left end moved
    20 m away: a measurement not in the store, kept as data with its command (measured.json)."""
    import json

    data = json.loads(Path(__file__).with_name("measured.json").read_text(encoding="utf-8"))["free_end_moved"]
    return float(data["x_min"]), float(data["largest_gap"])


def _span(values) -> str:
    lo, hi = f"{min(values):.2g}", f"{max(values):.2g}"
    return lo if lo == hi else f"{lo}-{hi}"


def _close(a, b, rtol: float = 0.01) -> bool:
    return len(a) == len(b) and all(abs(x / y - 1) <= rtol for x, y in zip(a, b))


def gap_cause(scene: str, linear) -> str:
    """Why the linear runs of ``scene`` do (or do not) equal the prediction on the mirror extension: "round-off"
    (they do), "free end" (they differ away from the wall only: the free left end's), "not only the free end"
    or "mirrors" (walls at both ends, where the prediction is exact: a defect of the mirrors)."""
    worst = max(abs(r["gap"]) for r in linear)
    at_wall = _at_wall(linear)
    free = "free-x" in scenes()[scene].boundaries()
    if worst < ROUND_OFF_GAP:
        return "round-off"
    if free and at_wall and max(at_wall) < 0.1 * worst:
        return "free end"
    return "not only the free end" if free else "mirrors"


def _at_wall(linear) -> list[float]:
    return [abs(r["wall_rms"] / r["predicted_wall"] - 1) for r in linear if r["wall_rms"] and r["predicted_wall"]]


def near_wall_cause(near) -> str:
    """Whether the near-wall error of linear runs ``near`` over the bulk's is the prediction's ratio (the lattice's
    dispersion: "dispersion") or departs from it (an error the wall or the model adds: "wall")."""
    measured = [r["wall_rms"] / r["bulk_rms"] for r in near]
    predicted = [r["predicted_wall"] / r["predicted_bulk"] for r in near]
    return "dispersion" if _close(measured, predicted) else "wall"


def _gap_note(scene: str, linear) -> str:
    """Why the linear runs of ``scene`` do (or do not) equal the prediction on the mirror extension, in words."""
    worst = max(linear, key=lambda r: abs(r["gap"]))
    at_wall = _at_wall(linear)
    head = f"measured and predicted differ by at most {_gap_words(worst['gap'])} (dx = {worst['dx']:g})"
    cause = gap_cause(scene, linear)
    if cause == "round-off":
        return head + ": round-off; the mirror extension is exactly the run's problem."
    if cause == "free end":
        x_min, gap = free_end_moved()
        return (
            head + f", near the wall by {max(at_wall):.2g}: the difference is the "
            "free left end's, not the wall's. The run's particles at that end miss the neighbours beyond it, "
            "while the prediction's even extension across the wall has no edge there; the pulse's tail "
            "(1.5e-5 of its peak at 10 m) is at that end from the start. With the left end moved to "
            f"x = {x_min:g} m the same runs match the prediction to {gap:.1g} (measured once, not in this "
            "store; tests/test_walls.py checks it)."
        )
    if cause == "not only the free end":
        return head + ": more than round-off, and not only away from the wall (its free left end is not all of it)."
    return (
        head + ": more than round-off where the prediction is exact (walls at both ends: the mirror "
        "extension is a periodic lattice and the run its problem), a defect of the mirrors to look for."
    )


def _accuracy_text(rows) -> list[str]:
    if not rows:
        return []
    table = [
        [
            r["scene"],
            r["model"],
            f"{r['dx']:g}",
            f"{r['N']:,}",
            r["domain"],
            f"{r['mse']:.5g}",
            f"{r['predicted']:.5g}",
            _gap_words(r["gap"]),
            _ratio_words(r["wall_rms"], r["predicted_wall"]),
            _ratio_words(r["bulk_rms"], r["predicted_bulk"]),
            fmt(r["wall_rms"] / r["bulk_rms"] if r["wall_rms"] is not None and r["bulk_rms"] else None, ".3g"),
        ]
        for r in rows
    ]
    lines = [
        "### Accuracy at the wall, t = 10 s",
        "",
        f"The paper's method ({Method.paper().words}) at Mach 0.05, scored against the exact "
        "linear solution (the pulse plus its mirror image): u for plane-wall, drho for pulse-wall, relative RMS "
        "over the domain; near the wall (the particles within a cutoff of a wall, the ones with mirror "
        "neighbours) and in the bulk (the others), each over the RMS of the reference over the whole domain, "
        "so that their squares, weighted by each band's share of the particles, add up to the whole's square. "
        "The prediction (`pcabench accuracy --scene NAME`) "
        "is the dispersion relation's on the mirror extension of the lattice: exact for `linear` where that "
        "extension is the run's whole problem; for `lagrangian` it is the linear part only.",
        "",
        md_table(
            [
                "scene",
                "model",
                "dx",
                "N",
                "domain",
                "error",
                "predicted (linear)",
                "measured / predicted - 1",
                "near the wall: measured / predicted",
                "bulk: measured / predicted",
                "near wall / bulk",
            ],
            table,
        ),
        "",
    ]
    for scene in sorted({r["scene"] for r in rows}):
        linear = [r for r in rows if r["scene"] == scene and r["model"] == "linear"]
        if linear:
            lines.append(f"- **{scene}**, linear: " + _gap_note(scene, linear))
        near = [r for r in linear if r["wall_rms"] is not None and r["bulk_rms"] and r["predicted_bulk"]]
        if near:
            measured = [r["wall_rms"] / r["bulk_rms"] for r in near]
            predicted = [r["predicted_wall"] / r["predicted_bulk"] for r in near]
            lines.append(
                f"- **{scene}**, linear: per particle, the RMS error near the wall is {_span(measured)} times the "
                f"bulk's in these runs, and {_span(predicted)} times in the linear prediction, which has no "
                "error of the wall's own (the mirror extension is a lattice without a wall): the near-wall "
                "error is the lattice's dispersion of the pulse that is there at t = 10 s"
                + (
                    ", not one the wall adds."
                    if near_wall_cause(near) == "dispersion"
                    else "; the runs' ratio departs from it: an error the wall (or the model) adds."
                )
            )
    moving = [r for r in rows if r["model"] != "linear"]
    if moving:
        lines.append(
            "- **lagrangian**: its error against the linear solution holds its nonlinear terms at Mach "
            "0.05 (the prediction is its linear part's); no isothermal reference exists at a wall (two "
            "simple waves crossing are not one), so it is not scored against its own physics here."
        )
    return lines + [""]


def _free_words(r) -> str:
    f = r["free"]
    if f is None:
        return "-"
    return (
        f"{r['free_scene']}: bounded to {fmt(f['bounded_to'], 'g') if f['bounded_to'] is not None else 'none'}, "
        f"blew up from {fmt(f['blew_up_from'], 'g') if f['blew_up_from'] is not None else 'none'}"
    )


def blow_up_cause(r) -> str:
    """What set the limit of a wall scene's method that blew up below its predicted stable CFL (stability row
    ``r``): "free ends" or "model" (its free counterpart blew up there too, without a wall: by its free ends, or
    by the model's terms), "wall" (the counterpart stayed bounded), or, with no counterpart's long runs, "free
    end or wall", "the wall alone" (a linear run with no free end: nothing else can) or "wall or model"."""
    f, w = r["free"], r["blew_up_from"]
    if f is not None and f["blew_up_from"] is not None and (f["bounded_to"] is None or w > f["bounded_to"]):
        return "free ends" if "free-x" in scenes()[r["free_scene"]].boundaries() else "model"
    if f is not None:
        return "wall"
    if "free-x" in scenes()[r["scene"]].boundaries():
        return "free end or wall"
    return "the wall alone" if r["model"] == "linear" else "wall or model"


def _cause_words(why: str, r) -> str:
    f = r["free"]
    if why in ("free ends", "model"):
        return f"as on {r['free_scene']}, which blew up from {f['blew_up_from']:g} without a wall: " + (
            f"the free ends ({r['scene']} keeps one) set this limit, not the wall"
            if why == "free ends"
            else "the model's own terms set this limit, not the wall"
        )
    if why == "wall":
        return f"{r['free_scene']} stayed bounded to {fmt(f['bounded_to'], 'g')}: the wall destabilises it"
    return {
        "free end or wall": "the free left end or the wall (no free long run of this method tells them apart)",
        "the wall alone": "the wall: without a free end the linear run is the prediction's periodic problem, "
        "so nothing else can",
        "wall or model": "the wall or the model's nonlinear terms (no free long run of this method tells them apart)",
    }[why]


def _stability_text(rows) -> list[str]:
    if not rows:
        return []
    table = []
    for r in rows:
        table.append(
            [
                r["scene"],
                f"{r['mach']:g}",
                r["model"],
                f"{r['kernel']}, h = {r['h_factor']:g} dx",
                ", ".join(f"{c:g}" for c in r["cfls"]),
                f"{r['predicted']:.3g}",
                *outcome_cells(r),
                _free_words(r),
                fmt(r["held"], "g") if r["held"] is not None else "prediction",
            ]
        )
    lines = [
        "### Stability at the wall",
        "",
        "`pcabench study --walls`: on each wall scene at dx = 0.25 to t = 300 s (long enough for round-off to "
        "grow, as the long runs of the free scenes; the plane pulse at Mach 0.01 so that it does not break "
        "before then, the 2D pulse, which spreads and never breaks, at the default 0.05), the linear model of each "
        "kernel at CFLs bracketing its "
        "predicted stable CFL, and the paper's method in every model at the free long runs' CFLs. Beside each, "
        "the same model and method's long runs on the free counterpart (`--stability long`: the plane pulse's "
        "strip with free ends, the 2D pulse's periodic square) where they were made. 'e-foldings': how far the "
        "most unstable mode of the periodic lattice grew at the largest bounded CFL (0 below the prediction). "
        "The last column is the limit advise and the tables use (pcabench/predict/measured_limits.csv, "
        "keyed by scene, where lower than the prediction).",
        "",
        md_table(
            [
                "scene",
                "Mach",
                "model",
                "method",
                "CFLs run",
                "predicted stable CFL",
                *OUTCOME_COLUMNS,
                "free counterpart's long runs",
                "limit used",
            ],
            table,
        ),
        "",
    ]
    not_the_wall = []  # per run that blew up below the prediction: whether its free counterpart did so too
    for r in rows:
        if not r["below_prediction"]:
            continue
        w = r["blew_up_from"]
        why = blow_up_cause(r)
        not_the_wall.append(why in ("free ends", "model"))
        cause = _cause_words(why, r)
        lines.append(
            f"- **{r['model']}, {r['kernel']} h = {r['h_factor']:g} dx** on {r['scene']} blew up below "
            f"the predicted {r['predicted']:.3g}, from CFL {w:g} ("
            + (f"bounded to {r['bounded_to']:g}" if r["bounded_to"] is not None else "none of its CFLs stayed bounded")
            + f"): {cause}"
            + (
                f"; advise takes it as {r['held']:g}."
                if r["held"] is not None
                else "; advise still uses the prediction for it (add it to pcabench/predict/measured_limits.csv)."
            )
        )
    if not not_the_wall:
        lines.append("- No run blew up below its predicted stable CFL: the wall destabilises none of these methods.")
    elif all(not_the_wall):
        lines.append(
            "- No wall lowered a limit below its free counterpart's: where a run blew up below the "
            "prediction, the same model and method blew up as low or lower without the wall."
        )
    return lines + [""]


def _cost_text(rows) -> list[str]:
    if not rows:
        return []
    table = [
        [
            f"{r['scene']} / {r['free_scene']}",
            r["model"],
            r["domain"],
            f"{r['dx']:g}",
            f"{r['N']:,}",
            f"{r['steps']} x {r['rounds']}",
            f"{r['free_ms']:.4g}",
            f"{r['wall_ms']:.4g}",
            f"{r['ratio']:.3f}",
            f"{min(r['round_ratios']):.3f}-{max(r['round_ratios']):.3f}",
            f"{r['wall_neighbours']:.1f} / {r['free_neighbours']:.1f}",
            r["commit"],
        ]
        for r in rows
    ]
    return [
        "### What the wall costs",
        "",
        "Time per step (SNP + PI + SU, ms, serial, the default CPU solver and pair loop) of each wall scene "
        "and its free counterpart on the same box at the same N, the paper's timing model (lagrangian: the "
        "mirrors follow every step). The two ran one after the other in each round, alternating which went "
        "first, in one sweep (the newest that made both: its commit in the last column); each side's best step "
        "time over the rounds and their ratio, and the ratio of "
        "each round's pair (a shared machine: the spread is the noise). The mirrors are computed in the pair "
        "sums, never stored: beside the free strip the wall adds the pairs its edge particles would miss; beside "
        "the periodic square, whose images give the same pairs (the mean neighbours column), it adds only the "
        "mirrors' own arithmetic.",
        "",
        md_table(
            [
                "wall / free scene",
                "model",
                "domain",
                "dx",
                "N",
                "steps x rounds",
                "free ms/step (best)",
                "wall ms/step (best)",
                "wall / free",
                "each round's ratio",
                "mean neighbours wall / free",
                "commit",
            ],
            table,
        ),
        "",
        *_cost_notes(rows),
    ]


def _cost_notes(rows) -> list[str]:
    """Whether each row's rounds agree on which side is faster: where they do not, the machine's noise is as large
    as the wall's cost and the table resolves neither."""
    agree = [r for r in rows if min(r["round_ratios"]) > 1 or max(r["round_ratios"]) < 1]
    spread = [x for r in rows for x in r["round_ratios"]]
    lines = []
    noisy = len(agree) < len(rows)
    for r in agree:
        side = "more" if r["ratio"] > 1 else "less"
        lines.append(
            f"- {r['scene']} at dx = {r['dx']:g}: in all {r['rounds']} rounds the wall's step cost {side}, by "
            f"{_span([abs(x - 1) * 100 for x in r['round_ratios']])} %"
            + (
                f"; with the other rows' noise as large as that, {r['rounds']} rounds do not make it a measurement."
                if noisy
                else "."
            )
        )
    if len(agree) < len(rows):
        lines.append(
            f"- In {len(rows) - len(agree)} of {len(rows)} rows the rounds disagree on which side is faster (the "
            f"ratios of all rounds spread {min(spread):.2f}-{max(spread):.2f}): on this shared machine the noise is "
            "as large as the wall's cost, which these runs do not resolve."
        )
    return lines + ([""] if lines else [])


def text(data, ctx) -> list[str]:
    """The section's Markdown from :func:`rows`."""
    if not data:
        return []
    body = _accuracy_text(data["accuracy"]) + _stability_text(data["stability"]) + _cost_text(data["cost"])
    if not body:
        return []
    return [
        "## Sound at a rigid wall",
        "",
        "A rigid wall by mirror particles (solvers/physics/pairs.py), on two scenes: `plane-wall`, the paper's plane "
        "pulse reflected by a wall at x = 6 m (free left end), and `pulse-wall`, the 2D acoustic pulse two "
        "widths from a wall in a duct walled at both x ends. `pcabench study --walls` makes every run below; "
        "`walls_error.png` draws the error near the wall and in the bulk against dx.",
        "",
        *body,
    ]


SECTION = Section(
    "walls",
    lambda ctx: rows(ctx.df_scenes if ctx.df_scenes is not None else ctx.df, ctx.runs),
    text,
    (lambda d, ctx: wall_errors(d["accuracy"], ctx.out, ctx.name) if d else None,),
    all_scenes=True,
    order=150,
    reads=(WALLS, WALL_COST_TAG + "*", "stability-long"),
)
