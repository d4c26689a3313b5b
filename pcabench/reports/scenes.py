"""Rows of the report's per-scene sections: time to accuracy on every scene, and which model each scene needs.

Every finished run at t = 10 s of every scene (solvers/scenes/), scored by
its scene's own primary error (u for the plane pulse, drho for the 2D
pulse): ``mse`` against the exact linear solution for `linear`, and
``mse_isothermal`` against the isothermal solution for `lagrangian`. A run at
or past its predicted stable CFL (solvers/dispersion.py) is never the
fastest to an accuracy, whatever its error: it ended bounded because it was
too short for round-off to grow.
"""

from __future__ import annotations

from functools import lru_cache

import numpy as np

from pcabench.spec import scene_from_row
from pcabench.stability import past_limit, stable_limit
from solvers import DEFAULT_SCENE, Scene

from .tables import is_paper_method, latest, numerics_label

TARGETS = (0.10, 0.05, 0.02)  # relative RMS errors of the primary field
T_FINAL = 10.0  # s
MODEL_TARGET = 0.02  # "which model this scene needs": the error against the isothermal physics asked for


def stable_cfl_of(r) -> float:
    """The largest stable CFL of row ``r``'s method (pcabench/stability.py: the prediction, or the lower limit
    long runs measured for a moving model)."""
    return stable_limit(r)


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
        stable = stable_cfl_of(r)
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
    """The linear prediction of row ``r``'s primary error (solvers/dispersion.py; exact for `linear`)."""
    from solvers.dispersion import predict

    return predict(scene_from_row(r).replace(model="linear")).predicted_error


@lru_cache(maxsize=256)
def linear_floor(name: str, mach: float, t_final: float) -> float | None:
    """The `linear` model's error floor against the isothermal physics (exact linear against isothermal
    solution, no discretisation) for scene ``name`` at ``mach`` and ``t_final``, on a 0.1 m lattice."""
    scene = Scene(dx=0.1, name=name, mach=mach, t_end=t_final, model="linear")
    return scene.kind.linear_floor(scene)


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
    from solvers.dispersion import phase_errors

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
        from solvers.dispersion import predict

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
