"""The report's sections, declared in one place: each is its rows, its Markdown and its figures.

A :class:`Section` names three things: ``rows(ctx)`` computes its numbers
(``tables.py``) once per report, ``text(rows, ctx)`` writes its Markdown from
them, and ``figures`` draw its PNGs (``figures.py``) from the same rows.
:data:`SECTIONS` lists them in report order: a new table or figure is one
entry here beside its text. Rows shared by several sections (Table 4 for
Table 5 and Fig. 13; Table 6 across every machine and the cards page) are
computed once through :meth:`Context.once`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path
from typing import Any, Callable

import numpy as np
import pandas as pd

from pcabench.presets import INACCURATE_ABOVE
from solvers import Scene, scene_kind

from . import figures as F
from . import paper as P
from . import tables as T
from . import walls as W
from .md import first_words, fmt, md_table, pct


@dataclass
class Context:
    """One machine's report: its runs (``df``), every machine's (``df_all``), its name and folder, and the
    rows computed once per report or once per set of reports (``shared``)."""

    df: pd.DataFrame
    df_all: pd.DataFrame
    name: str
    out: Path
    shared: dict = field(default_factory=dict)
    cache: dict = field(default_factory=dict)
    df_scenes: pd.DataFrame | None = None  # every scene's runs of this machine (``df`` holds the paper's scene's)

    @property
    def pid(self) -> str:
        df = self.df_scenes if self.df_scenes is not None else self.df
        return str(df.profile_id.iloc[0])

    def once(self, key: str, compute: Callable[[], Any], across_machines: bool = False):
        """``compute()`` the first time ``key`` is asked for in this report (or in every report)."""
        cache = self.shared if across_machines else self.cache
        if key not in cache:
            cache[key] = compute()
        return cache[key]

    def table4(self):
        return self.once("table4", lambda: T.table4(self.df))

    def table6(self):
        return self.once("table6", lambda: T.table6(self.df_all), across_machines=True)


@dataclass(frozen=True)
class Section:
    """A part of the report: ``rows(ctx)``, ``text(rows, ctx)`` (Markdown lines, [] when the rows hold
    nothing) and ``figures`` (each ``figure(rows, ctx)`` -> a PNG path or None)."""

    name: str
    rows: Callable[[Context], Any]
    text: Callable[[Any, Context], list[str]]
    figures: tuple[Callable[[Any, Context], Path | None], ...] = ()
    all_scenes: bool = False  # reads ``ctx.df_scenes``; the others read the paper's scene only


def _paper_cell(r) -> str:
    if r["paper_stages"]:
        return "K20c " + " / ".join(f"{v:g}" for v in r["paper_stages"]) + " (Table 4)"
    return (
        "; ".join(f"{p['ms']:.3g} ms/step, {p['processor']} ({p['source']}: {p['conversion']})" for p in r["paper"])
        or "-"
    )


def _paper_sizes(rows) -> str:
    """Where the paper has numbers of the kinds these rows are: by device and search, its N."""
    kinds = sorted({(r["device"], r["search"]) for r in rows})
    parts = []
    for device, search in kinds:
        ns = sorted({p["N"] for p in P.step_times() if (p["device"], p["search"]) == (device, search)})
        if ns:
            parts.append(f"{device.upper()} {search} at N = {', '.join(f'{n:,}' for n in ns)}")
    return "; ".join(parts)


# ---------------------------------------------------------------- Table 4 and Fig. 13
def _table4_text(rows, ctx) -> list[str]:
    if not rows:
        return []
    return [
        "## Table 4: stage times (the paper's scene: lagrangian, full domain)",
        "",
        "input, init and output in ms per run; SNP, PI and SU in ms per step (the mean step of the run). "
        "Each row names its protocol (run length, domain, pair loop, threads); rows of different protocols "
        "stand apart, never averaged or replaced. The paper's column holds its published numbers of the same "
        "kind only: same N, same device, same search, serial and float64 (the paper's codes are "
        "single-thread and double precision), each with the conversion it took "
        f"(pcabench/reports/paper.py). The paper has them for {_paper_sizes(rows)}.",
        "",
        md_table(
            [
                "config",
                "protocol",
                "N",
                "input",
                "init",
                "SNP",
                "PI",
                "SU",
                "output",
                "commit",
                "paper, same kind (published)",
            ],
            [
                [
                    r["config"],
                    r["protocol"],
                    f"{r['N']:,}",
                    fmt(r["input"], ".2f"),
                    fmt(r["init"], ".2f"),
                    fmt(r["snp"], ".3f"),
                    fmt(r["pi"], ".3f"),
                    fmt(r["su"], ".3f"),
                    fmt(r["output"], ".2f"),
                    r["commit"],
                    _paper_cell(r),
                ]
                for r in rows
            ],
        ),
        "",
    ]


def _fig13(rows, ctx):
    return F.fig13(T.one_step_shares(rows), ctx.out, ctx.name)


# ---------------------------------------------------------------- Table 5 and Fig. 11
def _table5_text(rows, ctx) -> list[str]:
    if not rows:
        return []
    allpair = any(r["search"] == "all-pair" for r in rows)
    beside = []
    if any(r["device"] == "gpu" for r in rows):
        beside.append("beside a serial float64 GPU row its Table 5 (Tesla K20c, same N)")
    if any(r["device"] == "cpu" and r["search"] == "linked list" for r in rows):
        shares = P.cpu_shares()
        beside.append(
            f"beside a serial float64 linked-list CPU row its Fig. 11 text (serial "
            f"{P.processor('paper-system-1', 'cpu')}, about {shares['snp']:g} % SNP and {shares['pi']:g} % "
            "PI at every N)"
        )
    return [
        "## Table 5 and Fig. 11: share of a step",
        "",
        f"The paper's column compares like with like: {', '.join(beside) or 'none of its shares is of these kinds'}"
        "; '-' elsewhere."
        + (
            " An all-pair row has no neighbour search to time: it visits every pair of particles inside PI, "
            "so its SNP share is 0 % and the paper, whose shares are the linked list's, has none beside it."
            if allpair
            else ""
        ),
        "",
        md_table(
            ["config", "protocol", "N", "SNP %", "PI %", "SU %", "paper, same kind: SNP / PI / SU % (published)"],
            [
                [
                    r["config"],
                    r["protocol"],
                    f"{r['N']:,}",
                    fmt(r["snp"], ".1f"),
                    fmt(r["pi"], ".1f"),
                    fmt(r["su"], ".1f"),
                    f"{' / '.join(f'{v:g}' for v in r['paper'][1])} ({r['paper'][0]})" if r["paper"] else "-",
                ]
                for r in rows
            ],
        ),
        "",
    ]


# ---------------------------------------------------------------- Fig. 10
def _fig10_text(rows, ctx) -> list[str]:
    if not rows:
        return []
    kinds = {(r["device"], r["search"]) for r in rows if r["precision"] == "float64"}
    paper = []
    if ("cpu", "linked list") in kinds:
        paper.append(
            f"its serial CPU from Table 6 ({P.CONVERSION['Table 6']}) and the 400K step of its text, "
            "two series never joined (they come from different runs and do not lie on one line)"
        )
    if ("gpu", "linked list") in kinds:
        paper.append("its K20c from Table 4 (one step)")
    return [
        "## Fig. 10: one step against N",
        "",
        "A panel per run length, a line per configuration (pair loop and threads in its label). "
        + (
            f"The paper's step times are drawn beside our lines of the same kind only: {'; '.join(paper)}."
            if paper
            else "The paper has no step times of these kinds."
        ),
        "",
    ]


# ---------------------------------------------------------------- speed per particle-step and per pair
def _speed_text(rows, ctx) -> list[str]:
    if not rows:
        return []
    return [
        "## Speed per particle-step and per neighbour pair (the paper's domain)",
        "",
        "One step (SNP + PI + SU) per particle, and per neighbour pair (two sweeps over N x mean neighbours "
        "pairs per Verlet step). Pair loops: `list`, each pair once per search with its kernel factors; "
        "`gather`, the paper's loop over each particle's stencil in every sweep. An all-pair run visits every "
        "pair of particles, not a neighbour list, so it has no time per neighbour pair ('-').",
        "",
        md_table(
            ["config", "protocol", "model", "N", "ns per particle-step", "ns per neighbour pair", "SNP %", "commit"],
            [
                [
                    r["config"],
                    r["protocol"],
                    r["model"],
                    f"{r['N']:,}",
                    fmt(r["ns_per_particle_step"], ".0f"),
                    fmt(r["ns_per_pair"], ".2f"),
                    fmt(r["snp_pct"], ".1f"),
                    r["commit"],
                ]
                for r in rows
            ],
        ),
        "",
    ]


# ---------------------------------------------------------------- Table 6 and Fig. 14
def table6_md(rows, across: bool = False, gpu_column: bool = False) -> str:
    """Table 6's rows, named and rounded alike in every report and the cards page: a "speedup" for a GPU against
    its own host's CPU, a "ratio" ``across`` machines (two computers, not what a GPU buys one of them)."""
    word = "ratio" if across else "speedup"
    return md_table(
        (["GPU profile"] if gpu_column else [])
        + [
            "N",
            "protocol",
            "GPU precision",
            "GPU ms/step",
            "CPU profile, loop",
            "CPU ms/step (1 thread)",
            word,
            f"{word} vs all cores (threads)",
        ],
        [
            ([r["gpu_profile"]] if gpu_column else [])
            + [
                f"{r['N']:,}",
                r["protocol"],
                r["precision"],
                fmt(r["gpu_ms"], ".3f"),
                f"{r['cpu_profile']}, {r['cpu_loop']}",
                fmt(r["cpu_ms"], ".1f"),
                fmt(r["speedup"], ".1f"),
                "-" if r["speedup_all_cores"] is None else f"{r['speedup_all_cores']:.1f} (x{r['cpu_threads']})",
            ]
            for r in rows
        ],
    )


