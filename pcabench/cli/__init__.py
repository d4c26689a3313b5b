"""The ``pcabench`` command line: the only module that knows about argparse.

    pcabench run --solver linkedlist-cpu --dx 0.1 --t-end 10
    pcabench study --quick | --paper | --stability [short|long] | --front [quick|full] | --walls | --dx 1 0.5 ...
    pcabench report [--reference]
    pcabench profile [--save | --asv]
    pcabench gpu-check --out DIR

Library code raises exceptions; this module alone maps them to the exit
codes of :data:`EXIT_HELP` (bad input is one line naming the parameter and its
allowed range, never a traceback).
"""

from __future__ import annotations

import argparse
import math
import os
import re
import shlex
import signal
import sys
import tempfile
import warnings
from pathlib import Path

from pcabench import __version__, jsonout, paths
from pcabench.errors import NoResults
from pcabench.execute.progress import Progress
from pcabench.machine import memory
from pcabench.parameters import METHOD, PARAMETERS, PRECISION_MODEL, PROBLEM
from pcabench.parser import EXIT_BAD_INPUT, Parser
from pcabench.spec import SERIAL, OptionError, RunSpec, parse_threads
from pcabench.store import StoreError
from solvers import (
    DEFAULT_SCENE,
    DEFAULT_SOLVER,
    MODELS,
    Scene,
    SceneError,
    SolverUnavailable,
    registry,
    scene_kind,
    scene_names,
    scenes,
)

DESCRIPTION = """Benchmark SPH solvers of computational acoustics (a Gaussian sound pulse in 2D, the paper's
scene) on CPUs and GPUs: run one scene, sweep studies into a results store, write reports with
tables and figures, and ask which stored run reaches an error fastest (advise) or what error and
largest stable step the dispersion relation predicts (accuracy)."""

# exit codes: each one means one thing
EXIT_OK, EXIT_RUN_FAILED, EXIT_UNAVAILABLE, EXIT_NO_RESULTS, EXIT_INTERRUPTED = 0, 1, 3, 4, 130
EXIT_PIPE, EXIT_TERMINATED = 141, 143  # 128 + SIGPIPE (the reader of stdout left: `| head`), 128 + SIGTERM
EXIT_HELP = f"""exit codes:
  {EXIT_OK}    ok
  {EXIT_RUN_FAILED}    the run failed: unstable (with its step), out-of-memory or error, recorded, never a
       traceback; `advise`: no stored run reaches --error; `gpu-check`: a stage failed
  {EXIT_BAD_INPUT}    bad input: one line naming the parameter and its allowed range, before any work
  {EXIT_UNAVAILABLE}    the solver cannot run here (no GPU)
  {EXIT_NO_RESULTS}    no results: no stored runs to report or advise from (run `pcabench study` first)
  {EXIT_INTERRUPTED}  interrupted (Ctrl-C); {EXIT_TERMINATED}: terminated (SIGTERM); {EXIT_PIPE}: the reader of the
       output left (`| head`), silently. A sweep stopped either way keeps every finished run and resumes"""


def solver_help() -> str:
    """The solvers section of --help, from each solver's own ``summary`` (plug-ins included)."""
    width = max(map(len, registry())) + 2
    lines = ["solvers:"]
    for name, cls in registry().items():
        first, *rest = (cls.summary or cls.__doc__ or "").strip().splitlines() or [""]
        lines += [f"  {name:<{width}}{first}"] + [f"  {'':<{width}}{line.strip()}" for line in rest]
    return "\n".join(lines)


MODEL_HELP = """models:
  lagrangian  the paper's: particles move, rho = rho0 + drho (isothermal Euler at Ma 0.05)
  fixed       particles stay on the lattice, rho = rho0 + drho
  linear      particles stay, coefficients frozen at rho0: exactly the linear wave equation
integrators:
  verlet  Stormer-Verlet, second order, no amplitude drift (default)
  kdk1    one-sweep kick-drift-kick: first order, amplitude grows
  euler   forward Euler: grows at any dt
  rk2     explicit midpoint"""


# ---------------------------------------------------------------- option types
DECIMAL = re.compile(r"[+-]?((\d+\.?\d*|\.\d+)(e[+-]?\d+)?|nan|inf|infinity)", re.ASCII | re.I)  # ASCII, as typed


