"""The front study's figures: time to solution against error (the work-precision diagram) on the paper's scene
and on every scene kind, and the phase error by direction."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from pcabench.reports.figures import (
    MODEL_COLOUR,
    TAB10,
    channels,
    figure,
    groups,
    nice_log_ticks,
    palette,
)
from pcabench.studies.front.rows import FRONT_MODELS, predicted_error
from solvers import kernel_names, scene_kind
from solvers.method import Method


def kernel_colour(kernel: str) -> str:
    """A kernel's colour by its place in the registry (the Gaussian, the paper's, blue; the others in the
    registry's order); grey for a stored kernel not registered here."""
    names = kernel_names()
    return TAB10[names.index(kernel) % len(TAB10)] if kernel in names else "grey"


def speed_vs_accuracy(points, front, out: Path, pid: str):
    """Time to solution against error at the time most runs ended at, one panel per model: every run (colour:
    kernel; hollow: float32), the paper's method starred, each model's front, and the prediction beside it."""
    if not points:
        return None
    times = [p["t_final"] for p in points]
    t_main = max(set(times), key=times.count)  # one physical time: the one most runs ended at (10 s in the presets)
    panels = [
        (t_main, m)
        for m in FRONT_MODELS  # a few points are no front
        if sum((q["t_final"], q["model"]) == (t_main, m) for q in points) >= 4
    ]
    if not panels:
        return None
    here_all = [p for p in points if (p["t_final"], p["model"]) in panels]
    key = channels(
        colour=("kernel", [p["kernel"] for p in here_all]),
        **{"hollow triangle": ("float32", [p["precision"] for p in here_all])},
    )
    path = out / "speed_vs_accuracy.png"
    with figure(
        path,
        f"Time to solution against error ({pid}){key}; black line: the fastest run to each error",
        "time to solution (s: init + steps, no JIT)",
        "relative RMS error of u at t (lagrangian: vs isothermal)",
        ncols=len(panels),
        logx=True,
        logy=True,
        size=(5.2 * len(panels) + 3.8, 4.6),
    ) as axes:
        for ax, (t_final, model) in zip(axes, panels):
            here = [p for p in points if (p["t_final"], p["model"]) == (t_final, model)]
            for (kern, precision), pts in groups([p for p in here if not p.get("past_limit")], ("kernel", "precision")):
                colour = kernel_colour(kern)
                single = precision == "float32"  # a hollow triangle over the filled float64 circle: both show
                ax.plot(
                    [p["seconds"] for p in pts],
                    [p["error"] for p in pts],
                    ls="none",
                    marker="^" if single else "o",
                    ms=6.5 if single else 4.5,
                    color=colour,
                    mfc="none" if single else colour,
                    mew=1.0,
                    alpha=0.85 if single else 0.7,
                    zorder=4 if single else 3,
                    label=f"{kern}, {precision}",
                )
            past = [p for p in here if p.get("past_limit")]
            if past:
                ax.plot(
                    [p["seconds"] for p in past],
                    [p["error"] for p in past],
                    ls="none",
                    marker="X",
                    ms=6,
                    mfc="none",
                    mec="tab:purple",
                    mew=1.0,
                    label="unstable by prediction (CFL at or past its stable CFL), any kernel: never on the front",
                )
            paper = [p for p in here if p["paper_method"]]
            ax.plot(
                [p["seconds"] for p in paper],
                [p["error"] for p in paper],
                ls="none",
                marker="*",
                ms=15,
                mfc="gold",  # a halo under the run's own circle and triangle: both stay in sight
                mec="black",
                mew=0.8,
                zorder=1.5,
                label=f"the paper's method ({Method.paper().words}): under its runs' marks",
            )
            fp = [p for p in front if (p["t_final"], p["model"]) == (t_final, model)]
            ax.step(
                [p["seconds"] for p in fp],
                [p["error"] for p in fp],
                color="black",
                where="post",
                lw=1.3,
                label="front: fastest run to each error",
            )
            ax.step(  # a dashed line, not marks: the runs under it stay in sight
                [p["seconds"] for p in fp],
                [predicted_error(p) for p in fp],
                color="crimson",
                where="post",
                lw=1.1,
                ls="--",
                zorder=2,
                label="the front runs' error, predicted (dispersion relation, linear part)",
            )
            ax.set_title(f"{model}, t = {t_final:g} s ({len(here)} runs)", fontsize=9)
            # plain ticks: a narrow log range would label its minor ticks too, and they collide
            nice_log_ticks(ax, [p["seconds"] for p in here], axis="x")
            nice_log_ticks(ax, [p["error"] for p in here] + [predicted_error(p) for p in fp], axis="y")
    return path


FRONT_PANEL_RUNS = 8  # a scene's panel needs this many runs at the default amplitude: fewer draw no front


def front_of(pts: list[dict]) -> list[dict]:
    """The runs no faster run beats in error (the lower-left envelope), fastest first; runs past their stable
    CFL are never on it."""
    front, best = [], np.inf
    for p in sorted((p for p in pts if not p["past_stable"]), key=lambda p: (p["seconds"], p["error"])):
        if p["error"] < best:
            front.append(p)
            best = p["error"]
    return front


