"""The report's per-scene section: time to accuracy on every scene, and which model each scene needs.

Every finished run at t = 10 s of every scene (solvers/scenes/), scored by
its scene's own primary error (u for the plane pulse, drho for the 2D
pulse): ``mse`` against the exact linear solution for `linear`, and
``mse_isothermal`` against the isothermal solution for `lagrangian`. A run at
or past its predicted stable CFL (solvers/reference/dispersion.py) is never the
fastest to an accuracy, whatever its error: it ended bounded because it was
too short for round-off to grow.
"""

from __future__ import annotations

import numpy as np

from pcabench.predict.stability import past_limit, stable_cfl
from pcabench.reports.md import fmt, md_table, pct
from pcabench.reports.section import Section
from pcabench.spec import scene_from_row
from pcabench.store.rows import is_paper_method, latest, linear_floor, numerics_label
from pcabench.studies.front.figures import phase_direction, scene_fronts
from pcabench.studies.protocols import FRONT_T_END as T_FINAL  # s
from solvers import DEFAULT_SCENE, Scene, scene_kind
from solvers.method import Method

TARGETS = (0.10, 0.05, 0.02)  # relative RMS errors of the primary field
MODEL_TARGET = 0.02  # "which model this scene needs": the error against the isothermal physics asked for


def points(df) -> list[dict]:
    """Every finished run at t = 10 s with its scene, method, time to solution and error (against the
    physics its model converges to), and whether its CFL is past the predicted stable one."""
    d = df[
        (df.status == "ok") & np.isclose(df.t_final.astype(float), T_FINAL) & df.model.isin(("linear", "lagrangian"))
    ]
    out = []
    for _, r in latest(d).iterrows():
        error = r.mse if r.model == "linear" else r.mse_isothermal
        if error is None or not np.isfinite(error):
            continue
        stable = stable_cfl(r)
        out.append(
            {
                "scene": r.scene,
                "model": r.model,
                "mach": float(r.mach),
                "method": numerics_label(r),
                "kernel": r.kernel,
                "h_factor": float(r.h_factor),
                "cfl": float(r.cfl),
                "dx": float(r.dx),
                "precision": r.precision,
                "threads": int(r.threads),
                "domain": r.domain,
                "seconds": float(r.t_solution),
                "error": float(error),
                "linear_error": float(r.mse),
                "isothermal_error": None
                if r.mse_isothermal is None or not np.isfinite(r.mse_isothermal)
                else float(r.mse_isothermal),
                "paper_method": is_paper_method(r),
                "stable_cfl": stable,
                "past_stable": past_limit(r.cfl, stable),
                "front_axis": r.get("err_front_axis"),
                "front_diagonal": r.get("err_front_diagonal"),
                "commit": str(r.commit),
                "N": int(r.n_particles),
                "row": r,
            }
        )
    return out


def fastest(points_, scene: str, model: str, target: float, mach: float) -> tuple[dict | None, dict | None]:
    """(the fastest run of ``scene``/``model`` at ``mach`` reaching ``target`` and not past its stable CFL,
    the fastest of the paper's method reaching it on the same kind of domain, threads and commit)."""
    ok = [
        p
        for p in points_
        if p["scene"] == scene
        and p["model"] == model
        and np.isclose(p["mach"], mach)
        and p["error"] <= target
        and not p["past_stable"]
    ]
    if not ok:
        return None, None
    best = min(ok, key=lambda p: p["seconds"])
    paper = [
        p
        for p in ok
        if p["paper_method"]
        and p["domain"] == best["domain"]
        and p["threads"] == best["threads"]
        and p["commit"] == best["commit"]
    ]
    return best, min(paper, key=lambda p: p["seconds"]) if paper else None


def time_to_accuracy(df) -> list[dict]:
    """Per scene (its default amplitude), model and target: the fastest method, the paper's, their ratio, and
    the error the prediction gives for the fastest."""
    pts = points(df)
    rows = []
    for scene in sorted({p["scene"] for p in pts}, key=lambda s: (s != DEFAULT_SCENE, s)):
        for model in ("linear", "lagrangian"):
            for target in TARGETS:
                best, paper = fastest(pts, scene, model, target, Scene.default("mach"))
                if best is None:
                    continue
                rows.append(
                    {
                        "scene": scene,
                        "model": model,
                        "target": target,
                        "best": best,
                        "paper": paper,
                        "predicted": predicted(best["row"]),
                        "speedup": paper["seconds"] / best["seconds"] if paper else None,
                    }
                )
    return rows


def predicted(r) -> float:
    """The linear prediction of row ``r``'s primary error (solvers/reference/dispersion.py; exact for `linear`)."""
    from solvers.reference.dispersion import predict

    return predict(scene_from_row(r).replace(model="linear")).predicted_error