def positive_int(name):
    def parse(text):
        if not text.isascii() or not text.strip().lstrip("+-").isdigit():
            raise argparse.ArgumentTypeError(f"{name} must be an integer >= 1 (got {text!r})")
        value = int(text)
        if value < 1:
            raise argparse.ArgumentTypeError(f"{name} must be an integer >= 1 (got {value})")
        return value

    return parse


def number(name, low: float | None = None):
    def parse(text):
        if not DECIMAL.fullmatch(text.strip()):
            raise argparse.ArgumentTypeError(f"{name} must be a number such as 0.5 or 1e-3 (got {text!r})")
        value = float(text)
        if not math.isfinite(value):
            raise argparse.ArgumentTypeError(f"{name} must be finite (got {text!r})")
        if low is not None and value < low:
            raise argparse.ArgumentTypeError(f"{name} must be at least {low:g} (got {text!r})")
        return value

    return parse


def folder(name):
    def parse(text):
        if not text.strip():
            raise argparse.ArgumentTypeError(f"{name} needs a folder (got {text!r})")
        return text

    return parse


def threads_option(text):
    try:
        return parse_threads(text)
    except OptionError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def add_parameter_options(p: argparse.ArgumentParser, parameters, many: bool = False) -> None:
    """Options for ``parameters`` (pcabench/parameters.py), each with its help and Scene's default."""
    n = {"nargs": "+"} if many else {}
    for par in parameters:
        kind = {"choices": par.choices()} if par.choices else {"type": number(par.option)} if par.numeric else {}
        p.add_argument(par.option, **kind, **n, help=par.describe())


def add_method_options(p: argparse.ArgumentParser, many: bool = False) -> None:
    """The numerical method's options (integrator, kernel, cutoff, h/dx, CFL), with Scene's defaults."""
    add_parameter_options(p, METHOD, many)


def add_problem_options(p: argparse.ArgumentParser, many: bool = False) -> None:
    """The problem's options: the scene kind and its physical parameters, with Scene's defaults."""
    add_parameter_options(p, PROBLEM, many)
    if not many:
        p.add_argument(
            "--domain-size",
            type=number("--domain-size"),
            help="side of a square scene's domain, m (acoustic-pulse: default 40)",
        )


def add_scene_options(p: argparse.ArgumentParser, many: bool) -> None:
    """The scene's options, with Scene's defaults; ``many``: each takes a list (a study's matrix)."""
    n = {"nargs": "+"} if many else {}
    add_problem_options(p, many)
    p.add_argument(
        "--dx",
        type=number("--dx"),
        required=not many,
        **n,
        help="lattice spacing, m (paper: 1 .. 0.004; 0.1 is 100K particles)",
    )
    add_parameter_options(p, PRECISION_MODEL[:1], many)
    end = p.add_mutually_exclusive_group()
    end.add_argument("--steps", type=positive_int("--steps"), **n, help="number of steps (default 100, the paper's)")
    end.add_argument("--t-end", type=number("--t-end"), **n, help="physical end time, s")
    add_parameter_options(p, PRECISION_MODEL[1:], many)
    add_method_options(p, many)
    threaded = ", ".join(name for name, cls in registry().items() if cls.threaded)
    loops = {name: cls.pair_loops for name, cls in registry().items() if len(cls.pair_loops) > 1}
    p.add_argument(
        "--threads",
        type=threads_option,
        **n,
        help=f"CPU threads for {threaded}: N or 'all' (default 1: serial, like the paper's CPU code)",
    )
    p.add_argument(
        "--pair-loop",
        choices=("auto", *dict.fromkeys(x for v in loops.values() for x in v)),
        **n,
        help="the pair loop of a solver with several ("
        + "; ".join(f"{name}: {', '.join(v)}" for name, v in loops.items())
        + "): list visits each pair once "
        "per search and keeps its kernel factors, gather is the paper's (every particle's stencil "
        "in every sweep); default auto: the solver's choice (list where it fits in memory)",
    )


SCENE_OPTIONS = {par.dest: par.field for par in PARAMETERS}  # argparse destination -> Scene field
# the method and the problem
ACCURACY_OPTIONS = {opt: key for opt, key in SCENE_OPTIONS.items() if opt not in ("precision", "model")}


