"""The ``pcabench`` argument parser: every command's options and the function that runs it."""

from __future__ import annotations

import argparse

from pcabench import __version__, paths
from pcabench.cli.accuracy import cmd_accuracy
from pcabench.cli.advise import cmd_advise
from pcabench.cli.exits import DESCRIPTION, EXIT_HELP
from pcabench.cli.machine import cmd_cache, cmd_check_solver, cmd_gpu_check, cmd_profile
from pcabench.cli.options import (
    MODEL_HELP,
    PresetHelpFormatter,
    add_method_options,
    add_preset_options,
    add_problem_options,
    add_scene_options,
    folder,
    number,
    positive_int,
    solver_help,
)
from pcabench.cli.report import cmd_report, cmd_runs
from pcabench.cli.run import cmd_run
from pcabench.cli.study import cmd_study
from pcabench.usage import Parser
from solvers import (
    DEFAULT_SCENE,
    MODELS,
    Scene,
    registry,
    scene_kind,
    scene_names,
)
from solvers.edges import OPEN_EDGES


def t_end_words() -> str:
    """The scenes' own --t-end for accuracy and advise, as help says it: "10 s; sphere 4 s"."""
    usual = scene_kind(DEFAULT_SCENE).t_end
    other = [f"{name} {scene_kind(name).t_end:g} s" for name in scene_names() if scene_kind(name).t_end != usual]
    return "; ".join([f"{usual:g} s", *other])