def _table6_text(rows, ctx) -> list[str]:
    if not rows:
        return []
    same = [r for r in rows if r["same_machine"]]
    other = [r for r in rows if not r["same_machine"]]
    lines = [
        "## Table 6: CPU against GPU, one step",
        "",
        "Speedups from one machine only: this GPU against its own host's CPU (linked list, float64), one "
        "thread (as the paper's) and every core (the honest peer), at the same N and run length. See "
        "[cards.md](../cards.md) for every system.",
        "",
    ]
    lines += [
        table6_md(same)
        if same
        else "No CPU run of the paper's scene on this GPU's host yet: no same-machine speedup to show "
        "(`pcabench gpu-check` times the host's CPU too).",
        "",
    ]
    if other:
        lines += [
            "### Across machines (not a speedup of one machine)",
            "",
            "This GPU's times against a CPU measured on another machine, named per row: a comparison of "
            "two computers, not what a GPU buys one of them.",
            "",
            table6_md(other, across=True),
            "",
        ]
    return lines


# ---------------------------------------------------------------- Fig. 9
def _fig9_text(rows, ctx) -> list[str]:
    if not any(r["allpair_ms"] or r["allpair_status"] == "skipped" for r in rows):
        return []
    steps = T.fig9_steps(rows)
    pub = [p for p in P.step_times() if p["source"] == "Fig. 9 text"]
    return [
        "## Fig. 9: all-pair against linked list (serial, float64, paper's scene)",
        "",
        f"Linked list: {T.FIG9_LOOP_NAMES.get(rows[0]['linkedlist_loop'], rows[0]['linkedlist_loop'])}, "
        "the loop measured beside the most all-pair runs, one loop throughout"
        + (
            "."
            if rows[0]["linkedlist_loop"] == "gather"
            else " (`--pair-loop gather` at the same N measures the paper's)."
        )
        + " Both sides of a row made the same number of steps"
        + (f"; the figure draws the {steps}-step runs." if steps else "."),
        "",
        md_table(
            ["steps", "N", "all-pair ms/step", "linked list ms/step", "eta = t_AP / t_LL", "all-pair status"],
            [
                [
                    r["steps"],
                    f"{r['N']:,}",
                    fmt(r["allpair_ms"], ".2f"),
                    fmt(r["linkedlist_ms"], ".2f"),
                    fmt(r["eta"], ".1f"),
                    r["allpair_status"] + (f": {first_words(r['allpair_note'])}" if r["allpair_note"] else ""),
                ]
                for r in rows
            ],
        ),
        "",
        f"Paper (published, whole runs to the 10th step, drawn as {P.CONVERSION['Fig. 9 text']}): "
        + "; ".join(f"{p['search']} {p['ms'] * P.FIG9_STEPS / 1e3:g} s at {p['N']:,}" for p in pub)
        + ".",
        "",
    ]