def domain_of(args) -> dict:
    """The domain ``--domain-size`` asks for (nothing when not given), for the scene named."""
    if getattr(args, "domain_size", None) is None:
        return {}
    try:
        return scene_kind(args.scene or DEFAULT_SCENE).sized_domain(args.domain_size)
    except ValueError as exc:
        raise OptionError(str(exc)) from None


def check_wall_option(names, wall_given: bool) -> None:
    """One line unless --wall-x (Scene.x_max, the wall) comes only with scenes that have a wall."""
    bare = [name for name in names if not scene_kind(name).walls]
    if wall_given and bare:
        walled = ", ".join(name for name, kind in scenes().items() if kind.walls)
        raise OptionError(f"--wall-x applies to the scenes with a wall ({walled}), not to {', '.join(bare)}")


def scene_from_args(args) -> Scene:
    """The scene of the options, bounded by the memory this process may use (one line if it does not fit)."""
    given = {key: getattr(args, opt) for opt, key in SCENE_OPTIONS.items() if getattr(args, opt) is not None}
    check_wall_option([given.get("name", DEFAULT_SCENE)], "x_max" in given)
    return Scene(
        dx=args.dx,
        steps=args.steps,
        t_end=args.t_end,
        strip_height=args.strip_height,
        memory_limit_bytes=memory.available_memory_bytes(),
        **given,
        **domain_of(args),
    )


def check_output_path(path, option: str) -> None:
    """OptionError naming ``option`` unless a file can be written at ``path`` (tried before any work, in its
    folder, leaving nothing behind and following no link: a link at ``path`` is replaced when the file is
    written, :mod:`pcabench.store.safeio`)."""
    text = str(path)
    path = Path(path)
    if not text.strip() or text.endswith(("/", os.sep)) or path.stem in ("", ".") or path.is_dir():
        raise OptionError(f"{option} {text!r} is not a file name")
    if not path.parent.is_dir():
        raise OptionError(f"{option} {path}: the folder {path.parent} does not exist")
    try:
        tempfile.TemporaryFile(dir=path.parent).close()
    except OSError as exc:
        raise OptionError(f"{option} {path} is not writable: {exc.strerror or exc}") from None


def check_folder(path, option: str) -> Path:
    """OptionError naming ``option`` unless the folder ``path`` can be made and written (tried in the
    nearest folder that exists, leaving nothing behind)."""
    path = Path(path)
    here = path
    while not here.exists() and here != here.parent:
        here = here.parent
    try:
        tempfile.TemporaryFile(dir=here).close()
    except OSError as exc:
        raise OptionError(f"{option} {path} is not a writable folder: {exc.strerror or exc}") from None
    return path


def home_option() -> str:
    """How the user sets the folder of their profiles and defaults: the variable if set."""
    return "PCABENCH_HOME" if os.environ.get("PCABENCH_HOME") else "the pcabench home"


# ---------------------------------------------------------------- commands
def cmd_run(args) -> int:
    from pcabench.execute.run import run, solver_output_to_stderr
    from pcabench.machine.profiles import machine_id
    from pcabench.store import to_row

    scene = scene_from_args(args)
    from pcabench.cli.study import check_specs

    # resolved once, and checked: the solver can run here (a GPU for a GPU solver), before anything is printed
    (spec,) = check_specs([RunSpec(args.solver, scene, args.threads or SERIAL, pair_loop=args.pair_loop or "auto")])
    if args.fields is not None:
        if args.fields.strip() and not args.fields.endswith((".npz", "/")):
            args.fields += ".npz"  # as numpy.savez names it
        check_output_path(args.fields, "--fields")
    if args.run_budget is not None and not args.run_budget > 0:
        raise OptionError(f"--run-budget must be > 0 seconds (got {args.run_budget})")
    if not args.json:
        print(f"pcabench run: {spec.label}; {scene.describe()}", flush=True)
    if args.run_budget is not None:  # in a child, as a sweep runs it: the budget holds whatever the solver does
        record = run_in_child(spec, args)
    else:
        progress = None if args.quiet else Progress(args.solver)
        with solver_output_to_stderr(args.json):
            record = run(spec, machine_id(), fields_path=args.fields, progress=progress)
    if args.json:  # the record as a store holds it: the whole scene, so the run can be made again from it
        print(jsonout.dumps(to_row(record)))  # strict JSON: null, never NaN
    else:
        print(record.text(scene))
    return EXIT_OK if record.status == "ok" else EXIT_RUN_FAILED


