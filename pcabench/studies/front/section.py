"""The speed-accuracy front: time to solution against error at t = 10 s."""

from __future__ import annotations

from functools import lru_cache

from pcabench.reports.md import fmt, md_table, pct
from pcabench.reports.section import Section, limit_words
from pcabench.store.rows import linear_floor
from pcabench.studies.front.figures import speed_vs_accuracy
from pcabench.studies.front.rows import fastest_to, predicted_by_model, predicted_error, speed_front, unstable_on_front
from pcabench.studies.front.scenes import SECTION as SCENES  # every scene kind's fronts: the study's second section
from solvers import Scene
from solvers.method import Method


def point_cells(p) -> list[str]:
    """A front point's cells: model, t (s), method, dx, domain, precision, time (s), error."""
    return [
        p["model"],
        fmt(p["t_final"], "g"),
        p["method"],
        fmt(p["dx"], "g"),
        p["domain"],
        p["precision"],
        fmt(p["seconds"], ".3g"),
        fmt(p["error"], ".3g"),
    ]


def rows(ctx):
    points, front = speed_front(ctx.df)
    return {"points": points, "front": front, "predicted": predicted_by_model(ctx.df) if points else []}


def unstable_front_text(rows) -> list[str]:
    if not rows:
        return []
    return [
        "Unstable by prediction, never on the front nor in the first table, whatever their error: the runs "
        "at or past their method's predicted stable CFL that a front ignoring the prediction would hold. "
        "Each ended bounded only because its run was too short: its most unstable mode grew by the "
        "e-foldings shown, while round-off (1e-16) needs about 37 to reach the pulse's size; a finer dx "
        "or a longer time makes it blow up. The limit is the prediction's (for `fixed` and `lagrangian` "
        "their linear part's), or where lower the one long runs on the scene measured (see 'Stability over "
        "long runs': on the paper's strip its free ends blow the paper's method up from CFL 4.8, every "
        "model, below the periodic lattice's 4.97).",
        "",
        md_table(
            [
                "model",
                "t (s)",
                "method",
                "dx",
                "domain",
                "precision",
                "time (s)",
                "error",
                "stable CFL",
                "steps",
                "e-foldings",
            ],
            [
                [
                    *point_cells(p),
                    limit_words(p["stable_cfl"]) + (" (long runs)" if p.get("limit_from") == "long runs" else ""),
                    str(p["steps"]),
                    fmt(p["e_foldings"], ".3g"),
                ]
                for p in rows
            ],
        ),
        "",
    ]


def past_margin_text(front) -> list[str]:
    """The front's runs that advise never names: stable, but past its one margin (stability.MARGIN), and why."""
    from pcabench.predict.stability import margin_rule

    past = [p for p in front if p.get("past_margin") and not p.get("past_limit")]
    if not past:
        return []
    models = sorted({p["model"] for p in past})
    return [
        f"On the front but never named by `pcabench advise`, which keeps a margin below the stable CFL "
        f"({'; '.join(margin_rule(m) for m in models)}): "
        + ", ".join(
            f"{p['model']} {p['method']}, dx {p['dx']:g} "
            f"(CFL {p['cfl']:g} = {p['fraction']:.2f} of {p['stable_cfl']:.3g})"
            for p in past
        )
        + ". Measured and bounded, they sit too close to their limit for a longer run or another dx.",
        "",
    ]


def predicted_by_model_text(predicted) -> list[str]:
    rows = [
        [r["model"], fmt(r["dx"], "g"), pct(r["measured"]), pct(r["predicted"]), pct(r["isothermal"])]
        for r in predicted
    ]
    if not rows:
        return []
    return [
        "Predicted against measured for every model (the paper's method on the strip, t = 10 s, float64; "
        "errors against the linear pulse). `linear` is the operator the prediction is exact for. `fixed` "
        "keeps rho = rho0 + drho in its coefficients and masses from the initial density, a first-order "
        "change in Ma of the operator, and no advection: it solves neither the linear nor the isothermal "
        "equations, so it parts from the prediction by several times. `lagrangian` moves its particles and "
        "converges to the isothermal solution instead, whose distance from the linear pulse "
        f"({pct(linear_floor(Scene.default('name'), Scene.default('mach'), 10.0))} at t = 10 s) its error "
        "against the pulse approaches; against the isothermal solution (last column) its "
        "error follows the predicted linear part closely: the prediction describes its discretisation "
        "error, the pulse's Mach number the rest.",
        "",
        md_table(["model", "dx", "measured", "predicted (linear part)", "lagrangian: vs isothermal"], rows),
        "",
    ]