def build_parser() -> argparse.ArgumentParser:
    parser = Parser(
        prog="pcabench", description=DESCRIPTION, epilog=EXIT_HELP, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--version", action="version", version=f"pcabench {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=Parser)
    results_help = f"folder of results stores, *.jsonl (default: {paths.user_results()})"
    reports_help = f"folder for the reports (default: {paths.user_reports()})"

    add_run(sub, results_help)
    add_study(sub, results_help, reports_help)
    add_report(sub, results_help, reports_help)
    add_runs(sub, results_help)
    add_accuracy(sub)
    add_advise(sub, results_help)
    add_profile(sub)
    add_gpu_check(sub, results_help, reports_help)
    add_check_solver(sub)
    add_cache(sub)
    parser.subcommands = dict(sub.choices)  # an unknown option is its subcommand's error
    return parser


def add_run(sub, results_help: str) -> None:
    """``pcabench run``: its options and the function that runs it."""
    p = sub.add_parser(
        "run",
        help="run one scene on one solver and print the stage table",
        epilog=solver_help() + "\n" + MODEL_HELP,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--solver", required=True, choices=registry())
    add_scene_options(p, many=False)
    p.add_argument(
        "--strip-height",
        type=number("--strip-height"),
        help="replace the 20 m height by a y-periodic strip of this height, m",
    )
    p.add_argument(
        "--fields",
        help="write the final fields (x, y, u, v, drho, t; z, w in 3D) to this .npz (a folder: a file named by the "
        "run in it), or NAME.vtu: a VTK unstructured grid of the particles with drho and the velocity vector, "
        "which ParaView opens (meshio: the extra vtk)",
    )
    p.add_argument(
        "--store",
        action="store_true",
        help="keep the run's record in the results store (as a study does), so `runs` and `advise` see it",
    )
    p.add_argument("--results", type=folder("--results"), help=f"with --store: {results_help}")
    p.add_argument("--json", action="store_true", help="print exactly one JSON object on stdout")
    p.add_argument("--quiet", action="store_true", help="no progress on stderr")
    p.add_argument(
        "--run-budget",
        type=number("--run-budget"),
        help="seconds before the run stops and is reported as a timeout (exit 1; default: no limit)",
    )
    p.set_defaults(func=cmd_run)


def add_study(sub, results_help: str, reports_help: str) -> None:
    """``pcabench study``: its options and the function that runs it."""
    p = sub.add_parser(
        "study",
        help="run a sweep (each run in its own process) and write the report",
        description="Run a preset, or the product of the matrix options, one process per run.",
        epilog=solver_help() + "\n" + MODEL_HELP,
        formatter_class=PresetHelpFormatter,
    )
    add_preset_options(p.add_mutually_exclusive_group(), matrix=True)
    p.add_argument("--list", action="store_true", help="print the runs the study would make, one a line, and exit")
    m = p.add_argument_group("matrix (instead of a preset: the product of these lists)")
    m.add_argument("--solver", nargs="+", choices=registry())
    add_scene_options(m, many=True)
    m.add_argument("--strip", action="store_true", help="the thinnest y-periodic strip instead of 20 m")
    p.add_argument("--results", type=folder("--results"), default=str(paths.user_results()), help=results_help)
    p.add_argument("--reports", type=folder("--reports"), default=str(paths.user_reports()), help=reports_help)
    p.add_argument(
        "--run-budget",
        type=number("--run-budget"),
        help="seconds per run before it is a timeout (default: {budgets})",
    )
    p.add_argument(
        "--sweep-budget", type=number("--sweep-budget"), default=4 * 3600.0, help="seconds for the whole sweep"
    )
    p.add_argument("--no-report", action="store_true", help="store the runs, do not write the reports")
    p.add_argument(
        "--cluster",
        metavar="ADDRESS",
        help="run each run as a Dask task: a scheduler address (tcp://host:8786) or local:N for a "
        'LocalCluster of N workers (pip install -e ".[cluster]")',
    )
    p.add_argument(
        "--retry-failed",
        action="store_true",
        help="run again the stored runs that timed out, were skipped or ended in an error",
    )
    p.set_defaults(func=cmd_study)


def add_report(sub, results_help: str, reports_help: str) -> None:
    """``pcabench report``: its options and the function that runs it."""
    p = sub.add_parser("report", help="regenerate the reports from the stored results")
    p.add_argument(
        "--reference", action="store_true", help="the committed reference: reports/results -> reports/ of the checkout"
    )
    p.add_argument("--results", type=folder("--results"), help=results_help)
    p.add_argument("--out", type=folder("--out"), help=reports_help)
    p.add_argument("--scene", choices=scene_names(), help="only this scene's runs (default: every scene)")
    p.set_defaults(func=cmd_report)


def add_runs(sub, results_help: str) -> None:
    """``pcabench runs``: its options and the function that runs it."""
    p = sub.add_parser("runs", help="list and filter stored runs, or compare two machines or commits")
    p.add_argument("--results", type=folder("--results"), help=results_help)
    p.add_argument("--reference", action="store_true", help="the committed reference results (reports/results)")
    p.add_argument("--solver")
    p.add_argument("--status")
    p.add_argument("--machine", help="a machine (profile id, or profile--host), or a prefix of one")
    p.add_argument("--commit", help="a commit prefix")
    p.add_argument("--model")
    p.add_argument("--scene", help="only the runs of this scene (plane-pulse, acoustic-pulse, ...)")
    p.add_argument(
        "--compare",
        nargs=2,
        metavar=("A", "B"),
        help="the runs both A and B made (machines or prefixes of them, or commit prefixes): step times, ratio, errors",
    )
    p.add_argument(
        "--limit",
        type=positive_int("--limit"),
        default=200,
        help="print at most the last this many matching runs, by machine and time (default 200; a line "
        "says when rows were left out)",
    )
    p.set_defaults(func=cmd_runs)


def add_accuracy(sub) -> None:
    """``pcabench accuracy``: its options and the function that runs it."""
    p = sub.add_parser(
        "accuracy",
        help="predict a run's error and largest stable CFL from the dispersion relation",
        description="The relative RMS error of the scene's primary field (u; drho in 2D) at --t-end and the "
        "largest stable CFL of the `linear` model, from the lattice's SPH operator and the integrator's step, "
        "with no simulation (for fixed and lagrangian: their linear part).",
    )
    p.add_argument("--dx", type=number("--dx"), required=True, help="lattice spacing, m")
    p.add_argument(
        "--t-end", type=number("--t-end"), help=f"physical end time, s (default: the scene's, {t_end_words()})"
    )
    add_problem_options(p)
    add_method_options(p)
    p.add_argument("--json", action="store_true", help="one JSON object: predicted_error, stable_cfl, ...")
    p.set_defaults(func=cmd_accuracy)


def add_advise(sub, results_help: str) -> None:
    """``pcabench advise``: its options and the function that runs it."""
    p = sub.add_parser(
        "advise",
        help="the fastest stored run that reaches an error at a physical time",
        description="Among one machine's stored runs at --t-end, the fastest by time to solution "
        "(init + steps, JIT apart) whose relative RMS error (u, or drho in 2D) is at most --error, "
        "the paper configuration's time to the same error, and the command line.",
    )
    p.add_argument(
        "--error",
        type=number("--error"),
        required=True,
        help="relative RMS error of the scene's primary field (u; drho in 2D), e.g. 0.01",
    )
    p.add_argument("--t-end", type=number("--t-end"), help=f"physical time, s (default: the scene's, {t_end_words()})")
    p.add_argument(
        "--model",
        choices=MODELS,
        default="linear",
        help=f"default linear, whose prediction is exact (run's and study's default is {Scene.default('model')}: "
        "name it to be advised on it)",
    )
    p.add_argument("--scene", choices=scene_names(), default=DEFAULT_SCENE, help=f"default {DEFAULT_SCENE}")
    p.add_argument(
        "--mach",
        type=number("--mach"),
        help=f"only runs at this amplitude (default: the scene's {Scene.default('mach'):g})",
    )
    p.add_argument(
        "--open",
        choices=[e for e in OPEN_EDGES if e],
        help="only runs with these edges open (default: closed runs only, as the scene is)",
    )
    p.add_argument("--reference", action="store_true", help="the committed reference results (reports/results)")
    p.add_argument("--results", help=results_help)
    p.add_argument(
        "--machine",
        help="a machine (profile id) of the stores, or a prefix of one; default this one where its runs answer, "
        "else the machine whose runs do (named in the answer)",
    )
    p.add_argument(
        "--domain",
        choices=("strip", "full"),
        help="only runs on the y-periodic strip or the full "
        "domain (default: either; the paper's configuration is always taken on the fastest run's)",
    )
    p.add_argument("--json", action="store_true", help="one JSON object: command, error, seconds, paper_seconds")
    p.set_defaults(func=cmd_advise)


def add_profile(sub) -> None:
    """``pcabench profile``: its options and the function that runs it."""
    p = sub.add_parser("profile", help="capture this machine's hardware profile")
    p.add_argument("--save", action="store_true", help="store it among the user's profiles")
    p.add_argument("--out", type=folder("--out"), help=f"folder to store it in (default: {paths.user_profiles()})")
    p.add_argument("--no-gpu", action="store_true")
    p.add_argument(
        "--asv",
        action="store_true",
        help="write this machine's entry into ~/.asv-machine.json and print its name (for --machine)",
    )
    p.set_defaults(func=cmd_profile)


def add_gpu_check(sub, results_help: str, reports_help: str) -> None:
    """``pcabench gpu-check``: its options and the function that runs it."""
    p = sub.add_parser(
        "gpu-check",
        help="on a GPU machine: all of the GPU work in one call, within a budget",
        description="Profile and ceilings, GPU vs CPU, the GPU sweep, the graph path, the host's "
        "CPU, GPU tests, pytest-benchmark, asv and Nsight Compute, in that order, "
        "within --budget seconds; everything to bring back in OUT/gpu_check.tar.gz.",
    )
    p.add_argument("--out", default="gpu_check_out", help="folder for the check's own files (tables, logs, tarball)")
    p.add_argument("--results", default=str(paths.user_results()), help=results_help)
    p.add_argument("--reports", default=str(paths.user_reports()), help=reports_help)
    p.add_argument(
        "--budget",
        type=number("--budget", low=60.0),
        default=480.0,
        help="seconds for the whole check (default 480: the full plan takes about 6 min on an H200)",
    )
    p.add_argument(
        "--rehearse",
        action="store_true",
        help="the same script in numba's CUDA simulator at a few hundred particles (no GPU needed)",
    )
    p.set_defaults(func=cmd_gpu_check)


def add_check_solver(sub) -> None:
    """``pcabench check-solver``: its options and the function that runs it."""
    p = sub.add_parser(
        "check-solver",
        help="the conformance suite: is a solver (yours too) right?",
        description="Checks a registered solver against the all-pair reference, its neighbour "
        "count, memory bound, threads, stage timing, blow-up report and its claims "
        "(pcabench/conformance.py); one line per check: ok, FAILED: why, skipped: why. "
        "Exit 0 when none fails, 1 when one fails.",
    )
    p.add_argument("name", metavar="NAME", help="a solver's name: " + ", ".join(registry()))
    p.add_argument(
        "--quick", action="store_true", help="the defaults and each claimed value once, not every combination"
    )
    p.add_argument("--json", action="store_true", help="one JSON object: solver, ok, checks")
    p.set_defaults(func=cmd_check_solver)


def add_cache(sub) -> None:
    """``pcabench cache``: its options and the function that runs it."""
    p = sub.add_parser(
        "cache",
        help="show or clear the on-disk cache of compiled loops",
        description="The compiled loops (solvers/loops/) are cached on disk once per machine and configuration "
        "(solvers/jitcache.py), in $PCABENCH_CACHE, else $XDG_CACHE_HOME/pcabench, else ~/.cache/pcabench. "
        "Clearing it is always safe: a run using it keeps its loops, and later runs compile again.",
    )
    p.add_argument("--clear", action="store_true", help="remove every compiled loop (all targets)")
    p.add_argument("--json", action="store_true", help="one JSON object: root, target, entries")
    p.set_defaults(func=cmd_cache)