def run_in_child(spec: RunSpec, args):
    """``pcabench run --run-budget S``: the run in a child process of its own group (as a sweep's,
    :func:`pcabench.execute.sweep.run_child`), killed with all it started at S seconds, whether or not the solver
    returns to Python (a compiled loop, a solver that ignores signals); its record."""
    import subprocess

    from pcabench.execute.sweep import failed_record, run_child
    from pcabench.machine.profiles import machine_id
    from pcabench.store.provenance import git_commit
    from pcabench.store.record import RunRecord

    stream = None if args.quiet else sys.stderr
    try:
        row = run_child(spec, args.run_budget, git_commit(), machine_id(), stream=stream, fields_to=args.fields)
    except subprocess.TimeoutExpired:
        return failed_record(spec, "timeout", f"past the run budget of {args.run_budget:g} s", machine_id())
    return RunRecord.from_row(row)


def study_specs(args) -> tuple[str, list[RunSpec]]:
    """The preset named by the flags, or the matrix built from the scene options."""
    from pcabench.presets import DEFAULT_PRESET, PRESETS, flags, matrix, named_by, preset

    given = [flag for flag in flags() if getattr(args, flag, None)]
    if args.dx and given:
        raise OptionError(f"--dx builds a matrix of runs; --{given[0]} is a preset with its own: give one or the other")
    if args.dx:
        lists = {key: getattr(args, opt) for opt, key in SCENE_OPTIONS.items() if getattr(args, opt)}
        check_wall_option(lists.get("name", [DEFAULT_SCENE]), "x_max" in lists)
        return "matrix", matrix(
            args.solver or [DEFAULT_SOLVER],
            args.dx,
            threads=args.threads or [SERIAL],
            steps=args.steps or [None],
            t_ends=args.t_end or [None],
            strip=args.strip,
            pair_loops=args.pair_loop or ["auto"],
            **lists,
        )
    scene = args.scene or [DEFAULT_SCENE]
    if (
        any(
            getattr(args, opt)
            for opt in (*SCENE_OPTIONS, "solver", "steps", "t_end", "threads", "pair_loop")
            if opt != "scene"
        )
        or args.strip
    ):
        raise OptionError(
            "--dx is needed to build a matrix from the scene options; a preset ("
            + ", ".join(f"--{flag}" for flag in flags())
            + ") takes none of them"
        )
    name = named_by(given[0], getattr(args, given[0])) if given else DEFAULT_PRESET
    scened = [p.option for p in PRESETS.all().values() if p.scened]
    if scene != [DEFAULT_SCENE] and (len(scene) > 1 or not PRESETS.get(name).scened):
        raise OptionError(
            f"--scene with a preset: one scene, with {' or '.join(scened)} (the other presets choose their own scenes)"
        )
    return name, preset(name, scene[0])


def cmd_study(args) -> int:
    from pcabench.cli.study import bounded_spec, check_specs, run_study
    from pcabench.presets import budget

    name, specs = study_specs(args)
    if args.cluster:  # the workers check their own solvers (a GPU run needs a GPU worker, not a GPU here)
        specs = [bounded_spec(spec) for spec in specs]
    else:
        specs = check_specs(specs)
    specs = list(dict.fromkeys(specs))  # resolved, two specs may be one run (auto is list here): counted once
    if args.list:
        for i, spec in enumerate(specs, 1):
            print(f"[{i}/{len(specs)}] {spec.preset}: {spec.label}")
        return EXIT_OK
    run_budget = args.run_budget if args.run_budget is not None else budget(name)
    for flag, value in (("--run-budget", run_budget), ("--sweep-budget", args.sweep_budget)):
        if not value > 0:
            raise OptionError(f"{flag} must be > 0 seconds (got {value})")
    if not args.cluster:
        check_folder(paths.user_profiles(), home_option())  # where the sweep saves this machine's profile
    if not args.no_report:
        check_folder(args.reports, "--reports")  # before the sweep, not after it
    return run_study(
        name,
        specs,
        Path(args.results),
        None if args.no_report else Path(args.reports),
        run_budget,
        args.sweep_budget,
        cluster=args.cluster,
        retry_failed=args.retry_failed,
    )


