"""``pcabench advise``: the fastest stored run that reaches an error at a physical time.

A researcher wants an answer of a given accuracy at a given physical time in
the least time. Among one machine's finished runs at that time (and model),
the fastest by time to solution (init + steps, JIT apart) whose relative RMS
error of u is at most the target; beside it, the fastest run of the paper's
configuration (Gaussian, h = 2.13 dx, 3h, CFL 0.2, Verlet) that reaches the
same error, and the ratio. The margin to instability comes from the
dispersion relation (solvers/reference/dispersion.py, pcabench/predict/stability.py): a run at or
past its method's predicted stable CFL is never advised, however small its
error (it ended bounded only because its run was too short for round-off to
grow). Where no stored run reaches the target, the prediction names the sweep
that would.
"""

from __future__ import annotations

import shlex
from pathlib import Path

import numpy as np

from pcabench import jsonout
from pcabench.cli.accuracy import ROUNDED_AS_PRINTED
from pcabench.cli.exits import EXIT_OK, EXIT_RUN_FAILED
from pcabench.cli.options import results_of
from pcabench.errors import NoResults
from pcabench.predict.search import suggest
from pcabench.predict.stability import assess, e_foldings, margin, margin_rule
from pcabench.reports.tables import comparable, default_numerics, error_column, latest, numerics_label
from pcabench.spec import OptionError, scene_from_row
from solvers import (
    DEFAULT_KERNEL,
    DEFAULT_SCENE,
    Scene,
    scene_kind,
)
from solvers.method import Method


def scene_of(r) -> dict:
    """A stored run's method and domain (the frame has brought rows that predate a parameter to its default)."""
    return {
        "kernel": r["kernel"],
        "h_factor": r["h_factor"],
        "cutoff_factor": r["cutoff_factor"],
        "cfl": r["cfl"],
        "integrator": r["integrator"],
        "correction": r.get("correction") or Scene.default("correction"),
        "dx": r["dx"],
        "strip_height": r["strip_height"],
    }


def command(r, t_end: float | None = None) -> str:
    """The ``pcabench run`` command line that makes stored run ``r`` (a row of the reports' frame) again, from
    its whole stored scene (:mod:`pcabench.commands`: every parameter away from its default, quoted for the
    shell). ``t_end`` is the run's own (kept for callers)."""
    from pcabench.commands import line_of, words_of

    scene = scene_from_row(r)
    return line_of(*words_of(str(r["solver"]), scene, int(r["threads"]), str(r.get("pair_loop") or "")))


def reaching(df, t_end: float, model: str):
    """Finished runs of ``model`` that ended at ``t_end`` (the newest of each configuration), fastest first."""
    d = df[(df.status == "ok") & (df.model == model) & df.t_final.notna()]
    d = d[np.isclose(d.t_final.astype(float), t_end, rtol=1e-6)]
    return latest(d).sort_values("t_solution") if not d.empty else d


def paper_configuration(df):
    """Rows of the paper's numerics: default integrator, CFL, h/dx and cutoff, and the Gaussian kernel."""
    d = default_numerics(df)
    return d[d["kernel"] == DEFAULT_KERNEL] if "kernel" in d else d


def _unstable_row(r, column: str) -> dict:
    """A run that reached the error past its predicted stable CFL: what it was, never advised."""
    a = assess(r)
    return {
        "method": numerics_label(r),
        "dx": float(r.dx),
        "cfl": float(r.cfl),
        "fraction": a["fraction"],
        "past_limit": bool(a["past_limit"]),
        "stable_cfl": a["stable_cfl"],
        "limit_from": a["limit_from"],
        "error": float(r[column]),
        "seconds": float(r.t_solution),
        "steps": int(r.steps),
        "e_foldings": e_foldings(r, int(r.steps)),
    }


def _unstable_rows(runs, column: str, most: int = 3) -> list[dict]:
    """The fastest ``most`` methods (kernel, h/dx, cutoff, CFL, dx) of ``runs`` (fastest first), once each."""
    rows, seen = [], set()
    for _, r in runs.iterrows():
        row = _unstable_row(r, column)
        if (row["method"], row["dx"]) not in seen and len(rows) < most:
            seen.add((row["method"], row["dx"]))
            rows.append(row)
    return rows