# ---------------------------------------------------------------- Fig. 8
def _fig8_rows(ctx):
    series = T.error_series(ctx.df)
    return {"series": series, "bars": T.accuracy_bars(series)}


def _lagrangian_note(s) -> str:
    t = s["t_final"][0] if len(set(np.round(s["t_final"], 6))) == 1 else None
    ref = T.ISOTHERMAL_VS_LINEAR.get(round(t, 6)) if t else None
    return (
        f"it {T.trend(s)} ({', '.join(pct(e) for e in s['mse'])} for dx = "
        f"{', '.join(f'{d:g}' for d in s['dx'])}). The lagrangian model solves the isothermal (nonlinear) "
        "equations at Ma = 0.05, not the linear ones, so against the linear pulse its error tends to the "
        "difference between the two solutions"
        + (f", {pct(ref)} at t = {t:g} s," if ref else "")
        + " however small dx gets; coarse lattices score lower only because their numerical smoothing hides "
        "the nonlinear steepening. No order is fitted."
    )


def _fig8_text(rows, ctx) -> list[str]:
    series = rows["series"]
    if not series:
        return []
    lines = [
        "## Fig. 8: error against dx",
        "",
        "Relative RMS error of u against the analytic pulse (the paper's MSE) and max error ME (m/s). "
        "`t = 10 s` is a fixed physical time, the honest protocol for convergence; `100 steps` is the paper's, "
        f"a different physical time (20 dx s) for each dx. The paper's one published point ({P.fig8_point()[1]:g} "
        f"at dx = {P.fig8_point()[0]:g}, 100 steps) is drawn only where our runs come near that dx.",
        "",
    ]
    table = []
    for s in series:
        for dx, n, mse, me, t in zip(s["dx"], s["N"], s["mse"], s["me"], s["t_final"]):
            table.append(
                [
                    s["model"],
                    s["precision"],
                    s["protocol"],
                    s["domain"],
                    f"{dx:g}",
                    f"{n:,}",
                    f"{t:g}",
                    fmt(mse, ".4g"),
                    fmt(me, ".3g"),
                ]
            )
    lines += [md_table(["model", "precision", "protocol", "domain", "dx", "N", "t (s)", "MSE", "ME"], table), ""]
    for s in series:
        head = f"- {s['model']} {s['precision']}, {s['protocol']}, {s['domain']}: "
        if s["model"] == "lagrangian" and s["protocol"].startswith("t ="):
            lines.append(head + _lagrangian_note(s))
        elif s["stops_falling"] and s["protocol"].startswith("t ="):
            lines.append(
                head + f"its error {T.trend(s)} "
                f"({', '.join(pct(e) for e in s['mse'])} for dx = {', '.join(f'{d:g}' for d in s['dx'])})"
                + (
                    "; the fixed model keeps the nonlinear rho div(u) term of the paper's equations but "
                    "drops the advection terms (u . grad), so it solves neither the linear nor the "
                    "isothermal equations and its error against the linear pulse stays large"
                    if s["model"] == "fixed"
                    else ""
                )
                + ". No order is fitted."
            )
        else:
            lines.append(head + T.trend(s) + ".")
    bars = [b for b in rows["bars"] if b["verdict"] != "not measured" or b["bar"].startswith("relative")]
    if bars:
        lines += [
            "",
            "### Accuracy bars (linear, Verlet, cutoff 3h, strip, t = 10 s, float64)",
            "",
            md_table(["bar", "measured", "verdict"], [[b["bar"], b["measured"], b["verdict"]] for b in bars]),
            "",
        ]
    return lines