def cmd_report(args) -> int:
    from pcabench.reports import write_reports

    results, reports = args.results, args.out
    if args.reference:
        if paths.checkout() is None:
            raise OptionError("--reference needs a source checkout (its reports/ folder)")
        results, reports = results or paths.reference_results(), reports or paths.reference_reports()
    results, reports = results or paths.user_results(), reports or paths.user_reports()
    check_folder(reports, "--out" if args.out else "--reference" if args.reference else home_option())
    for p in write_reports(Path(results), Path(reports), scene=args.scene):
        print(f"wrote {p}", file=sys.stderr)
    return 0


def cmd_runs(args) -> int:
    import warnings

    import pandas as pd

    from pcabench.reports.frame import load
    from pcabench.store import runs

    results = args.results or (paths.reference_results() if args.reference else paths.user_results())
    with warnings.catch_warnings():
        warnings.simplefilter("default")
        df = load(results)
    if df.empty:
        raise NoResults(f"no stored runs in {results}: run `pcabench study` first, or use --reference")
    if args.scene:
        df = df[df.scene == args.scene]
    with pd.option_context("display.max_columns", None, "display.width", 200):
        if args.compare:
            try:
                out = runs.compare(df, *args.compare)
            except KeyError as exc:
                raise OptionError(exc.args[0]) from None
            print(runs.render(out) if not out.empty else "no configuration was run by both")
        else:
            out = runs.table(
                df, solver=args.solver, status=args.status, machine=args.machine, commit=args.commit, model=args.model
            )
            print(runs.render(out.tail(args.limit)) if not out.empty else f"no stored runs match in {results}")
            if len(out) > args.limit:
                print(
                    f"(the last {args.limit} of {len(out)} matching runs, by machine and time; --limit {len(out)} "
                    "shows them all)"
                )
    return 0


def cmd_accuracy(args) -> int:
    from solvers.reference.dispersion import predict

    given = {key: getattr(args, opt) for opt, key in ACCURACY_OPTIONS.items() if getattr(args, opt) is not None}
    check_wall_option([given.get("name", DEFAULT_SCENE)], "x_max" in given)
    scene = Scene(  # the prediction builds the scene's lattice: bounded by this process's memory, as a run is
        dx=args.dx,
        t_end=args.t_end,
        model="linear",
        memory_limit_bytes=memory.available_memory_bytes(),
        **given,
        **domain_of(args),
    )
    p = predict(scene)
    past = p.stable_cfl <= scene.cfl  # at or past the largest stable step (pcabench/predict/stability.py)
    if args.json:
        print(jsonout.dumps({"scene": scene.as_dict(), **p.as_dict(), "past_stable_cfl": past}, sort_keys=True))
        return 0
    if past:
        print(
            f"CFL {scene.cfl:g} is past the largest stable CFL {p.stable_cfl:.3g} of {scene.integrator}: a run "
            "grows without bound (the predicted error is that growth)"
            if p.stable_cfl > 0
            else f"{scene.integrator} grows at every CFL: a long enough run grows without bound"
        )
    print(
        f"{scene.describe()}\n"
        f"predicted relative RMS error of {scene.kind.primary} at t = {p.t_end:.4g} s: {p.predicted_error:.4g} "
        f"(max error {p.predicted_me:.3g} {'m/s' if scene.kind.primary == 'u' else 'kg/m^3'})\n"
        f"largest stable CFL (dt c0 / dx) for {scene.integrator}: {p.stable_cfl:.4g}"
        f"{' (grows at any step)' if p.stable_cfl == 0 else ''}\n"
        f"phase speed error at k = 1/w: lattice {100 * p.lattice_phase_error:+.3f} %, with the step "
        f"{100 * p.step_phase_error:+.3f} %"
        + (
            ""
            if p.lattice_phase_error_diagonal is None
            else f" along the lattice's axis; along its diagonal {100 * p.lattice_phase_error_diagonal:+.3f} % and "
            f"{100 * p.step_phase_error_diagonal:+.3f} %"
        )
    )
    for name, value in (p.measures or {}).items():
        print(f"predicted {name.replace('_', ' ')}: {value:.4g}")
    return 0