def model_needs(df, target: float = MODEL_TARGET) -> list[dict]:
    """Per scene and amplitude, for `linear` and `lagrangian` (the paper's method): the cheapest run within
    ``target`` of the isothermal physics, or the smallest error its runs reached; and `linear`'s floor there
    (the distance between the exact linear and isothermal solutions), which no dx removes."""
    pts = [p for p in points(df) if p["paper_method"] and p["isothermal_error"] is not None]
    rows = []
    for scene, mach in sorted({(p["scene"], p["mach"]) for p in pts}, key=lambda k: (k[0] != DEFAULT_SCENE, k)):
        row = {"scene": scene, "mach": mach, "target": target, "floor": linear_floor(scene, mach, T_FINAL)}
        for model in ("linear", "lagrangian"):
            mine = [p for p in pts if p["scene"] == scene and np.isclose(p["mach"], mach) and p["model"] == model]
            if not mine:
                row[model] = None
                continue
            hits = [p for p in mine if p["isothermal_error"] <= target]
            best = min(hits, key=lambda p: p["seconds"]) if hits else None
            row[model] = {
                "reaches": best is not None,
                "seconds": best["seconds"] if best else None,
                "dx": best["dx"] if best else None,
                "best": min(p["isothermal_error"] for p in mine),
            }
        if row.get("linear") or row.get("lagrangian"):
            rows.append(row)
    return rows


SHORT_WAVE = 8.0  # particles per wavelength of the second wavenumber drawn (k dx = 2 pi / 8)


def phase_directions(methods, angles=np.linspace(0.0, np.pi / 4, 19)) -> list[dict]:
    """The predicted phase speed error (with the step) against the direction of travel for each method
    (dicts of kernel, h_factor, cfl, dx), at the 2D pulse's wavenumber 1 / b and at a short wave of
    ``SHORT_WAVE`` particles per wavelength, where the lattice's anisotropy shows."""
    from solvers.reference.dispersion import phase_errors

    out = []
    for m in methods:
        scene = Scene(
            dx=m["dx"],
            name="acoustic-pulse",
            kernel=m["kernel"],
            h_factor=m["h_factor"],
            cfl=m["cfl"],
            model="linear",
            t_end=T_FINAL,
        )
        short = scene.replace(pulse_width=SHORT_WAVE * scene.dx / (2 * np.pi))  # k = 1 / width
        out.append(
            {
                **m,
                "angles": np.degrees(angles),
                "error": [phase_errors(scene, a)[1] for a in angles],
                "short": [phase_errors(short, a)[1] for a in angles],
            }
        )
    return out


def front_shifts(points_, most: int = 12) -> list[dict]:
    """The 2D runs' wave front speed error along the lattice's axis and its diagonal, measured and predicted
    (the same measure on the predicted fields), for the fastest `linear` runs of the 2D scenes."""
    runs = sorted(
        (
            p
            for p in points_
            if p["scene"] != DEFAULT_SCENE
            and p["model"] == "linear"
            and not p["past_stable"]
            and p["front_axis"] is not None
            and np.isfinite(p["front_axis"])
        ),
        key=lambda p: p["seconds"],
    )[:most]
    out = []
    for p in runs:
        from solvers.reference.dispersion import predict

        measures = predict(scene_from_row(p["row"]).replace(model="linear")).measures or {}
        out.append(
            {
                "method": p["method"],
                "dx": p["dx"],
                "measured": (p["front_axis"], p["front_diagonal"]),
                "predicted": (measures.get("front_axis"), measures.get("front_diagonal")),
            }
        )
    return out


def rows(ctx):
    df = ctx.df_scenes if ctx.df_scenes is not None else ctx.df
    if df.empty or set(df.scene) == {Scene.default("name")} and not (df.mach != Scene.default("mach")).any():
        return None  # the paper's scene only, at its amplitude: the sections above say it all
    pts = points(df)
    rows = time_to_accuracy(df)
    methods = {}
    for r in rows:
        if scene_kind(r["scene"]).dims != 2:
            continue  # the phase's direction is drawn on the square lattice: the 2D scenes' methods
        for p in (r["best"], r["paper"]):
            if p is not None:
                methods.setdefault(
                    (p["kernel"], p["h_factor"], p["cfl"]),
                    {
                        "kernel": p["kernel"],
                        "h_factor": p["h_factor"],
                        "cfl": p["cfl"],
                        "dx": 0.25,
                        "label": f"{p['method']}" + (" (paper's)" if p["paper_method"] else ""),
                    },
                )
    return {
        "points": pts,
        "fastest": rows,
        "needs": model_needs(df),
        "phase": phase_directions(list(methods.values())),
        "fronts": front_shifts(pts),
    }


