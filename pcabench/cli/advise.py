"""``pcabench advise``: the fastest stored run that reaches an error at a physical time, in words.

A researcher wants an answer of a given accuracy at a given physical time in
the least time. Among one machine's finished runs at that time (and model),
the fastest by time to solution (init + steps, JIT apart) whose relative RMS
error of u is at most the target; beside it, the fastest run of the paper's
method that reaches the same error, and the ratio. The margin to instability
comes from the dispersion relation (pcabench/predict/stability.py): a run past
the margin of its method's stable CFL is never advised, however small its
error. Where no stored run reaches the target, the prediction names the sweep
that would. The choice is pcabench/predict/advice.py (``advise``) and the
search pcabench/predict/search.py; this module checks the problem, loads the
stored runs and writes the answer.
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
from pcabench.predict.advice import advise
from pcabench.predict.search import suggest
from pcabench.predict.stability import margin, margin_rule
from pcabench.spec import OptionError
from solvers import (
    DEFAULT_SCENE,
    Scene,
    scene_kind,
    scenes,
)
from solvers.method import Method


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
    if out.get("host_machine"):  # answered from another machine's runs: say so before anything else
        lines.append(
            f"(this host is {out['host_machine']}, whose stored runs do not answer: the answer is {out['machine']}'s "
            "runs; --machine names one)"
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


def answering_machine(df, machines, asked: tuple) -> tuple[str, dict]:
    """The machine whose stored runs answer and the answer (:func:`advise` of ``asked``): this host's machine
    where its runs reach the error, else the first of the other machines (most stored runs first) whose runs
    do; where none does, this host's machine (or the one with the most runs) with the prediction's study. So
    a new host (a machine id with no rows, or rows that do not reach the error) is answered from the runs that
    do, and the answer names their machine."""
    from pcabench.machine.profiles import machine_id

    here = machine_id()
    order = ([here] if here in machines.index else []) + [m for m in machines.index if m != here]
    for machine in order:
        answer = advise(df[df.machine == machine], *asked, suggest_missing=False)
        if answer["found"]:
            return machine, answer
    return order[0], advise(df[df.machine == order[0]], *asked)


def cmd_advise(args) -> int:
    """``pcabench advise``; a scene kind with no prediction (the sphere) refused in one line."""
    from solvers.scenes.base import NoPrediction

    try:
        return _advise(args)
    except NoPrediction as exc:
        raise OptionError(str(exc)) from None


def _advise(args) -> int:
    from pcabench.machine.profiles import machine_id
    from pcabench.reports.frame import load as load_frame
    from pcabench.store import runs

    if not 0 < args.error <= 1:
        raise OptionError(f"--error is a relative RMS error in (0, 1] (got {args.error:g})")
    if args.t_end is None:
        args.t_end = scene_kind(args.scene).t_end
    if not args.t_end > 0:
        raise OptionError(f"--t-end is a physical time in s, > 0 (got {args.t_end:g})")
    if args.domain == "strip" and not scene_kind(args.scene).strip:  # before any work, as a run refuses it
        strips = ", ".join(name for name, kind in scenes().items() if kind.strip)
        raise OptionError(f"--domain strip applies to the scenes with a strip ({strips}), not to {args.scene}")
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
    asked = (args.error, args.t_end, args.model, args.domain, args.scene, problem)
    if args.machine:
        named = runs.machines(machines.index, args.machine)  # a machine's name, or a prefix of one
        if len(named) != 1:
            why = f"names {', '.join(named)}" if named else f"is none of {', '.join(sorted(machines.index))}"
            raise OptionError(f"--machine {args.machine!r} {why}: give one machine (or a prefix of one)")
        machine, answer = named[0], advise(df[df.machine == named[0]], *asked)
    else:
        machine, answer = answering_machine(df, machines, asked)
    out = {"machine": machine, "scene": args.scene, **answer}
    if not args.machine and machine != machine_id():
        out["host_machine"] = machine_id()  # this host's machine, whose stored runs do not answer
    if args.json:  # the numbers the text prints, rounded as it prints them
        shown = {key: jsonout.significant(out[key]) for key in ROUNDED_AS_PRINTED if out.get(key) is not None}
        if out.get("cfl_fraction") is not None:
            shown["cfl_fraction"] = round(out["cfl_fraction"], 2)  # printed as "0.66 of the predicted stable"
        jsonout.emit(jsonout.dumps({**out, **shown}, sort_keys=True))
        return EXIT_OK if out["found"] else EXIT_RUN_FAILED
    text, found = advice_text(out, args.error, args.t_end, args.model, args.domain, args.scene)
    print(text)
    return EXIT_OK if found else EXIT_RUN_FAILED