# ---------------------------------------------------------------- time to a given accuracy
def _front_rows(ctx):
    points, front = T.speed_front(ctx.df)
    return {"points": points, "front": front, "predicted": T.predicted_by_model(ctx.df) if points else []}


def _front_text(data, ctx) -> list[str]:
    points, front = data["points"], data["front"]
    if not points:
        return []
    rows = []
    for r in T.fastest_to(points):
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
            p["model"],
            fmt(p["t_final"], "g"),
            p["method"],
            fmt(p["dx"], "g"),
            p["domain"],
            p["precision"],
            fmt(p["seconds"], ".3g"),
            fmt(p["error"], ".3g"),
            fmt(T.predicted_error(p), ".3g"),
        ]
        for p in front
    ]
    return [
        "## Time to a given accuracy",
        "",
        "Every finished run at a fixed physical time, whatever its method (kernel, h/dx, cutoff, CFL), dx and "
        "precision: time to solution (init + steps, no JIT) against the relative RMS error of u. For each "
        "error, the fastest run that reaches it, beside the fastest run of the paper's method (Gaussian, "
        "h = 2.13 dx, cut at 3h, CFL 0.2, Verlet) that reaches it, on this machine, serial or as labelled. "
        "The paper's method is compared on the same kind of domain as the fastest run (a strip holds fewer "
        "particles than the full domain for the same answer; on a strip each method runs on the thinnest "
        "strip its support allows, so a compact kernel's strip is thinner). Errors are against what each model "
        "converges to: the linear "
        "pulse for `linear`, the isothermal solution (solvers/isothermal1d.py) for `lagrangian` (its error "
        "against the linear pulse never falls below the two equations' 9.8 % difference at t = 10 s; "
        "lagrangian runs from before this was measured are left out). `fixed` solves neither and is in the "
        "cost of the simplifications below. A quick study runs the paper's method only (every ratio is then "
        "1); `pcabench study --front` adds the other kernels, h/dx and steps.",
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
        "relation predicts for each (`pcabench accuracy`, solvers/dispersion.py: the lattice's SPH operator "
        "and the integrator's own step on every wavenumber of the pulse, no simulation). For `linear` the "
        "two agree to many digits while the pulse's error waves stay clear of the domain's ends (tested to "
        "1e-8 on a longer strip); where they part here, at coarse dx and large steps, those waves have "
        "reached the ends, which the prediction's unbounded lattice lacks. For `lagrangian` the prediction "
        "is the linear part only: the moving particles and the nonlinear terms add to it.",
        "",
        md_table(["model", "t (s)", "method", "dx", "domain", "precision", "time (s)", "error", "predicted"], fronts),
        "",
        *_unstable_front_text(T.unstable_on_front(points)),
        *_predicted_by_model(data["predicted"]),
        *_why_the_paper_method(),
    ]


