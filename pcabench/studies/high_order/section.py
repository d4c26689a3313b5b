"""High-order SPH (``pcabench study --high-order``): the kernel gradient correction, the Laguerre-Gauss kernel and
RK4 against standard SPH. Its rows, text and two figures: the error against dx at fixed h / dx (the orders) and
the error against the time to solution (work-precision), on the plane pulse and the 2D pulse; the long runs'
stable step. The cylinder's runs of the method are in "Sound around an object"."""

from __future__ import annotations

import math

import numpy as np

from pcabench.predict.stability import stable_cfl
from pcabench.reports import figures as F
from pcabench.reports.md import fmt, md_table
from pcabench.reports.section import Section
from pcabench.spec import scene_from_row
from pcabench.store.rows import latest
from pcabench.studies.high_order.plan import HIGH_ORDER, HIGH_ORDER_T_END
from solvers.method import Method
from solvers.reference import dispersion

TARGET = 1e-4  # the issue's plane-pulse target at dx 0.1 for the high-order method (RK4, CFL 1)
SCENES = {"plane-pulse": "the plane pulse (5 m strip)", "acoustic-pulse": "the 2D pulse (40 m square)"}


def rows(df) -> dict | None:
    """The high-order study's runs ``df`` (the report's ``ctx.runs``; newest of each), one row each; None where there
    are none."""
    if df is None or df.empty:
        return None
    runs = []
    for _, r in latest(df).iterrows():
        scene = scene_from_row(r)
        method = Method.of(scene)
        runs.append(
            {
                "scene": scene.name,
                "dx": float(scene.dx),
                "label": method.numerics,
                "kernel": scene.kernel,
                "h": float(scene.h_factor),
                "corrected": scene.correction != "none",
                "cfl": float(scene.cfl),
                "model": scene.model,
                "t_end": float(scene.t_final),
                "status": str(r.status),
                "failed_step": r.failed_step,
                "error": float(r.mse) if r.status == "ok" and np.isfinite(r.mse) else None,
                "seconds": float(r.t_solution) if r.status == "ok" else None,
                "N": int(r.n_particles),
                "limit": stable_cfl(scene),
                "predicted": dispersion.predicted_stable_cfl(scene),
            }
        )
    return {"runs": runs}


def methods(runs, scene: str) -> dict:
    """{(label, CFL): [runs at t = 10 s, coarse to fine]} of ``scene``'s linear accuracy runs."""
    out: dict = {}
    for r in runs:
        if r["scene"] == scene and r["model"] == "linear" and math.isclose(r["t_end"], HIGH_ORDER_T_END):
            out.setdefault((r["label"], r["cfl"]), []).append(r)
    return {k: sorted(v, key=lambda r: -r["dx"]) for k, v in sorted(out.items())}


def order(a, b) -> float | None:
    """log(e_a / e_b) / log(dx_a / dx_b) of two runs, None where either has no error."""
    if not (a["error"] and b["error"]):
        return None
    return math.log(a["error"] / b["error"]) / math.log(a["dx"] / b["dx"])


def _error(r) -> str:
    if r["status"] != "ok":
        step = r["failed_step"]
        return f"{r['status']} (step {int(step) if step is not None and step == step else '-'})"
    return fmt(r["error"], ".3g")


def text(data, ctx) -> list[str]:
    if not data:
        return []
    runs = data["runs"]
    lines = [
        "## High-order SPH",
        "",
        "Standard SPH at fixed h / dx keeps a phase-speed error that no refinement removes (the lattice sum of "
        "the kernel's gradient misses its continuous first moment) and a second-order smoothing lag. The kernel "
        "gradient correction (`--correction gradient`: L_i = M_i^-1 on the momentum gradient, its negative adjoint "
        "in continuity, so that the discrete energy is kept; solvers/corrections/gradient.py) removes the first, "
        "the fourth-order Laguerre-Gauss kernel (`--kernel laguerre-gauss`, h = 1.5 dx, `--cutoff 4`) the second, "
        "and RK4 (`--integrator rk4`) Verlet's second-order phase error behind them (design.md, 1c). Linear "
        "model, t = 10 s, relative RMS of the primary field against the exact solution; `pcabench study "
        "--high-order`, linked list, serial.",
        "",
    ]
    for scene, title in SCENES.items():
        found = methods(runs, scene)
        if not found:
            continue
        dxs = sorted({r["dx"] for rs in found.values() for r in rs}, reverse=True)
        table = []
        for (label, cfl), rs in found.items():
            by_dx = {r["dx"]: r for r in rs}
            steps = [order(a, b) for a, b in zip(rs, rs[1:])]
            table.append(
                [label, f"{cfl:g}"]
                + [_error(by_dx[dx]) if dx in by_dx else "" for dx in dxs]
                + [" / ".join(fmt(o, ".2f") for o in steps) or "-"]
                + [fmt(rs[-1]["seconds"], ".3g")]
            )
        header = ["method", "CFL", *(f"dx {dx:g}" for dx in dxs), "orders", "s (finest)"]
        lines += [f"{title[0].upper()}{title[1:]}:", "", md_table(header, table), ""]
    plane = methods(runs, "plane-pulse")
    target = [rs for (label, cfl), rs in plane.items() if label.startswith("laguerre-gauss") and "rk4" in label]
    for rs in target:
        fine = rs[-1]
        o = order(rs[-2], rs[-1]) if len(rs) > 1 else None
        corrected = "gradient" in rs[-1]["label"]
        lines.append(
            f"- **{fine['label']}, CFL {fine['cfl']:g}**: {fmt(fine['error'], '.3g')} at dx {fine['dx']:g}, order "
            f"{fmt(o, '.2f')} from dx {rs[-2]['dx']:g}"
            + (
                f" (the issue's target: at most {TARGET:g} and order 3.5: "
                + ("met)." if fine["error"] and fine["error"] <= TARGET and o and o >= 3.5 else "not met).")
                if corrected
                else " (without the correction: the kernel's lattice moment, 4e-5 from 1, floors it)."
            )
        )
    fixed = [
        (label, cfl, order(rs[-2], rs[-1]))
        for (label, cfl), rs in plane.items()
        if len(rs) > 1 and "rk4" not in label and "gradient" in label
    ]
    if fixed:
        lines.append(
            "- **Each kernel corrected, Verlet CFL 0.2, order from dx 0.2 to 0.1** (the issue asks at least 1.9): "
            + "; ".join(f"{label} {fmt(o, '.2f')}" for label, cfl, o in fixed)
            + "."
        )
    long = [r for r in runs if r["t_end"] > HIGH_ORDER_T_END]
    for key in sorted({(r["label"], r["model"]) for r in long}):
        mine = sorted((r for r in long if (r["label"], r["model"]) == key), key=lambda r: r["cfl"])
        lines.append(
            f"- **Long runs, {key[0]}, {key[1]}, dx {mine[0]['dx']:g}, to t = {mine[0]['t_end']:g} s** (Mach 0.01): "
            + ", ".join(f"CFL {r['cfl']:g} {_ended(r)}" for r in mine)
            + f"; the periodic lattice predicts {mine[0]['predicted']:.3g}, advise keeps below {mine[0]['limit']:.3g}."
        )
    return lines + [""]