def advise(
    df,
    error: float,
    t_end: float,
    model: str = "linear",
    domain: str | None = None,
    scene: str = Scene.default("name"),
    problem: tuple[str, ...] = (),
) -> dict:
    """The fastest stored run of ``scene`` reaching ``error`` at ``t_end`` (on ``domain``, ``strip`` or ``full``,
    if given) within the margin of its stable CFL, the fastest run of the paper's configuration reaching it that
    compares with it, and the ratio. Like is compared with like (``tables.comparable``): the same kind of domain (a
    strip holds fewer particles than the full domain; on a strip each method runs on the thinnest strip its
    support allows), the same threads and the same commit. A run past the margin of its method's stable CFL
    (pcabench/predict/stability.py ``MARGIN``, the one rule: at or past the limit it is unstable by prediction) is
    never advised, whatever its error: ``not_advised`` lists those faster than the advice (or all of them,
    fastest first, where none within the margin reaches the error). ``problem``: the study options of the problem
    asked about (``--open x``), for the study command :func:`suggest` names."""
    runs = reaching(df, t_end, model)
    if domain is not None and not runs.empty:
        runs = runs[runs.domain == domain]
    column = error_column(model)
    hits = runs[runs[column] <= error] if not runs.empty else runs
    past = np.array([assess(r)["past_margin"] for _, r in hits.iterrows()], bool)  # the one margin rule
    unstable, hits = hits[past], hits[~past]
    out = {
        "error_target": error,
        "t_end": t_end,
        "model": model,
        "runs_considered": int(len(runs)),
        "margin": margin(model),
        "problem": list(problem),
        "error_against": "the isothermal solution"
        if column == "mse_isothermal"
        else "the linear pulse"
        if scene == Scene.default("name")
        else "the exact linear solution",
    }
    if hits.empty:
        out["found"] = False
        out["not_advised"] = _unstable_rows(unstable, column)
        out["suggestion"] = suggest(error, t_end, model, scene, problem, domain)
        return out
    best = hits.iloc[0]
    faster = unstable[unstable.t_solution < best.t_solution]
    limit = assess(best)
    stable = limit["stable_cfl"]
    paper = paper_configuration(hits[[comparable(r, best) for _, r in hits.iterrows()]])
    paper_best = paper.iloc[0] if not paper.empty else None
    out.update(
        found=True,
        command=command(best, t_end),
        error=float(best[column]),
        seconds=float(best.t_solution),
        machine=str(best.machine),
        solver=str(best.solver),
        domain=str(best.domain),
        precision=str(best.precision),
        commit=str(best.commit)[:12],
        threads=int(best.threads),
        n_particles=int(best.n_particles),
        steps=int(best.steps),
        **scene_of(best),
        stable_cfl=stable,
        cfl_fraction=float(best.cfl) / stable,
        limit_from=limit["limit_from"],
        paper_seconds=None if paper_best is None else float(paper_best.t_solution),
        paper_error=None if paper_best is None else float(paper_best[column]),
        paper_command=None if paper_best is None else command(paper_best, t_end),
        not_advised=_unstable_rows(faster, column),
    )
    out["is_paper_configuration"] = paper_best is not None and out["paper_command"] == out["command"]
    out["speedup_over_paper"] = out["paper_seconds"] / out["seconds"] if out["paper_seconds"] else None
    return out


