"""The report's "Sound around an object" section (``pcabench study --cylinder``): the CAA workshop's pulse scattered
by a rigid cylinder, each boundary method's error at the workshop's points A, B, C over 6 <= t <= 10 s and near
the body against dx and the kernel, the order it converges at, lagrangian beside linear, the stable CFL with the
body, and p(t) at A, B, C beside the exact solution, the way the workshop drew them.

The measures are the scene's (solvers/scenes/cylinder.py): ``probe_rms`` (A, B, C together) and ``probe_A`` ...,
the relative RMS of p = c0^2 drho over the window; ``near_rms`` and ``far_rms``, the field's error at the run's
end within 3 cutoffs of the surface and away from it, each over the RMS of the reference over the whole fluid.
"""

from __future__ import annotations

import json
import math
from functools import lru_cache

import numpy as np

from pcabench.predict.stability import stable_cfl
from pcabench.reports import figures as F
from pcabench.reports.md import fmt, md_table
from pcabench.reports.section import Section, stored_measure
from pcabench.spec import scene_from_row
from pcabench.store.rows import latest
from pcabench.studies.cylinder.plan import CYLINDER, CYLINDER_T_END
from solvers.method import Method
from solvers.reference import dispersion

TARGET = 0.02  # the issue's: 2 % relative RMS at the probes
TARGET_DX = 0.02  # at no more than 10 particles a pulse width
# a boundary method's line and marker (the predictions are dotted)
WALL_STYLE = {"lattice": "-", "rings": "--", "weak": "-.", "cut": (0, (6, 2, 1, 2, 1, 2))}
WALL_MARKER = {"lattice": "o", "rings": "s", "weak": "^", "cut": "D"}
WALL_COLOUR = {"lattice": "tab:blue", "rings": "tab:orange", "weak": "tab:green", "cut": "tab:red"}
# the prediction's dx (the wall exact, the bulk's dispersion alone: solvers/reference/dispersive_cylinder.py), to
# four times finer than the finest run: where each method would go, and where it floors
PREDICTED_DX = (0.04, 0.02, 0.01, 0.005, 0.0025)


@lru_cache(maxsize=256)
def predicted(scene) -> float:
    """The probes' error the bulk's dispersion alone gives ``scene`` (linear, the wall exact): about 1 s."""
    scene = scene.replace(model="linear", boundary_method="")
    return float(scene.kind.predict_headline(scene).predicted_error)


def rows(df) -> dict | None:
    """The cylinder runs of ``df`` (newest of each), one row each, with the orders between successive dx; None
    where there are none."""
    if df is None or df.empty or not (df.scene == CYLINDER).any():
        return None
    runs = []
    for _, r in latest(df[df.scene == CYLINDER]).iterrows():
        scene = scene_from_row(r)
        runs.append(
            {
                "dx": float(scene.dx),
                "per_width": scene.pulse_width / scene.dx,
                "method": scene.boundary_method_used,
                "kernel": scene.kernel,
                "h": float(scene.h_factor),
                "label": Method.of(scene).numerics,
                "model": scene.model,
                "cfl": float(scene.cfl),
                "t_end": float(scene.t_final),
                "status": r.status,
                "failed_step": r.failed_step,
                "probes": stored_measure(r, "probe_rms"),
                **{k: stored_measure(r, f"probe_{k}") for k in "ABC"},
                "near": stored_measure(r, "near_rms"),
                "far": stored_measure(r, "far_rms"),
                "N": int(r.n_particles),
                "step_ms": 1e3 * float(r.t_step) if r.status == "ok" else None,
                "wall_s": float(r.t_solution) if r.status == "ok" else None,
                "series": json.loads(r.probes) if isinstance(r.get("probes"), str) else {},
                "scene_value": scene,
                "predicted": predicted(scene) if scene.model == "linear" and r.status == "ok" else None,
            }
        )
    runs.sort(key=lambda r: (r["model"], r["kernel"], r["h"], r["method"], r["cfl"], -r["dx"]))
    return {"runs": runs, "orders": orders(runs)}


def _key(r) -> tuple:
    return (r["model"], r["label"], r["method"], r["cfl"])