# advise's numbers printed to 3 significant digits (the scene's own parameters stay exact)
ROUNDED_AS_PRINTED = (
    "error",
    "seconds",
    "stable_cfl",
    "paper_seconds",
    "paper_error",
    "speedup_over_paper",
    "unstable_by_prediction",
)


def cmd_advise(args) -> int:
    from pcabench.cli.advise import advice_text, advise
    from pcabench.machine.profiles import machine_id
    from pcabench.reports.frame import load as load_frame
    from pcabench.store import runs

    if not 0 < args.error <= 1:
        raise OptionError(f"--error is a relative RMS error in (0, 1] (got {args.error:g})")
    results = paths.reference_results() if args.reference else Path(args.results or paths.user_results())
    df = load_frame(results) if results is not None and Path(results).exists() else None
    if df is not None and not df.empty:
        import numpy as np

        mach = Scene.default("mach") if args.mach is None else args.mach
        df = df[(df.scene == args.scene) & np.isclose(df.mach.astype(float), mach)]
    if df is None or df.empty:
        study = ["pcabench", "study", "--front", *([] if args.scene == DEFAULT_SCENE else ["--scene", args.scene])]
        raise NoResults(
            f"no stored runs of the {args.scene} scene at --mach "
            f"{Scene.default('mach') if args.mach is None else args.mach:g} in {results}: run "
            f"`{shlex.join(study)}` first, or use --reference"
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
        **advise(df[df.machine == machine], args.error, args.t_end, args.model, args.domain, args.scene),
    }
    if args.json:  # the numbers the text prints, rounded as it prints them
        shown = {key: jsonout.significant(out[key]) for key in ROUNDED_AS_PRINTED if out.get(key) is not None}
        if out.get("cfl_fraction") is not None:
            shown["cfl_fraction"] = round(out["cfl_fraction"], 2)  # printed as "0.66 of the predicted stable"
        print(jsonout.dumps({**out, **shown}, sort_keys=True))
        return EXIT_OK if out["found"] else EXIT_RUN_FAILED
    text, found = advice_text(out, args.error, args.t_end, args.model, args.domain, args.scene)
    print(text)
    return EXIT_OK if found else EXIT_RUN_FAILED


def cmd_profile(args) -> int:
    from pcabench.machine import profiles

    profile = profiles.capture(with_gpu=not args.no_gpu)
    if args.asv:
        from pcabench.bench import asv_machine

        print(asv_machine.write(profile))
        return 0
    if args.save:
        out = check_folder(args.out, "--out") if args.out else check_folder(paths.user_profiles(), home_option())
        print(f"wrote {profiles.save(profile, out)}", file=sys.stderr)
    print(jsonout.dumps(profile, indent=2))
    return 0


def cmd_gpu_check(args) -> int:
    from pcabench.gpu.check import gpu_check

    return gpu_check(
        Path(args.out), Path(args.results), Path(args.reports), budget_s=args.budget, rehearse=args.rehearse
    )


def cmd_check_solver(args) -> int:
    from pcabench.conformance import main as check_solver

    return check_solver(args.name, quick=args.quick, as_json=args.json)


def cmd_cache(args) -> int:
    from solvers import jitcache

    root = jitcache.cache_root()
    blocked = next((p for p in (root, *root.parents) if p.exists() and not p.is_dir()), None)
    if blocked is not None:  # runs warn and compile in memory; here it is the whole answer
        raise OptionError(
            f"the JIT cache root {root} cannot be a folder: {blocked} is a file "
            f"(set ${jitcache.ENV} or $XDG_CACHE_HOME to a folder)"
        )
    if args.clear:
        freed = jitcache.clear()
        print(f"cleared {root / 'jit'} ({freed / 2**20:.1f} MiB); the next run of each configuration compiles again")
        return 0
    entries = jitcache.entries()
    if args.json:
        print(jsonout.dumps({"root": str(root), "target": jitcache.target(), "entries": entries}, indent=2))
        return 0
    size = sum(e["bytes"] for e in entries)
    print(f"JIT cache  {root / 'jit'}  (${jitcache.ENV} moves it)")
    print(f"this machine's target  {jitcache.target()}")
    print(
        f"{len(entries)} specialised modules, {sum(e['functions'] for e in entries)} compiled functions, "
        f"{size / 2**20:.1f} MiB"
    )
    for e in entries:
        here = "" if e["target"] == jitcache.target() else f"  ({e['target']})"
        print(f"  {e['module']:<34} {e['functions']:>2} functions {e['bytes'] / 2**10:>6.0f} KiB{here}")
        print(f"      {e['specialisation']}")
    return 0