def advice_text(out: dict, error: float, t_end: float, model: str, domain, scene: str) -> tuple[str, bool]:
    """``pcabench advise``'s answer in words: the text for :func:`advise`'s result ``out``, and whether a run
    reached the error."""
    lines = []
    scene_words = "" if scene == DEFAULT_SCENE else f"{scene}, "
    no_reference = out["error_against"] == "the isothermal solution" and not scene_kind(scene).has_isothermal
    against = "the isothermal solution, which this scene does not have" if no_reference else out["error_against"]
    head = (
        f"{scene_words}{model} to a {scene_kind(scene).headline(t_end)} <= {error:g} "
        f"(against {against}) on {out['machine']}" + (f", {domain} domain" if domain else "")
    )
    if not out["found"]:
        s = out["suggestion"]
        lines.append(
            f"{head}: none of the {out['runs_considered']} stored runs reaches it within the margin of its stable "
            f"CFL ({margin_rule(model)})."
        )
        lines += unstable_lines(out["not_advised"], "runs that reach it", model)
        if no_reference:
            lines.append(
                f"no {model} run of {scene} can be scored (no isothermal solution is known there); the "
                "prediction below is of the linear part, the method to try with --model linear"
            )
        if "study" not in s:
            c = s.get("closest")
            lines.append(
                "no method of the searched grid is predicted to reach it"
                + (
                    f" (the closest: {c['method']}, dx {c['dx']:g}: predicted {c['predicted_error']:.3g}, {s['note']})"
                    if c
                    else ""
                )
            )
        else:
            lines.append(
                f"predicted cheapest ({s['note']}): {s['method']}"
                + (f", {s['boundary_method']} wall" if "boundary_method" in s else "")
                + f", dx {s['dx']:g} (predicted {s['predicted_error']:.3g}"
                + (f"; {s['n_particles']:,} particles, {s['steps']:,} steps" if "steps" in s else "")
                + f"; CFL {s['cfl']:g} = {s['cfl'] / s['stable_cfl']:.2f} of its stable {s['stable_cfl']:.3g}, "
                + f"{margin_rule(model)}); "
                f"run:\n  {s['study']}"
            )
        lines.append(
            f"the paper's configuration needs dx <= {s['paper_dx']:g} m (predicted)"
            if s["paper_dx"]
            else f"the paper's configuration needs dx below {s['smallest_dx_searched']:g} m (the smallest searched)"
        )
        return "\n".join(lines), False
    lines.append(
        f"{head}:\n  fastest: {out['seconds']:.3g} s (error {out['error']:.3g}; {Method.of(out).numerics}, "
        f"CFL {out['cfl']:g} = {out['cfl_fraction']:.2f} of the "
        + (
            f"stable {out['stable_cfl']:.3g} measured over long runs"
            if out["limit_from"] == "long runs"
            else f"predicted stable {out['stable_cfl']:.3g}{'' if model == 'linear' else ' (its linear part)'}"
        )
        + f", dx {out['dx']:g}, "
        f"{out['precision']}, {out['threads']} thread{'s' if out['threads'] > 1 else ''}, "
        f"{out['domain']} domain, {out['n_particles']:,} particles, {out['steps']} steps, "
        f"commit {out['commit'][:7]}; {margin_rule(model)})\n  {out['command']}"
    )
    if out["is_paper_configuration"]:
        lines.append(
            f"  this is the paper's configuration: none of the {out['runs_considered']} stored runs reaching t = "
            f"{t_end:g} s is faster"
            + (
                ""
                if scene == DEFAULT_SCENE or out.get("problem")  # the front takes no problem options
                else f" (`{shlex.join(['pcabench', 'study', '--front', '--scene', scene])}` runs other methods)"
            )
        )
    elif out["paper_seconds"]:
        lines.append(
            f"  the paper's configuration: {out['paper_seconds']:.3g} s (error {out['paper_error']:.3g}), "
            f"{out['speedup_over_paper']:.3g} times as long\n  {out['paper_command']}"
        )
    elif not scene_kind(scene).strip:  # one kind of domain: nowhere else to look
        lines.append("  no stored run of the paper's configuration with the same threads and commit reaches it")
    else:
        other = {"strip": "full", "full": "strip"}[out["domain"]]
        lines.append(
            f"  no stored run of the paper's configuration on the {out['domain']} domain with the same "
            f"threads and commit reaches it; `pcabench advise --domain {other}` looks at the {other} "
            "domain's runs"
        )
    lines += unstable_lines(out["not_advised"], "faster runs", model)
    return "\n".join(lines), True


def unstable_lines(rows, what: str, model: str) -> list[str]:
    """The lines naming advise's runs past the margin of their stable CFL that reached the error: never advised
    (at or past the limit itself: unstable by prediction)."""
    lines = []
    if rows:
        lines.append(
            f"  not advised: {what} past the margin ({margin_rule(model)}; at or past the limit a run is "
            "unstable by prediction: a longer run or a finer dx grows it without bound)"
        )
    for r in rows:
        if not r["past_limit"]:  # stable, but closer to its limit than the margin allows
            lines.append(
                f"    {r['method']}, dx {r['dx']:g}: {r['seconds']:.3g} s, error {r['error']:.3g}; CFL {r['cfl']:g} = "
                f"{r['fraction']:.2f} of the {'predicted ' if r['limit_from'] == 'prediction' else ''}stable "
                f"{r['stable_cfl']:.3g}, past the margin of {margin(model):g}"
            )
            continue
        which = (
            f"predicted stable {r['stable_cfl']:.3g}"
            if r["limit_from"] == "prediction"
            else f"stable {r['stable_cfl']:.3g} measured over long runs"
        )
        limit = f"CFL {r['cfl']:g} is past the {which}" if r["stable_cfl"] > 0 else "its integrator grows at every CFL"
        why = (
            f"bounded only because its {r['steps']} steps gave the most unstable mode "
            f"{r['e_foldings']:.3g} e-foldings (round-off needs about 37)"
            if r["limit_from"] == "prediction"
            else f"bounded only because its {r['steps']} steps were fewer than the long runs' before they blew up"
        )
        lines.append(f"    {r['method']}, dx {r['dx']:g}: {r['seconds']:.3g} s, error {r['error']:.3g}; {limit}, {why}")
    return lines