def _limit_words(stable_cfl: float) -> str:
    return f"{stable_cfl:.3g}" if stable_cfl > 0 else "none (grows at every CFL)"


def _unstable_front_text(rows) -> list[str]:
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
                    p["model"],
                    fmt(p["t_final"], "g"),
                    p["method"],
                    fmt(p["dx"], "g"),
                    p["domain"],
                    p["precision"],
                    fmt(p["seconds"], ".3g"),
                    fmt(p["error"], ".3g"),
                    _limit_words(p["stable_cfl"]) + (" (long runs)" if p.get("limit_from") == "long runs" else ""),
                    str(p["steps"]),
                    fmt(p["e_foldings"], ".3g"),
                ]
                for p in rows
            ],
        ),
        "",
    ]


def _predicted_by_model(predicted) -> list[str]:
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
        "converges to the isothermal solution instead, whose distance from the linear pulse (9.8 % at "
        "t = 10 s) its error against the pulse approaches; against the isothermal solution (last column) its "
        "error follows the predicted linear part closely: the prediction describes its discretisation "
        "error, the pulse's Mach number the rest.",
        "",
        md_table(["model", "dx", "measured", "predicted (linear part)", "lagrangian: vs isothermal"], rows),
        "",
    ]


@lru_cache(maxsize=1)
def _why_the_paper_method() -> list[str]:  # pure: cached, as every report shows it
    """Why the paper's h and dt sit where they do, from the prediction at its own scene's dx."""
    from solvers.dispersion import lattice_offsets, predict

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


