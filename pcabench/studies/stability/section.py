"""Where methods fail: the stable CFL of each integrator and h/dx, and the stability map."""

from __future__ import annotations

from pcabench.reports.md import md_table, pct
from pcabench.reports.section import Section, limit_words
from pcabench.studies.stability.figures import stability_map
from pcabench.studies.stability.long_runs import SECTION as LONG_RUNS  # the study's second section
from pcabench.studies.stability.plan import INACCURATE_ABOVE
from pcabench.studies.stability.rows import cfl_ranges, stability
from solvers import Scene


def e_fold_words(bounded) -> str:
    """ "CFL 5-7 ended bounded after 6-8 steps, their most unstable mode 1.9-12 e-foldings" from
    ``bounded_past_limit`` entries (cfl, steps, e-foldings)."""
    steps = sorted({b[1] for b in bounded})
    folds = [b[2] for b in bounded]

    def span(lo, hi, f):
        return f"{lo:{f}}" if f"{lo:{f}}" == f"{hi:{f}}" else f"{lo:{f}}-{hi:{f}}"

    return (
        f"ended bounded after {span(steps[0], steps[-1], 'd')} steps, in which the most unstable mode grew by "
        f"{span(min(folds), max(folds), '.2g')} e-foldings"
    )


def stability_row(lim) -> list[str]:
    swept = lim["cfls"]
    bounded = lim["bounded_past_limit"]
    blew = lim["blew_up_at"]
    limit = limit_words(lim["stable_cfl"]) + (" (long runs)" if lim.get("limit_from") == "long runs" else "")
    return [
        lim["config"],
        f"{lim['dx']:g}",
        ", ".join(f"{c:g}" for c in swept),
        limit,
        cfl_ranges(lim["accurate_at"], swept) or "none",
        "; ".join(f"{c:g} ({pct(e)})" for c, e in lim["inaccurate_at"]) or "-",
        "; ".join(f"{c:g}" + (f" (step {st})" if st else "") for c, st in blew) or "-",
        (f"{cfl_ranges([b[0] for b in bounded], swept)}: " + e_fold_words(bounded)) if bounded else "-",
    ]


def text(rows, ctx) -> list[str]:
    _points, limits = rows
    if not limits:
        return []
    lines = [
        "## Stability: where methods fail",
        "",
        "`pcabench study --stability` (and a quick study's few CFLs): the linear model on a strip. The story "
        "comes from the prediction (`pcabench accuracy`: the largest CFL at which one step of the integrator "
        "never grows any lattice mode, exact for this model on a periodic lattice; where long runs on the "
        "scene blew up below it, as the strip's free ends make the paper's method do from CFL 4.8, that limit "
        "is used: see 'Stability over long runs'): a run at or past its method's stable CFL is unstable. It "
        "either blew up (stopped at the step where max|u| left its bound or went "
        "non-finite) or, where it ended bounded, it is *unstable by prediction*: its run was too short for "
        "round-off to grow, as its e-foldings say (round-off, 1e-16 of the pulse, needs about 37 to reach the "
        "pulse's size; a finer dx or a longer time makes such a run blow up). Below the limit a run is stable "
        f"(relative RMS error within {100 * INACCURATE_ABOVE:g} %) or inaccurate (bounded, error above it). "
        "The map draws the same classes, and the predicted limit on each row.",
        "",
        md_table(
            [
                "method",
                "dx",
                "CFLs run",
                "stable CFL (predicted, or long runs where lower)",
                f"stable, within {100 * INACCURATE_ABOVE:g} %, at CFL",
                "inaccurate (below the limit) at CFL",
                "blew up at CFL",
                "past the limit, ended bounded (unstable by prediction)",
            ],
            [stability_row(lim) for lim in limits],
        ),
        "",
    ]
    for lim in limits:
        if lim["h_factor"] == Scene.default("h_factor") and lim["precision"] == "float64" and len(lim["cfls"]) > 3:
            swept = lim["cfls"]
            parts = [
                (
                    f"stable up to CFL {lim['stable_cfl']:.3g} as long runs on this scene measured (its free "
                    f"ends; {lim['predicted']:.3g} predicted for a periodic lattice)"
                    if lim["limit_from"] == "long runs"
                    else f"predicted stable up to CFL {lim['stable_cfl']:.3g}"
                )
                if lim["stable_cfl"] > 0
                else "predicted to grow at every CFL"
            ]
            if lim["blew_up_at"]:
                parts.append(f"blew up at CFL {cfl_ranges([c for c, _ in lim['blew_up_at']], swept)}")
            if lim["bounded_past_limit"]:
                b = lim["bounded_past_limit"]
                parts.append(
                    f"CFL {cfl_ranges([x[0] for x in b], swept)} {e_fold_words(b)}: too few for "
                    "round-off to grow, unstable by prediction, not stable"
                )
            if lim["blew_up_below_limit"]:
                parts.append(
                    f"blew up below the predicted limit at CFL "
                    f"{cfl_ranges(lim['blew_up_below_limit'], swept)} (against the prediction)"
                )
            accurate = cfl_ranges(lim["accurate_at"], swept)
            parts.append(
                f"stable and within {100 * INACCURATE_ABOVE:g} % error at CFL {accurate}"
                if accurate
                else f"stable and within {100 * INACCURATE_ABOVE:g} % error at none of the CFLs run"
            )
            lines.append(f"- **{lim['integrator']}** ({lim['protocol']}): " + "; ".join(parts) + ".")
    return lines + [""]


def draw_stability_map(rows, ctx):
    return stability_map(*rows, ctx.out, ctx.name, INACCURATE_ABOVE)


SECTION = Section(
    "stability",
    lambda ctx: stability(ctx.runs, INACCURATE_ABOVE),
    text,
    (draw_stability_map,),
    order=100,
    reads=("stability", "quick"),  # the stability map's runs, and a quick study's CFL sweep
)

__all__ = ["SECTION", "LONG_RUNS"]  # the registry finds both here