def problem_words(args) -> tuple[str, ...]:
    """The study options of the problem advise was asked about where they are not the scene's own: ``--open``
    and ``--mach``, so that a study advise names makes the runs it reads."""
    words: list[str] = []
    if args.open and args.open != scene_kind(args.scene).defaults.get("open", ""):
        words += ["--open", args.open]
    if args.mach is not None and args.mach != Scene.default("mach"):
        words += ["--mach", f"{args.mach:g}"]
    return tuple(words)


def check_problem(name: str, mach: float, edges: str) -> None:
    """One line naming the option unless scene ``name`` takes ``--mach`` and ``--open`` as given (before any search:
    a study advise names for a problem Scene refuses would be refused in turn)."""
    from solvers import SceneError

    try:
        smallest = scene_kind(name).smallest  # the kind's smallest case (a wall clear of the kernel's support)
        Scene(**{**smallest, "name": name, "steps": 1, "mach": mach, "open": edges, "model": "linear"})
    except (SceneError, ValueError) as exc:
        text = str(exc)  # Scene's own range checks name the parameter, its kinds' the option
        raise OptionError(f"--mach: {text}" if text.startswith("mach ") else text) from None


def cmd_advise(args) -> int:
    from pcabench.machine.profiles import machine_id
    from pcabench.reports.frame import load as load_frame
    from pcabench.store import runs

    if not 0 < args.error <= 1:
        raise OptionError(f"--error is a relative RMS error in (0, 1] (got {args.error:g})")
    if not args.t_end > 0:
        raise OptionError(f"--t-end is a physical time in s, > 0 (got {args.t_end:g})")
    results = results_of(args)
    df = load_frame(results) if results is not None and Path(results).exists() else None
    mach = Scene.default("mach") if args.mach is None else args.mach
    edges = args.open or scene_kind(args.scene).defaults.get("open", "")  # an open problem's edges by default
    problem = problem_words(args)
    check_problem(args.scene, mach, edges)
    if df is not None and not df.empty:
        df = df[(df.scene == args.scene) & np.isclose(df.mach.astype(float), mach) & (df.open == edges)]
    if df is None or df.empty:  # what makes the runs asked about: the prediction's study, with their problem
        s = suggest(args.error, args.t_end, args.model, args.scene, problem, args.domain)
        make = (
            f"run `{s['study']}` first (the method predicted cheapest to --error {args.error:g})"
            if "study" in s
            else f"no method of the searched grid is predicted to reach --error {args.error:g}"
        )
        raise NoResults(
            f"no stored runs of the {args.scene} scene at --mach {mach:g}"
            f"{f' with --open {args.open}' if args.open else ''} in {results}: {make}, or use --reference"
        )
    machines = df.machine.value_counts()
    if args.machine:
        named = runs.machines(machines.index, args.machine)  # a machine's name, or a prefix of one
        if len(named) != 1:
            why = f"names {', '.join(named)}" if named else f"is none of {', '.join(sorted(machines.index))}"
            raise OptionError(f"--machine {args.machine!r} {why}: give one machine (or a prefix of one)")
        machine = named[0]
    else:
        machine = machine_id() if machine_id() in machines else machines.index[0]
    out = {
        "machine": machine,
        "scene": args.scene,
        **advise(df[df.machine == machine], args.error, args.t_end, args.model, args.domain, args.scene, problem),
    }
    if args.json:  # the numbers the text prints, rounded as it prints them
        shown = {key: jsonout.significant(out[key]) for key in ROUNDED_AS_PRINTED if out.get(key) is not None}
        if out.get("cfl_fraction") is not None:
            shown["cfl_fraction"] = round(out["cfl_fraction"], 2)  # printed as "0.66 of the predicted stable"
        jsonout.emit(jsonout.dumps({**out, **shown}, sort_keys=True))
        return EXIT_OK if out["found"] else EXIT_RUN_FAILED
    text, found = advice_text(out, args.error, args.t_end, args.model, args.domain, args.scene)
    print(text)
    return EXIT_OK if found else EXIT_RUN_FAILED