def orders(runs) -> list[dict]:
    """Per method (model, kernel, h, boundary method, CFL) with two or more dx: the order of the probes' error
    and of the near-body error between each pair of successive dx, log(e1 / e2) / log(dx1 / dx2)."""
    out = []
    runs = [r for r in runs if np.isclose(r["t_end"], CYLINDER_T_END)]  # the long runs are the limit's, not the order's
    for key in sorted({_key(r) for r in runs}):
        mine = sorted((r for r in runs if _key(r) == key and r["status"] == "ok"), key=lambda r: -r["dx"])
        for a, b in zip(mine, mine[1:]):
            step = math.log(a["dx"] / b["dx"])
            o = {"key": key, "dx": (a["dx"], b["dx"])}
            for what in ("probes", "near"):
                ea, eb = a[what], b[what]
                o[what] = math.log(ea / eb) / step if ea and eb else None
            out.append(o)
    return out


def wall_share(r) -> float | None:
    """The wall's share of a linear run's probes' error, sqrt(probes^2 - predicted^2) (the bulk's, ``predicted``,
    and the wall's taken as independent; 0 where the run is at or below the prediction); None where either is
    missing."""
    if r["probes"] is None or r["predicted"] is None:
        return None
    return math.sqrt(max(r["probes"] ** 2 - r["predicted"] ** 2, 0.0))


def limited_by(r) -> str:
    """Which error limits a linear run at the probes: ``wall`` where the wall's share (:func:`wall_share`) is the
    larger, else ``bulk`` (the method's dispersion, the prediction with the wall exact); "-" where unknown."""
    share = wall_share(r)
    if share is None:
        return "-"
    return "wall" if share > r["predicted"] else "bulk"


def _step(r) -> str:
    v = r["failed_step"]
    return "-" if v is None or (isinstance(v, float) and not np.isfinite(v)) else f"{int(v)}"


def _method(r) -> str:
    return r["label"]