# ---------------------------------------------------------------- the cost of each simplification
def _simplifications_text(rows, ctx) -> list[str]:
    if not rows:
        return []
    return [
        "## The cost of each simplification",
        "",
        "Each row changes one thing and keeps the rest (its runs name the protocol): what the change buys in "
        "time to solution and what it costs (or gains) in error against the linear analytic pulse.",
        "",
        md_table(
            ["simplification", "runs", "dx", "N", "time (s)", "speedup", "error"],
            [
                [
                    r["simplification"],
                    r["runs"],
                    f"{r['dx']:g}",
                    f"{r['N'][0]:,} -> {r['N'][1]:,}",
                    f"{fmt(r['seconds'][0])} -> {fmt(r['seconds'][1])}",
                    fmt(r["speedup"], ".2f"),
                    f"{pct(r['mse'][0])} -> {pct(r['mse'][1])}",
                ]
                for r in rows
            ],
        ),
        "",
    ]


# ---------------------------------------------------------------- stability
def _e_fold_words(bounded) -> str:
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


def _stability_row(lim) -> list[str]:
    swept = lim["cfls"]
    bounded = lim["bounded_past_limit"]
    blew = lim["blew_up_at"]
    limit = _limit_words(lim["stable_cfl"]) + (" (long runs)" if lim.get("limit_from") == "long runs" else "")
    return [
        lim["config"],
        f"{lim['dx']:g}",
        ", ".join(f"{c:g}" for c in swept),
        limit,
        T.cfl_ranges(lim["accurate_at"], swept) or "none",
        "; ".join(f"{c:g} ({pct(e)})" for c, e in lim["inaccurate_at"]) or "-",
        "; ".join(f"{c:g}" + (f" (step {st})" if st else "") for c, st in blew) or "-",
        (f"{T.cfl_ranges([b[0] for b in bounded], swept)}: " + _e_fold_words(bounded)) if bounded else "-",
    ]


def _stability_text(rows, ctx) -> list[str]:
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
            [_stability_row(lim) for lim in limits],
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
                parts.append(f"blew up at CFL {T.cfl_ranges([c for c, _ in lim['blew_up_at']], swept)}")
            if lim["bounded_past_limit"]:
                b = lim["bounded_past_limit"]
                parts.append(
                    f"CFL {T.cfl_ranges([x[0] for x in b], swept)} {_e_fold_words(b)}: too few for "
                    "round-off to grow, unstable by prediction, not stable"
                )
            if lim["blew_up_below_limit"]:
                parts.append(
                    f"blew up below the predicted limit at CFL "
                    f"{T.cfl_ranges(lim['blew_up_below_limit'], swept)} (against the prediction)"
                )
            accurate = T.cfl_ranges(lim["accurate_at"], swept)
            parts.append(
                f"stable and within {100 * INACCURATE_ABOVE:g} % error at CFL {accurate}"
                if accurate
                else f"stable and within {100 * INACCURATE_ABOVE:g} % error at none of the CFLs run"
            )
            lines.append(f"- **{lim['integrator']}** ({lim['protocol']}): " + "; ".join(parts) + ".")
    return lines + [""]


def _stability_map(rows, ctx):
    return F.stability_map(*rows, ctx.out, ctx.name, INACCURATE_ABOVE)