# ---------------------------------------------------------------- the parser
class PresetHelpFormatter(argparse.RawDescriptionHelpFormatter):
    """``{size:PRESET}`` in an option's help is the preset's run count, counted from its plan when the help is
    shown (:meth:`pcabench.presets.Preset.size`), so the help cannot drift from the runs."""

    def _expand_help(self, action):
        from pcabench.presets import MATRIX_BUDGET, PRESETS, size_text

        text = super()._expand_help(action)
        budgets = ", ".join(f"{p.name} {p.budget:g}" for p in PRESETS.all().values()) + f", matrix {MATRIX_BUDGET:g}"
        text = text.replace("{budgets}", budgets)
        return re.sub(r"\{size:([\w-]+)\}", lambda m: size_text(m.group(1)), text)


def add_preset_options(group) -> None:
    """One option per preset flag (pcabench/presets/: each preset names its flag, choice and help): a flag of
    one preset is a switch, a flag several share takes their choices (the first one's when none is given)."""
    from pcabench.presets import flags

    for flag, shared in flags().items():
        sized = [p.help.replace("{size}", "{size:" + p.name + "}") for p in shared]
        if len(shared) == 1 and shared[0].choice is None:
            group.add_argument(f"--{flag}", action="store_true", help=sized[0])
            continue
        group.add_argument(
            f"--{flag}",
            nargs="?",
            const=shared[0].choice,
            choices=[p.choice for p in shared],
            help="; ".join(f"{p.choice}: {text}" for p, text in zip(shared, sized)),
        )