def text(data, ctx) -> list[str]:
    if not data:
        return []
    runs = [r for r in data["runs"] if np.isclose(r["t_end"], CYLINDER_T_END)]
    table = [
        [
            f"{r['dx']:g}",
            f"{r['per_width']:.3g}",
            _method(r),
            r["method"],
            r["model"],
            f"{r['cfl']:g}",
            f"{r['N']:,}",
            fmt(r["probes"], ".3g") if r["status"] == "ok" else f"{r['status']} (step {_step(r)})",
            fmt(r["predicted"], ".3g"),
            fmt(wall_share(r), ".2g"),
            limited_by(r),
            " / ".join(fmt(r[k], ".3g") for k in "ABC") if r["status"] == "ok" else "-",
            fmt(r["near"], ".3g"),
            fmt(r["far"], ".3g"),
            fmt(r["step_ms"], ".1f"),
        ]
        for r in runs
    ]
    lines = [
        "## Sound around an object",
        "",
        "The Second CAA Workshop's category 1 problem 2 (`--scene cylinder`): the pulse b = 0.2 m at (4, 0) "
        "scattered by a rigid cylinder of radius 0.5 m at the origin, in the open square [-6, 6]^2 m, scored "
        "against the series solution. The wall is a boundary method: ghost particles inside the body with the "
        "fluid's values at their mirror points (`lattice`: the lattice's own sites, a staircase; `rings`: rings "
        "fitted to the surface) or none (`weak`: the body's sites carry no volume and the kernel gradient "
        "correction's energy-keeping operators make the wall, u . n = 0 weakly; the high-order method's, "
        "solvers/boundaries/bodies/weak.py; `cut`: the same with the sites the surface cuts carrying their "
        "cells' fluid "
        "volume, solvers/boundaries/bodies/cut.py). Probes: the relative RMS of p at the workshop's points A (r "
        "= 5 m, 90 deg), B "
        "(135 deg), C (180 deg) over 6 <= t <= 10 s, together and each; near the body (within 3 cutoffs of its "
        "surface) and away from it: the field's error at t = 10 s. Predicted: the probes' error the bulk's "
        "dispersion alone gives, the series solution with each wavenumber evolved by the method's own (its "
        "kernel's and its step's) instead of cos(c0 k t), the wall exact (`pcabench accuracy --scene cylinder`); "
        "the wall's share: sqrt(probes^2 - predicted^2), the two taken as independent; limited by: the larger "
        "share. `pcabench study --cylinder` (and `--cylinder wall`: cut cells, the sixth-order kernel), linked "
        "list, serial.",
        "",
        md_table(
            [
                "dx (m)",
                "particles per b",
                "kernel",
                "boundary method",
                "model",
                "CFL",
                "N",
                "probes",
                "predicted (wall exact)",
                "wall's share",
                "limited by",
                "A / B / C",
                "near the body",
                "away from it",
                "step (ms)",
            ],
            table,
        ),
        "",
    ]
    ok = [r for r in runs if r["status"] == "ok" and r["probes"] is not None and r["model"] == "linear"]
    if ok:
        coarse = [r for r in ok if r["dx"] >= TARGET_DX - 1e-12]
        best = min(coarse or ok, key=lambda r: r["probes"])
        reached = [r for r in ok if r["probes"] <= TARGET]
        lines.append(
            f"- **The issue's target** (2 % at the probes with at most 10 particles a pulse width): the best linear "
            f"run at dx >= {TARGET_DX:g} m has {best['probes']:.3g} ({_method(best)}, {best['method']}, dx = "
            f"{best['dx']:g} m): "
            + (
                "reached."
                if best["probes"] <= TARGET
                else "not reached by any method here"
                + (
                    f" (the finest run that does: dx = {min(r['dx'] for r in reached):g} m)."
                    if reached
                    else "; the error is the bulk's dispersion over 5 to 9 m of travel (the free pulse at this "
                    "width shows the same, docs/accuracy.md), not the wall's."
                )
            )
        )
        for key, pts in predicted_curves(ok).items():
            label, cfl = key
            reach = [dx for dx, e in pts if e <= TARGET]
            scene = next(r["scene_value"] for r in ok if (r["label"], r["cfl"]) == key)
            limit = stable_cfl(scene.replace(model="linear"))
            past = (
                f" (at or past CFL {limit:g}, where long runs of this scene blew up: bounded only to t = 10 s)"
                if cfl >= limit
                else ""
            )
            lines.append(
                f"- **Predicted, {label}, CFL {cfl:g}**{past} (the wall exact): "
                + ", ".join(f"{e:.3g} at dx {dx:g}" for dx, e in pts)
                + (
                    f"; 2 % from dx {max(reach):g} m ({scene.pulse_width / max(reach):.3g} particles a pulse width)."
                    if reach
                    else f"; 2 % not by dx {PREDICTED_DX[-1]:g} m (the kernel's long-wave phase-speed deficit at "
                    "fixed h / dx, which refinement keeps, floors it: docs/accuracy.md)."
                )
            )
        for o in data["orders"]:
            model, label, method, cfl = o["key"]
            lines.append(
                f"- **{label}, CFL {cfl:g}, {method}, {model}**: converges from dx {o['dx'][0]:g} to "
                f"{o['dx'][1]:g} "
                f"at order {fmt(o['probes'], '.2g')} at the probes and {fmt(o['near'], '.2g')} near the body."
            )
    moving = [r for r in runs if r["model"] != "linear" and r["status"] == "ok"]
    if moving:
        lines.append(
            "- **The lagrangian runs** are scored against the exact *linear* solution (no isothermal one is known "
            "with a body): at Mach 0.05 the pulse of width 0.2 m steepens over a few metres, so their error holds "
            "the model's nonlinear terms, not only the method's; they are not beside the linear runs like for like."
        )
    blown = [r for r in runs if r["status"] != "ok"]
    for key in sorted({(_method(r), r["method"], r["model"], r["dx"]) for r in blown}):
        mine = sorted(
            (r for r in blown if (_method(r), r["method"], r["model"], r["dx"]) == key), key=lambda r: r["cfl"]
        )
        held = [r["cfl"] for r in runs if r["status"] == "ok" and (_method(r), r["method"], r["model"], r["dx"]) == key]
        lines.append(
            f"- **{key[0]}, {key[1]}, {key[2]}, dx {key[3]:g}**: "
            + ", ".join(f"CFL {r['cfl']:g} {r['status']} at step {_step(r)}" for r in mine)
            + (f"; bounded up to CFL {max(held):g}." if held else ".")
        )
    long = sorted((r for r in data["runs"] if r["t_end"] > CYLINDER_T_END), key=lambda r: (_method(r), r["cfl"]))
    for key in sorted({(_method(r), r["method"], r["dx"], r["t_end"]) for r in long}):
        mine = [r for r in long if (_method(r), r["method"], r["dx"], r["t_end"]) == key]
        lines.append(
            f"- **Long runs, {key[0]}, {key[1]}, dx {key[2]:g}, to t = {key[3]:g} s** (the stable CFL with the open "
            "edges): "
            + ", ".join(
                f"CFL {r['cfl']:g} " + ("bounded" if r["status"] == "ok" else f"{r['status']} at step {_step(r)}")
                for r in mine
            )
            + "; the periodic lattice's predicted limit is "
            + f"{dispersion.predicted_stable_cfl(mine[0]['scene_value']):.3g}."
        )
    return lines + [""]