# ---------------------------------------------------------------- the moving models' limit over long runs
def _long_runs_text(rows, ctx) -> list[str]:
    if not rows:
        return []
    table = []
    for r in rows:
        blew = "; ".join(f"{c:g}" + (f" (step {st})" if st else "") for c, st in r["blew_up_at"]) or "none"
        method = f"{r['kernel']}, h = {r['h_factor']:g} dx, {r['integrator']}"
        table.append(
            [
                r["scene"],
                f"{r['mach']:g}",
                r["model"],
                method,
                f"{r['dx']:g}",
                f"{r['protocol']} (up to {r['steps']} steps)",
                ", ".join(f"{c:g}" for c in r["cfls"]),
                _limit_words(r["predicted"]),
                fmt(r["bounded_to"], "g") if r["bounded_to"] is not None else "none",
                blew,
                fmt(r["e_foldings"], ".2g") if r["e_foldings"] is not None else "-",
                fmt(r["held"], "g") if r["held"] is not None else "prediction",
            ]
        )
    lines = [
        "## Stability over long runs",
        "",
        "`pcabench study --stability long`: each model of the paper's method at the CFLs around the predicted "
        "limit (of the linear part, on a periodic lattice), to t = 300 s: on the paper's plane pulse (a strip "
        "with free ends in x, at an amplitude that does not break before 300 s; the pulse leaves by the free "
        "end long before, so these runs test the ends) and on the 2D acoustic pulse in a 20 m periodic square "
        "(the sound neither leaves nor breaks, so the moving models' nonlinear terms act for the whole run). "
        "The linear model is the control: on a periodic lattice the prediction is exact for it. 'e-foldings' "
        "is how far the most unstable mode of the periodic lattice grew at the largest bounded CFL over the "
        "run (0 below the predicted limit; round-off needs about 37 to reach the pulse's size). The last "
        "column is the limit advise, the front and the tables use for that scene and model "
        "(pcabench/stability.py: its MEASURED_LIMITS, where lower than the prediction).",
        "",
        md_table(
            [
                "scene",
                "Mach",
                "model",
                "method",
                "dx",
                "run",
                "CFLs run",
                "predicted stable CFL",
                "bounded up to CFL",
                "blew up at CFL",
                "e-foldings",
                "limit used",
            ],
            table,
        ),
        "",
    ]
    for r in rows:
        if r["blew_up_from"] is not None and r["blew_up_from"] < r["predicted"]:
            cause = (
                "the prediction is exact for this model on a periodic lattice, so the scene's edges set this limit"
                if r["model"] == "linear"
                else "its nonlinear terms or the scene's edges set its limit"
            )
            lines.append(
                f"- **{r['model']}** on {r['scene']} blew up below the predicted {r['predicted']:.3g}, "
                f"from CFL {r['blew_up_from']:g}: {cause}"
                + (
                    f"; advise takes it as {r['held']:g}."
                    if r["held"] is not None
                    else "; advise still uses the prediction for it (add it to MEASURED_LIMITS)."
                )
            )
    return lines + [""]


# ---------------------------------------------------------------- float32 against float64
def _float32_text(rows, ctx) -> list[str]:
    if not rows:
        return []
    lines = ["## float32 against float64", ""]
    for r in rows:
        pairs = "; ".join(f"dx {d:g}: {e64:.3g} / {e32:.3g}" for d, e64, e32 in r["pairs"])
        verdict = (
            f"float32 departs from float64 by more than {100 * r['tolerance']:g} % at dx = {r['stops_at']:g}"
            if r["stops_at"]
            else f"float32 tracks float64 within {100 * r['tolerance']:g} % down to dx = {r['pairs'][-1][0]:g}, "
            "the smallest measured: it has not stopped converging"
        )
        lines.append(f"- {r['model']}, {r['protocol']}, {r['domain']} (MSE float64 / float32: {pairs}): {verdict}.")
    return lines + [""]


# ---------------------------------------------------------------- runs that did not finish
def _failed_rows(ctx):
    return T.latest(ctx.df[ctx.df.status != "ok"])


def _failed_text(bad, ctx) -> list[str]:
    if bad.empty:
        return []
    rows = [
        [
            r.solver,
            r.precision,
            r.model,
            r.integrator,
            f"{r.dx:g}",
            f"{int(r.n_particles):,}",
            T.protocol(r),
            fmt(r.cfl, "g"),
            r.status,
            "-" if r.failed_step is None or not np.isfinite(r.failed_step) else int(r.failed_step),
            first_words(str(r.message)) if r.message else "",
        ]
        for _, r in bad.sort_values(["status", "solver", "dx"]).iterrows()
    ]
    return [
        "## Runs that did not finish",
        "",
        md_table(
            ["solver", "precision", "model", "integrator", "dx", "N", "protocol", "CFL", "status", "step", "message"],
            rows,
        ),
        "",
    ]