def scene_fronts(points, out: Path, pid: str):
    """Time to solution against error, one panel per scene at its default amplitude (t = 10 s) with at least
    FRONT_PANEL_RUNS runs: each model a colour, its front a step line, runs past their predicted stable CFL
    drawn as crosses (never on a front). A scene with fewer runs (the walls: their own figure) has no panel."""
    counts = {}
    for p in points:
        if np.isclose(p["mach"], 0.05):
            counts[p["scene"]] = counts.get(p["scene"], 0) + 1
    scenes = sorted((s for s, n in counts.items() if n >= FRONT_PANEL_RUNS), key=lambda s: (s != "plane-pulse", s))
    if len(scenes) < 2:
        return None
    path = out / "scene_fronts.png"
    past = " x: past the predicted stable CFL," if any(p["past_stable"] for p in points) else ""
    ncols = min(len(scenes), 2)
    nrows = -(-len(scenes) // ncols)
    with figure(
        path,
        f"Time to solution against error on each scene, t = 10 s, Mach 0.05 ({pid});{past} colour: model; "
        "each stepped line is a model's front (no faster run has a smaller error)",
        "time to solution, s",
        "relative RMS error",
        ncols=ncols,
        nrows=nrows,
        logx=True,
        logy=True,
        size=(6.0 * ncols + 2.5, 4.3 * nrows),
    ) as axes:
        for ax in axes[len(scenes) :]:
            ax.set_axis_off()  # a spare panel: no labels either (the figure's frame skips an axes that is off)
        for ax, scene in zip(axes, scenes):
            mine = [p for p in points if p["scene"] == scene and np.isclose(p["mach"], 0.05)]
            for model in ("linear", "lagrangian"):
                for past in (False, True):
                    pts = [p for p in mine if p["model"] == model and p["past_stable"] == past]
                    if not pts:
                        continue
                    ax.scatter(
                        [p["seconds"] for p in pts],
                        [p["error"] for p in pts],
                        s=14 if not past else 22,
                        marker="x" if past else "o",
                        color=MODEL_COLOUR[model],
                        alpha=0.55 if not past else 0.5,
                        label=f"{model}" + (" (past the stable CFL)" if past else ""),
                    )
                line = front_of([p for p in mine if p["model"] == model])
                if len(line) > 1:
                    ax.step(
                        [p["seconds"] for p in line],
                        [p["error"] for p in line],
                        where="post",
                        color=MODEL_COLOUR[model],
                        lw=1.6,
                        label=f"{model} front",
                    )
            errors = [p["error"] for p in mine]
            nice_log_ticks(ax, errors)
            nice_log_ticks(ax, [p["seconds"] for p in mine], axis="x")
            ax.set_ylabel(f"relative RMS error of {scene_kind(scene).primary}")
            ax.set_title(scene, fontsize=9)
    return path


def phase_direction(curves, fronts, out: Path, pid: str):
    """The lattice's anisotropy: the predicted phase speed error's change from its value along the axis, against
    the direction of travel, one colour per method, at the pulse's wavenumber and at a short wave (a panel
    each); where 2D runs stored it, their wave front speed error along the axis and the diagonal, measured
    against predicted, each run in its method's colour (grey: a method with no curve)."""
    if not curves:
        return None
    path = out / "phase_direction.png"
    colours = palette(len(curves))
    colour_of = {c["label"].removesuffix(" (paper's)"): colour for c, colour in zip(curves, colours)}
    fronts = [f for f in fronts if f["predicted"][0] is not None]
    with figure(
        path,
        f"Phase speed against the direction of travel, predicted at dx = 0.25 m ({pid}); colour: method",
        "direction, degrees from the lattice's x axis",
        "phase speed error minus its value along the axis, %",
        ncols=3 if fronts else 2,
        size=(15.5 if fronts else 11.0, 5.2),
    ) as axes:
        for ax, key, title in (
            (axes[0], "error", "the pulse's wavenumber k = 1/b"),
            (axes[1], "short", "a short wave, 8 particles per wavelength"),
        ):
            for i, (c, colour) in enumerate(zip(curves, colours)):
                values = 100 * np.asarray(c[key])
                style = ("-", "--", ":", "-.")[i % 4]  # a curve under another still shows
                ax.plot(c["angles"], values - values[0], color=colour, ls=style, lw=1.8, label=c["label"])
            ax.set_xticks([0, 15, 30, 45])
            ax.set_title(title, fontsize=10)
        if fronts:
            ax = axes[2]
            ax.set_xlabel("predicted front speed error, %")
            ax.set_ylabel("measured front speed error, %")
            ax.set_title("2D runs: the front along the axis (o) and the diagonal (^)", fontsize=10)
            values = []
            for f in fronts:
                colour = colour_of.get(f["method"], "0.5")
                for k, marker in ((0, "o"), (1, "^")):
                    ax.scatter(
                        100 * f["predicted"][k],
                        100 * f["measured"][k],
                        marker=marker,
                        facecolors="none",
                        edgecolors=colour,
                        s=36,
                        label=None if f["method"] in colour_of else "runs of other methods",
                    )
                    values += [100 * f["predicted"][k], 100 * f["measured"][k]]
            lo, hi = min(values), max(values)
            pad = 0.05 * (hi - lo or 1.0)
            ax.plot(
                [lo - pad, hi + pad], [lo - pad, hi + pad], color="0.6", lw=0.8, ls=":", label="measured = predicted"
            )
    return path