def predicted_curves(runs) -> dict:
    """{(method label, CFL): [(dx, predicted probes' error)]} on PREDICTED_DX for each linear method of ``runs``
    run at two dx or more (the stability scan's single runs are not a method's curve)."""
    out = {}
    for key in sorted({(r["label"], r["cfl"]) for r in runs}):
        mine = [r for r in runs if (r["label"], r["cfl"]) == key]
        if len({r["dx"] for r in mine}) < 2:
            continue
        out[key] = [(dx, predicted(mine[0]["scene_value"].replace(dx=dx))) for dx in PREDICTED_DX]
    return out


def _exact(scene, series) -> tuple:
    """(t, {name: exact p}) at the stored probe times."""
    t = np.asarray(series["t"], dtype=np.float64)
    ref = scene.kind.reference(scene, float(t.max()))
    points = scene.probe_points()
    return t, {k: ref.drho(np.array([points[k][0]]), np.array([points[k][1]]), t)[:, 0] for k in "ABC"}


def probes_figure(data, ctx):
    """p(t) at A, B and C over the workshop's window: the exact solution (black) beside each boundary method's
    run of the most accurate method and dx run with more than one wall (else the most accurate run), linear."""
    if not data:
        return None
    ok = [r for r in data["runs"] if r["status"] == "ok" and r["probes"] is not None and r["series"].get("t")]
    ok = [r for r in ok if r["model"] == "linear" and np.isclose(r["t_end"], CYLINDER_T_END)]
    if not ok:
        return None
    held = [r for r in ok if r["cfl"] < stable_cfl(r["scene_value"].replace(model="linear"))]
    ok = held or ok  # a run past the limit long runs measured is bounded only because it is short: not shown first
    same = ("dx", "label", "cfl")
    groups: dict = {}
    for r in ok:
        groups.setdefault(tuple(r[k] for k in same), []).append(r)
    walls = [g for g in groups.values() if len({r["method"] for r in g}) > 1]  # where the walls differ, side by side
    shown = min(walls or groups.values(), key=lambda g: min(r["probes"] for r in g))
    best = min(shown, key=lambda r: r["probes"])
    path = ctx.out / "cylinder_probes.png"
    t, exact = _exact(best["scene_value"], best["series"])
    window = (t >= 6.0 - 1e-9) & (t <= 10.0 + 1e-9)
    c2 = best["scene_value"].c0 ** 2
    with F.figure(
        path,
        f"The pulse scattered by a cylinder: p(t) at the workshop's points, {_method(best)}, CFL {best['cfl']:g}, "
        f"dx = {best['dx']:g} m "
        f"({best['per_width']:.3g} particles a pulse width), linear ({ctx.name}); black: the exact solution",
        "t (s)",
        "p (Pa, c0^2 drho)",
        ncols=3,
        size=(15.5, 4.4),
    ) as axes:
        for ax, name in zip(axes, "ABC"):
            ax.plot(t[window], c2 * exact[name][window], color="black", lw=2.0, label="exact")
            for r in shown:
                tr = np.asarray(r["series"]["t"])
                w = (tr >= 6.0 - 1e-9) & (tr <= 10.0 + 1e-9)
                ax.plot(
                    tr[w],
                    c2 * np.asarray(r["series"][name])[w],
                    color=WALL_COLOUR.get(r["method"], "tab:green"),
                    lw=1.2,
                    ls=WALL_STYLE.get(r["method"], "-"),
                    label=f"{r['method']} (probes {r['probes']:.2g})",
                )
            ax.set_title(f"{name} ({ {'A': '90', 'B': '135', 'C': '180'}[name] } deg, r = 5 m)", fontsize=9)
    return path


