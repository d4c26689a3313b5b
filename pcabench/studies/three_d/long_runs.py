"""Where methods fail in 3D (``pcabench study --three-d long``): each method's stable CFL as long runs measured it
on the 3D pulse's periodic cube and at the sphere's wall, beside the cubic lattice's prediction and the square's."""

from __future__ import annotations

from pcabench.reports.long_runs import long_run_limits
from pcabench.reports.md import fmt, md_table
from pcabench.reports.section import OUTCOME_COLUMNS, Section, limit_words, outcome_cells
from pcabench.studies.three_d.plan import THREE_D_LONG


def rows(df) -> list[dict]:
    """:func:`long_run_limits` of the preset's runs, each with the square lattice's prediction beside the cube's."""
    from pcabench.predict.stability import lattice_limits, method_of

    if df is None or df.empty:
        return []
    out = []
    for r in long_run_limits(df, preset=THREE_D_LONG):
        square = lattice_limits({"scene": "acoustic-pulse", **dict(zip(("kernel", "h_factor", "cutoff_factor"),
                                                                      method_of(r)[:3])),
                                 "integrator": r["integrator"], "correction": r["correction"]})[0]  # fmt: skip
        out.append({**r, "square": square})
    return out


def _sort(r) -> tuple:
    return (r["scene"] != "acoustic-pulse-3d", r["kernel"], r["integrator"], r["model"] != "linear", r["model"])


def text(rows, ctx) -> list[str]:
    if not rows:
        return []
    rows = sorted(rows, key=_sort)
    table = [
        [
            r["scene"],
            r["model"],
            f"{r['kernel']}, h = {r['h_factor']:g} dx{', corrected' if r['correction'] != 'none' else ''}, "
            f"{r['integrator']}",
            f"{r['dx']:g}",
            f"{r['protocol']} (up to {r['steps']} steps)",
            ", ".join(f"{c:g}" for c in r["cfls"]),
            limit_words(r["predicted"]),
            limit_words(r["square"]),
            *outcome_cells(r),
            fmt(r["held"], "g") if r["held"] is not None else "prediction",
        ]
        for r in rows
    ]
    lines = [
        "### Where methods fail in 3D",
        "",
        "`pcabench study --three-d long`: long runs either side of each method's stable CFL, not scored. The 3D "
        "pulse in an 18 m periodic cube at dx 1 (5,832 particles), where the cubic lattice's prediction is exact "
        "for the linear model; the rigid sphere with cut cells (a wall without ghosts: a free end, "
        "pcabench/predict/stability.py `free_ended`) and the PML, at dx 0.125 in a 3.2 m cube (the pulse's centre "
        "at 1 m), to t = 30 s. 'predicted' is the periodic cubic lattice's stable CFL (solvers/reference/"
        "dispersion3d.py), 'square' the square lattice's for the same method; 'e-foldings' how far the lattice's "
        "most unstable mode grew at the largest bounded CFL (0 below the prediction); the last column the limit "
        "advise, the front and the tables use (pcabench/predict/measured_limits.csv where lower than the "
        "prediction; a wall without ghosts takes the plane pulse's free end's where its scene has no row).",
        "",
        md_table(
            [
                "scene",
                "model",
                "method",
                "dx",
                "run",
                "CFLs run",
                "predicted (cube)",
                "square",
                *OUTCOME_COLUMNS,
                "limit used",
            ],
            table,
        ),
        "",
    ]
    for r in rows:
        blew, bounded = r["blew_up_from"], r["bounded_to"]
        if blew is None:
            continue
        if blew < r["predicted"]:
            lines.append(
                f"- **{r['scene']}, {r['model']}, {r['kernel']} {r['integrator']}** blew up below the cubic "
                f"lattice's {r['predicted']:.3g}, from CFL {blew:g}"
                + (f" (bounded at {bounded:g})" if bounded is not None else "")
                + ": its wall or edges set the limit"
                + (f"; the suite steps below {r['held']:g}." if r["held"] is not None else "; no row yet.")
            )
        elif blew < r["square"] and (bounded is None or bounded < r["predicted"]):
            lines.append(
                f"- **{r['scene']}, {r['model']}, {r['kernel']} {r['integrator']}**: CFL {blew:g} blew up, past "
                f"the cubic lattice's {r['predicted']:.3g} and short of the square's {r['square']:.3g}: a 3D run "
                "steps by the cube's limit, not a 2D run's."
            )
    return lines + [""]


SECTION = Section(
    "three-d-long-runs",
    lambda ctx: rows(ctx.runs),
    text,
    all_scenes=True,
    order=159.5,
    reads=(THREE_D_LONG,),
)