def build_parser() -> argparse.ArgumentParser:
    parser = Parser(
        prog="pcabench", description=DESCRIPTION, epilog=EXIT_HELP, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--version", action="version", version=f"pcabench {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, parser_class=Parser)
    results_help = f"folder of results stores, *.jsonl (default: {paths.user_results()})"
    reports_help = f"folder for the reports (default: {paths.user_reports()})"

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
    p.add_argument("--fields", help="write the final fields (x, y, u, v, drho, t) to this .npz")
    p.add_argument("--json", action="store_true", help="print exactly one JSON object on stdout")
    p.add_argument("--quiet", action="store_true", help="no progress on stderr")
    p.add_argument(
        "--run-budget",
        type=number("--run-budget"),
        help="seconds before the run stops and is reported as a timeout (exit 1; default: no limit)",
    )
    p.set_defaults(func=cmd_run)

    p = sub.add_parser(
        "study",
        help="run a sweep (each run in its own process) and write the report",
        description="Run a preset, or the product of the matrix options, one process per run.",
        epilog=solver_help() + "\n" + MODEL_HELP,
        formatter_class=PresetHelpFormatter,
    )
    add_preset_options(p.add_mutually_exclusive_group())
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

    p = sub.add_parser("report", help="regenerate the reports from the stored results")
    p.add_argument(
        "--reference", action="store_true", help="the committed reference: reports/results -> reports/ of the checkout"
    )
    p.add_argument("--results", type=folder("--results"), help=results_help)
    p.add_argument("--out", type=folder("--out"), help=reports_help)
    p.add_argument("--scene", choices=scene_names(), help="only this scene's runs (default: every scene)")
    p.set_defaults(func=cmd_report)

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

    p = sub.add_parser(
        "accuracy",
        help="predict a run's error and largest stable CFL from the dispersion relation",
        description="The relative RMS error of the scene's primary field (u; drho in 2D) at --t-end and the "
        "largest stable CFL of the `linear` model, from the lattice's SPH operator and the integrator's step, "
        "with no simulation (for fixed and lagrangian: their linear part).",
    )
    p.add_argument("--dx", type=number("--dx"), required=True, help="lattice spacing, m")
    p.add_argument("--t-end", type=number("--t-end"), default=10.0, help="physical end time, s (default 10)")
    add_problem_options(p)
    add_method_options(p)
    p.add_argument("--json", action="store_true", help="one JSON object: predicted_error, stable_cfl, ...")
    p.set_defaults(func=cmd_accuracy)

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
    p.add_argument("--t-end", type=number("--t-end"), default=10.0, help="physical time, s (default 10)")
    p.add_argument("--model", choices=MODELS, default="linear", help="default linear")
    p.add_argument("--scene", choices=scene_names(), default=DEFAULT_SCENE, help=f"default {DEFAULT_SCENE}")
    p.add_argument(
        "--mach",
        type=number("--mach"),
        help=f"only runs at this amplitude (default: the scene's {Scene.default('mach'):g})",
    )
    p.add_argument("--reference", action="store_true", help="the committed reference results (reports/results)")
    p.add_argument("--results", help=results_help)
    p.add_argument("--machine", help="a machine (profile id) of the stores; default this one, else the first")
    p.add_argument(
        "--domain",
        choices=("strip", "full"),
        help="only runs on the y-periodic strip or the full "
        "domain (default: either; the paper's configuration is always taken on the fastest run's)",
    )
    p.add_argument("--json", action="store_true", help="one JSON object: command, error, seconds, paper_seconds")
    p.set_defaults(func=cmd_advise)

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
    return parser


# Scene's parameter names as the options a user types (a SceneError names the parameter)
OPTION_NAMES = {
    "t_end": "--t-end",
    "strip_height": "--strip-height",
    "pair_loop": "--pair-loop",
    **{
        par.field: par.option
        for par in PARAMETERS
        if par.option[2:] != par.field and par.field not in ("name", "x_max")  # x_max: a wall only in some scenes
    },
}
# a message that starts with a field an option of the same word sets ("mach must be ...") names the option
LEADING_OPTIONS = (
    "dx",
    "steps",
    "threads",
    "solver",
    *(par.field for par in PARAMETERS if par.option[2:] == par.field),
)


def option_words(message: str) -> str:
    """``message`` with Scene's parameter names written as the options that set them (``--cutoff``)."""
    for name, option in OPTION_NAMES.items():
        message = re.sub(rf"(?<![\w-]){name}\b", option, message)
    return re.sub(rf"^({'|'.join(LEADING_OPTIONS)})\b", r"--\1", message)


class Terminated(BaseException):
    """SIGTERM, raised in the main thread so that a sweep ends as an interrupt does (its lock and reserve
    released, every finished run kept)."""


def _terminated(signum, frame):
    raise Terminated()


def main(argv=None) -> int:
    shown = warnings.formatwarning
    warnings.formatwarning = lambda message, *_, **__: f"pcabench: warning: {message}\n"  # one line each
    prog = "pcabench"
    parser = Parser(prog=prog)  # until the whole one is built (a Ctrl-C while the plug-ins load)
    import threading

    on_term = None
    if threading.current_thread() is threading.main_thread():
        on_term = signal.signal(signal.SIGTERM, _terminated)
    try:
        parser = build_parser()  # finds the solvers: a plug-in left out is one warning line
        args = parser.parse_args(argv)
        prog = f"pcabench {args.command}"
        return args.func(args)
    except (SceneError, OptionError, StoreError) as exc:
        parser.exit(EXIT_BAD_INPUT, f"{prog}: error: {option_words(str(exc))} (see {prog} --help)\n")
    except BrokenPipeError:  # `pcabench ... | head`: the reader has what it wanted
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())  # so that the flush at exit does not complain either
        return EXIT_PIPE
    except OSError as exc:  # a path the checks before the work could not foresee: one line all the same
        where = f"{exc.filename}: " if exc.filename else ""
        parser.exit(EXIT_BAD_INPUT, f"{prog}: error: {where}{exc.strerror or exc}\n")
    except SolverUnavailable as exc:
        parser.exit(EXIT_UNAVAILABLE, f"{prog}: {exc}\n")
    except NoResults as exc:
        parser.exit(EXIT_NO_RESULTS, f"{prog}: {exc}\n")
    except KeyboardInterrupt:
        parser.exit(EXIT_INTERRUPTED, f"{prog}: interrupted\n")
    except Terminated:
        parser.exit(EXIT_TERMINATED, f"{prog}: terminated\n")
    finally:
        warnings.formatwarning = shown
        if on_term is not None:
            signal.signal(signal.SIGTERM, on_term)