def _ended(r) -> str:
    return "bounded" if r["status"] == "ok" else f"{r['status']} at step {int(r['failed_step'])}"


def kernel_colours(runs) -> dict:
    """{(kernel, h / dx): colour}: one colour per kernel and h, shared by its corrected and standard runs."""
    keys = sorted({(r["kernel"], r["h"]) for r in runs})
    return dict(zip(keys, F.palette(len(keys))))


def _style(label: str, cfl: float) -> dict:
    """Solid and filled: corrected, dashed and hollow: standard; triangles up: RK4 at CFL 1 or more, triangles down: RK4
    below CFL 1, circles: Verlet at the paper's CFL 0.2, squares: Verlet at another CFL."""
    if "rk4" in label:
        marker = "^" if cfl >= 1 else "v"
    else:
        marker = "o" if math.isclose(cfl, 0.2) else "s"
    corrected = "gradient" in label
    return {"ls": "-" if corrected else "--", "marker": marker, **({} if corrected else {"mfc": "none"})}


STYLE_KEY = (
    "solid, filled: gradient-corrected; dashed, hollow: standard; triangles up / down: RK4 at CFL 1 / below, "
    "circles: Verlet at CFL 0.2, "
    "squares: Verlet at "
)
STYLE_KEY += "another CFL"


def _figure(data, ctx, name: str, title: str, xlabel: str, x_of, dx_ticks: bool):
    """One panel per scene of the study's linear accuracy runs: the error against ``x_of(run)``, a line per method
    (colour: kernel and h, :func:`_style`); ``dx_ticks``: the runs' dx as the x ticks."""
    if not data:
        return None
    panels = [(scene, methods(data["runs"], scene)) for scene in SCENES]
    panels = [(scene, found) for scene, found in panels if found]
    if not panels:
        return None
    path = ctx.out / name
    colours = kernel_colours(data["runs"])
    with F.figure(
        path,
        f"High-order SPH: {title}, linear, t = 10 s ({ctx.name}); colour: kernel and h; {STYLE_KEY}",
        xlabel,
        "relative RMS",
        ncols=len(panels),
        logx=True,
        logy=True,
        size=(6.0 * len(panels) + 3.5, 4.6),
    ) as axes:
        for ax, (scene, found) in zip(axes, panels):
            values, xs = [], []
            for (label, cfl), rs in found.items():
                pts = [(x_of(r), r["error"]) for r in rs if r["error"] and x_of(r)]
                if not pts:
                    continue
                values += [e for _, e in pts]
                xs += [x for x, _ in pts]
                ax.plot(
                    *zip(*pts),
                    color=colours[rs[0]["kernel"], rs[0]["h"]],
                    ms=5,
                    label=f"{label}, CFL {cfl:g}",
                    **_style(label, cfl),
                )
            F.nice_log_ticks(ax, values)
            if dx_ticks:
                ticks = sorted(set(xs))
                ax.set_xticks(ticks)
                ax.set_xticklabels([f"{d:g}" for d in ticks])
                ax.minorticks_off()
            else:
                F.nice_log_ticks(ax, xs, axis="x")
            ax.set_title(SCENES[scene], fontsize=9)
    return path


def orders_figure(data, ctx):
    """The error against dx of each method, plane pulse and 2D pulse (log-log)."""
    return _figure(data, ctx, "high_order_orders.png", "error against dx at fixed h / dx", "dx (m)", _dx, True)


def work_precision_figure(data, ctx):
    """The error against the time to solution (init + steps, s) of every accuracy run, plane pulse and 2D pulse."""
    title = "error against time to solution, serial; a line joins one method's runs"
    return _figure(
        data, ctx, "high_order_work_precision.png", title, "time to solution (s, init + steps)", _seconds, False
    )


def _dx(r):
    return r["dx"]


def _seconds(r):
    return r["seconds"]


SECTION = Section(
    "high-order",
    lambda ctx: rows(ctx.runs),
    text,
    (orders_figure, work_precision_figure),
    all_scenes=True,
    order=158,
    reads=(HIGH_ORDER,),
)