SECTIONS = (
    Section("table4", lambda ctx: ctx.table4(), _table4_text, (_fig13,)),
    Section(
        "table5",
        lambda ctx: T.table5(ctx.table4()),
        _table5_text,
        (lambda rows, ctx: F.fig11(rows, ctx.out, ctx.name),),
    ),
    Section(
        "fig10",
        lambda ctx: T.runtime_series(ctx.df),
        _fig10_text,
        (lambda rows, ctx: F.fig10(rows, ctx.out, ctx.name),),
    ),
    Section("speed", lambda ctx: T.speed(ctx.df), _speed_text),
    Section(
        "table6",
        lambda ctx: [r for r in ctx.table6() if r["gpu_profile"] == ctx.pid],
        _table6_text,
        # drawn where this GPU was measured with its own host's CPU: the paper's lines alone are the cards page's
        (lambda rows, ctx: F.fig14(rows, ctx.out, ctx.pid) if any(r["same_machine"] for r in rows) else None,),
    ),
    Section("fig9", lambda ctx: T.fig9(ctx.df), _fig9_text, (lambda rows, ctx: F.fig9(rows, ctx.out, ctx.name),)),
    Section("fig8", _fig8_rows, _fig8_text, (lambda rows, ctx: F.fig8(rows["series"], ctx.out, ctx.name),)),
    Section(
        "front",
        _front_rows,
        _front_text,
        (lambda rows, ctx: F.speed_vs_accuracy(rows["points"], rows["front"], ctx.out, ctx.name),),
    ),
    Section("simplifications", lambda ctx: T.simplifications(ctx.df), _simplifications_text),
    Section("stability", lambda ctx: T.stability(ctx.df, INACCURATE_ABOVE), _stability_text, (_stability_map,)),
    Section(
        "long-runs",
        lambda ctx: T.long_run_limits(ctx.df_scenes if ctx.df_scenes is not None else ctx.df),
        _long_runs_text,
        all_scenes=True,
    ),
    Section("float32", lambda ctx: T.float32_vs_float64(ctx.df), _float32_text),
    Section("failed", _failed_rows, _failed_text),
)


# ---------------------------------------------------------------- scenes (every scene of the machine's runs)
def _scene_rows(ctx):
    from . import scenes as S

    df = ctx.df_scenes if ctx.df_scenes is not None else ctx.df
    if df.empty or set(df.scene) == {Scene.default("name")} and not (df.mach != Scene.default("mach")).any():
        return None  # the paper's scene only, at its amplitude: the sections above say it all
    pts = S.points(df)
    rows = S.time_to_accuracy(df)
    methods = {}
    for r in rows:
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
        "needs": S.model_needs(df),
        "phase": S.phase_directions(list(methods.values())),
        "fronts": S.front_shifts(pts),
    }


def _scene_text(data, ctx) -> list[str]:
    if not data:
        return []
    from . import scenes as S

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
        f"Every finished run at t = {S.T_FINAL:g} s of every scene (solvers/scenes/; `pcabench study --front "
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
        lines += [
            f"Does the method fastest on the plane pulse stay fastest in 2D? In {len(both) - len(differ)} of "
            f"{len(both)} (model, target) pairs both scenes name the same method"
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
            "The paper's method (Gaussian, h = 2.13 dx, 3h, CFL 0.2, Verlet) at several amplitudes, every "
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
            "the methods of the table, the predicted phase speed error (lattice and step together) at the "
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


SECTIONS = SECTIONS + (
    Section(
        "scenes",
        _scene_rows,
        _scene_text,
        (
            lambda d, ctx: F.scene_fronts(d["points"], ctx.out, ctx.name) if d else None,
            lambda d, ctx: F.phase_direction(d["phase"], d["fronts"], ctx.out, ctx.name) if d else None,
        ),
        all_scenes=True,
    ),
)


# ---------------------------------------------------------------- sound at a rigid wall (every wall scene's runs)
SECTIONS = SECTIONS + (
    Section(
        "walls",
        lambda ctx: W.rows(ctx.df_scenes if ctx.df_scenes is not None else ctx.df),
        W.text,
        (lambda d, ctx: F.wall_errors(d["accuracy"], ctx.out, ctx.name) if d else None,),
        all_scenes=True,
    ),
)