def text(data, ctx) -> list[str]:
    if not data:
        return []
    rows = [
        [
            r["scene"],
            r["model"],
            pct(r["target"]),
            r["best"]["method"],
            fmt(r["best"]["dx"], "g"),
            fmt(r["best"]["seconds"], ".3g"),
            pct(r["best"]["error"]),
            pct(r["predicted"]),
            f"{r['best']['cfl'] / r['best']['stable_cfl']:.2f}" if r["best"]["stable_cfl"] else "-",
            fmt(r["paper"]["dx"], "g") if r["paper"] else "-",
            fmt(r["paper"]["seconds"], ".3g") if r["paper"] else "-",
            fmt(r["speedup"], ".3g") if r["speedup"] else "-",
        ]
        for r in data["fastest"]
    ]
    lines = [
        "## Time to accuracy on each scene",
        "",
        f"Every finished run at t = {T_FINAL:g} s of every scene (solvers/scenes/; `pcabench study --front "
        "--scene NAME`), at the scene's default amplitude, Mach 0.05. The error is the scene's primary field "
        "(u for the plane pulse, drho for the 2D acoustic pulse), relative RMS, against the exact linear "
        "solution for `linear` and the isothermal solution for `lagrangian`. A run at or past its predicted "
        "stable CFL is never picked, whatever its error (it was too short for round-off to grow). The "
        "prediction (`pcabench accuracy --scene NAME`) is exact for `linear` on a periodic scene; for "
        "`lagrangian` it is the linear part only. Times on this machine, serial unless labelled.",
        "",
        md_table(
            [
                "scene",
                "model",
                "target",
                "fastest method",
                "dx",
                "time (s)",
                "error",
                "predicted",
                "CFL / stable",
                "paper's method: dx",
                "time (s)",
                "paper / fastest",
            ],
            rows,
        )
        if rows
        else "No run of a scene at t = 10 s reaches 10 %.",
        "",
    ]
    by_target = {}
    for r in data["fastest"]:
        if scene_kind(r["scene"]).walls:
            continue  # the question is the free pulse's, plane against 2D; the walls have a section of their own
        by_target.setdefault((r["model"], r["target"]), {})[r["scene"]] = r["best"]["method"]
    both = {k: v for k, v in by_target.items() if len(v) > 1}
    if both:
        differ = [
            f"{m} to {pct(t)} ({'; '.join(f'{s}: {meth}' for s, meth in sorted(v.items()))})"
            for (m, t), v in sorted(both.items())
            if len(set(v.values())) > 1
        ]
        three_d = any(scene_kind(s).dims == 3 for v in both.values() for s in v)
        lines += [
            f"Does the method fastest on the plane pulse stay fastest in 2D{' and 3D' if three_d else ''}? In "
            f"{len(both) - len(differ)} of {len(both)} (model, target) pairs "
            f"{'every scene names' if any(len(v) > 2 for v in both.values()) else 'both scenes name'} the same method"
            + (f"; they differ for {', '.join(differ)}." if differ else "."),
            "",
        ]
    needs = [
        [
            r["scene"],
            fmt(r["mach"], "g"),
            pct(r["target"]),
            pct(r["floor"]),
            *(
                (
                    "-"
                    if r.get(model) is None
                    else f"{fmt(r[model]['seconds'], '.3g')} s (dx {fmt(r[model]['dx'], 'g')})"
                    if r[model]["reaches"]
                    else f"not reached (best {pct(r[model]['best'])})"
                )
                for model in ("linear", "lagrangian")
            ),
            "linear suffices"
            if r["floor"] is not None and r["floor"] < r["target"]
            else "lagrangian (linear's floor is above the target)",
        ]
        for r in data["needs"]
    ]
    if needs:
        lines += [
            "### Which model this scene needs",
            "",
            f"The paper's method ({Method.paper().words}) at several amplitudes, every "
            "model scored against the isothermal physics (the equations the paper's moving particles "
            "solve): the cheapest run within the target, or the smallest error its runs reached. `linear`'s "
            "floor is the distance between the exact linear and the isothermal solutions at t = 10 s (no "
            "dx removes it; it grows with the amplitude and the time): where it is below the target the "
            "linear model is all the scene needs.",
            "",
            md_table(["scene", "Mach", "target", "linear's floor", "linear", "lagrangian", "the scene needs"], needs),
            "",
        ]
    if data["phase"]:
        spread = [abs(c["error"][0] - c["error"][-1]) for c in data["phase"]]
        short = [abs(c["short"][0] - c["short"][-1]) for c in data["phase"]]
        lines += [
            "The lattice's phase error depends on the direction of travel. `phase_direction.png` draws, for "
            "the 2D scenes' methods of the table, the predicted phase speed error (lattice and step together) at the "
            "2D pulse's wavenumber 1/b from the lattice's axis (0 degrees) to its diagonal (45 degrees) at "
            f"dx = 0.25 m: axis and diagonal differ by at most {100 * max(spread):.3g} % of c0 there, far "
            "less than the lag itself; for a short wave of 8 particles per wavelength by up to "
            f"{100 * max(short):.3g} %. Beside it, the 2D runs' wave front speed error along the axis and "
            "along the diagonal (the outgoing peak of drho against the exact one's, over c0 t), measured "
            "against the same measure on the predicted fields; each run also stores its relative RMS error "
            "along the axes and the diagonals apart (`err_axis_rms`, `err_diagonal_rms`).",
            "",
        ]
    return lines


SECTION = Section(
    "scenes",
    rows,
    text,
    (
        lambda d, ctx: scene_fronts(d["points"], ctx.out, ctx.name) if d else None,
        lambda d, ctx: phase_direction(d["phase"], d["fronts"], ctx.out, ctx.name) if d else None,
    ),
    all_scenes=True,
    order=140,
)