@lru_cache(maxsize=1)
def why_the_paper_method() -> list[str]:  # pure: cached, as every report shows it
    """Why the paper's h and dt sit where they do, from the prediction at its own scene's dx."""
    from solvers.reference.dispersion import lattice_offsets, predict

    base = Scene(dx=0.1, t_end=10.0, model="linear")
    rows = []
    for what, scene in (
        ("the paper's method", base),
        ("CFL 2", base.replace(cfl=2.0)),
        ("h = 1.5 dx", base.replace(h_factor=1.5)),
        ("Wendland C4, h = 1.6 dx", base.replace(kernel="wendland-c4", h_factor=1.6)),
    ):
        p = predict(scene)
        nbrs = len(lattice_offsets(scene)[0])
        rows.append(
            [
                what,
                str(nbrs),
                f"{100 * p.lattice_phase_error:+.3f} %",
                f"{100 * p.step_phase_error:+.3f} %",
                fmt(p.stable_cfl, ".3g"),
                pct(p.predicted_error),
            ]
        )
    return [
        "Why the paper's h and dt sit where they do (predicted at dx = 0.1, t = 10 s): the lattice sum lags "
        "the true phase speed (a smoother, wider kernel lags more, and the 3h truncation biases the "
        "sound speed by about 0.12 %), while the leapfrog step leads it by about (c0 k dt)^2 / 24, so a "
        "larger step cancels part of the lag: the paper's small CFL keeps the whole lag, and its wide h pays "
        "for twice the neighbours with a larger lag.",
        "",
        md_table(
            ["method", "neighbours", "phase speed: lattice", "with the step", "stable CFL", "predicted error"], rows
        ),
        "",
    ]


def text(data, ctx) -> list[str]:
    points, front = data["points"], data["front"]
    if not points:
        return []
    rows = []
    for r in fastest_to(points):
        best, paper = r["best"], r["paper"]
        if best is None:
            continue
        rows.append(
            [
                r["model"],
                fmt(r["t_final"], "g"),
                pct(r["target"]),
                best["method"],
                fmt(best["dx"], "g"),
                best["domain"],
                f"{best['precision']}, {best['threads']} thread(s)",
                fmt(best["seconds"], ".3g"),
                pct(best["error"]),
                fmt(paper["dx"], "g") if paper else "-",
                f"{paper['threads']} thread(s)" if paper else "-",
                fmt(paper["seconds"], ".3g") if paper else "-",
                fmt(r["speedup"], ".3g") if r["speedup"] else "-",
            ]
        )
    fronts = [
        [
            *point_cells(p),
            fmt(predicted_error(p), ".3g"),
        ]
        for p in front
    ]
    return [
        "## Time to a given accuracy",
        "",
        "Every finished run at a fixed physical time, whatever its method (kernel, h/dx, cutoff, CFL), dx and "
        "precision: time to solution (init + steps, no JIT) against the relative RMS error of u. For each "
        "error, the fastest run that reaches it, beside the fastest run of the paper's method "
        f"({Method.paper().words}) that reaches it, on this machine, serial or as labelled. "
        "The paper's method is compared on the same kind of domain as the fastest run (a strip holds fewer "
        "particles than the full domain for the same answer; on a strip each method runs on the thinnest "
        "strip its support allows, so a compact kernel's strip is thinner). Errors are against what each model "
        "converges to: the linear "
        "pulse for `linear`, the isothermal solution (solvers/reference/isothermal1d.py) for `lagrangian` (its error "
        "against the linear pulse never falls below the two equations' "
        f"{pct(linear_floor(Scene.default('name'), Scene.default('mach'), 10.0))} difference at t = 10 s; "
        "lagrangian runs from before this was measured are left out). `fixed` solves neither and is in the "
        "cost of the simplifications below. "
        + (
            "These runs are all of the paper's method, so every ratio is 1 (a quick study's); `pcabench study "
            "--front` adds the other kernels, h/dx and steps."
            if all(p["paper_method"] for p in points)
            else "The other kernels, h/dx and steps are `pcabench study --front`'s runs."
        ),
        "",
        md_table(
            [
                "model",
                "t (s)",
                "error target",
                "fastest method",
                "dx",
                "domain",
                "precision, threads",
                "time (s)",
                "error",
                "paper's method: dx",
                "threads",
                "time (s)",
                "paper / fastest",
            ],
            rows,
        ),
        "",
        "The front (the runs no faster run of the same model beats in error), with the error the dispersion "
        "relation predicts for each (`pcabench accuracy`, solvers/reference/dispersion.py: the lattice's SPH operator "
        "and the integrator's own step on every wavenumber of the pulse, no simulation). For `linear` the "
        "two agree to many digits while the pulse's error waves stay clear of the domain's ends (tested to "
        "1e-8 on a longer strip); where they part here, at coarse dx and large steps, those waves have "
        "reached the ends, which the prediction's unbounded lattice lacks. For `lagrangian` the prediction "
        "is the linear part only: the moving particles and the nonlinear terms add to it.",
        "",
        md_table(["model", "t (s)", "method", "dx", "domain", "precision", "time (s)", "error", "predicted"], fronts),
        "",
        *past_margin_text(front),
        *unstable_front_text(unstable_on_front(points)),
        *predicted_by_model_text(data["predicted"]),
        *why_the_paper_method(),
    ]


SECTION = Section(
    "front",
    rows,
    text,
    (lambda rows, ctx: speed_vs_accuracy(rows["points"], rows["front"], ctx.out, ctx.name),),
    order=80,
)

__all__ = ["SECTION", "SCENES"]  # the registry finds both here