def error_figure(data, ctx):
    """The probes' error and the near-body error against dx, per kernel and boundary method (linear)."""
    if not data:
        return None
    ok = [r for r in data["runs"] if r["status"] == "ok" and r["model"] == "linear" and r["probes"] is not None]
    ok = [r for r in ok if np.isclose(r["t_end"], CYLINDER_T_END)]  # the long runs measure the limit, not the error
    curves = predicted_curves(ok)
    ok = [r for r in ok if (r["label"], r["cfl"]) in curves]  # methods run at two dx or more
    if not ok:
        return None
    path = ctx.out / "cylinder_error.png"
    kernels = list(curves)
    colours = F.palette(len(kernels))
    past_limit = {
        key: " (past the long runs' limit)"
        if key[1] >= stable_cfl(next(r for r in ok if (r["label"], r["cfl"]) == key)["scene_value"])
        else ""
        for key in kernels
    }
    with F.figure(
        path,
        f"Sound around a cylinder: error against dx, linear ({ctx.name}); colour: method; solid, circles: lattice "
        "ghosts; dashed, squares: rings; dash-dot, triangles: the weak wall's staircase; dash-dot-dot, diamonds: its "
        "cut cells; dotted, crosses: predicted (the wall exact); grey: the 2 % target",
        "dx (m)",
        "relative RMS",
        ncols=2,
        logx=True,
        logy=True,
        size=(13.0, 4.6),
    ) as axes:
        values = {0: [TARGET], 1: []}
        for i, (what, title) in enumerate(
            (
                ("probes", "at the probes A, B, C, 6 <= t <= 10 s"),
                ("near", "near the body (within 3 cutoffs), t = 10 s"),
            )
        ):
            ax = axes[i]
            for (label, cfl), colour in zip(kernels, colours):
                for method in WALL_STYLE:
                    pts = sorted(
                        (r["dx"], r[what])
                        for r in ok
                        if (r["label"], r["cfl"], r["method"]) == (label, cfl, method) and r[what]
                    )
                    if pts:
                        values[i] += [v for _, v in pts]
                        ax.plot(
                            *zip(*pts),
                            color=colour,
                            ls=WALL_STYLE[method],
                            marker=WALL_MARKER[method],
                            ms=4,
                            label=f"{label}, CFL {cfl:g}, {method}" + past_limit[label, cfl],
                        )
                if i == 0:
                    pts = curves[label, cfl]
                    values[i] += [v for _, v in pts]
                    ax.plot(*zip(*pts), color=colour, ls=":", lw=1.5, marker="x", ms=4)
            if i == 0:
                ax.plot([], [], color="0.3", ls=":", marker="x", ms=4, label="dotted: predicted (the wall exact)")
                ax.axhline(TARGET, color="0.6", lw=1.0, label="target: 2 %")
            F.nice_log_ticks(ax, values[i])
            ticks = sorted(set(PREDICTED_DX) if i == 0 else {r["dx"] for r in ok})
            ax.set_xticks(ticks)
            ax.set_xticklabels([f"{d:g}" for d in ticks])
            ax.minorticks_off()
            ax.set_title(title, fontsize=9)
    return path


SECTION = Section(
    "cylinder",
    lambda ctx: rows(ctx.every_run()),
    text,
    (probes_figure, error_figure),
    all_scenes=True,
    order=157,
)
