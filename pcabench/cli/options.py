"""The command line's options: their types (one line naming the option and its range on bad input), the scene's options
declared once (pcabench/parameters.py), the presets' flags, and the words that name Scene's parameters as options."""

from __future__ import annotations

import argparse
import math
import os
import re
import tempfile
from pathlib import Path

from pcabench.machine import memory
from pcabench.parameters import BODY, BOUNDARY, METHOD, PARAMETERS, PRECISION_MODEL, PROBLEM
from pcabench.spec import OptionError, parse_threads
from solvers import (
    DEFAULT_SCENE,
    Scene,
    registry,
    scene_kind,
    scenes,
)


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
  rk2     explicit midpoint
  rk4     classical fourth-order Runge-Kutta (four sweeps of both rates)"""


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


def point(name):
    """A point x,y (a 2D scene's) or x,y,z (a 3D scene's, checked against it by Scene), m."""

    def parse(text):
        parts = text.split(",")
        if len(parts) not in (2, 3) or not all(DECIMAL.fullmatch(x.strip()) for x in parts):
            raise argparse.ArgumentTypeError(
                f"{name} takes a point x,y (x,y,z in a 3D scene) in m, such as 1.5,-2 (got {text!r})"
            )
        coordinates = tuple(float(v) for v in parts)
        if not all(math.isfinite(c) for c in coordinates):
            raise argparse.ArgumentTypeError(f"{name} must be finite (got {text!r})")
        return coordinates

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
    """Options for ``parameters`` (pcabench/parameters.py), each with its help and Scene's default. In a matrix
    (``many``) an option that is also a preset's flag (``--open``) takes no values too: given alone, it is the
    preset (:func:`preset_given`)."""
    from pcabench.studies import flags

    for par in parameters:
        kind = {"choices": par.choices()} if par.choices else {"type": number(par.option)} if par.numeric else {}
        text = par.describe()
        n = {"nargs": "+"} if many else {}
        if many and par.dest in flags():
            (preset,) = flags()[par.dest]
            n = {"nargs": "*"}
            text = f"{text}; given alone, a preset: {preset.help.replace('{size}', '{size:' + preset.name + '}')}"
        p.add_argument(par.option, **kind, **n, help=text)


def preset_given(args, flag: str) -> bool:
    """Whether ``--<flag>`` names a preset on this command line: a preset's switch or choice, or a matrix option
    of the same word given alone (``--open`` with no values: ``[]``)."""
    value = getattr(args, flag.replace("-", "_"), None)  # argparse's destination of --high-order: high_order
    return value == [] if isinstance(value, list) else bool(value)


def add_method_options(p: argparse.ArgumentParser, many: bool = False) -> None:
    """The numerical method's options (integrator, kernel, cutoff, h/dx, CFL), with Scene's defaults."""
    add_parameter_options(p, METHOD, many)


def add_problem_options(p: argparse.ArgumentParser, many: bool = False) -> None:
    """The problem's options: the scene kind, its physical parameters and its open edges, with Scene's
    defaults."""
    add_parameter_options(p, PROBLEM + BOUNDARY + BODY, many)
    if not many:
        p.add_argument(
            "--probe",
            action="append",
            type=point("--probe"),
            metavar="X,Y[,Z]",
            help="a point (m; x,y,z in a 3D scene) where the run records drho every few steps, beside the scene's "
            "own (the cylinder's A, B, C); repeat for more",
        )
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
    if not args.domain_size > 0:
        raise OptionError(f"--domain-size must be > 0 m (got {args.domain_size:g})")
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
        probes=tuple(getattr(args, "probe", None) or ()),
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


# ---------------------------------------------------------------- the parser
class PresetHelpFormatter(argparse.RawDescriptionHelpFormatter):
    """``{size:PRESET}`` in an option's help is the preset's run count, counted from its plan when the help is
    shown (:meth:`pcabench.studies.Preset.size`), so the help cannot drift from the runs."""

    def _expand_help(self, action):
        from pcabench.studies import MATRIX_BUDGET, PRESETS, size_text

        text = super()._expand_help(action)
        budgets = ", ".join(f"{p.name} {p.budget:g}" for p in PRESETS.all().values()) + f", matrix {MATRIX_BUDGET:g}"
        text = text.replace("{budgets}", budgets)
        return re.sub(r"\{size:([\w-]+)\}", lambda m: size_text(m.group(1)), text)


def add_preset_options(group, matrix: bool = False) -> None:
    """One option per preset flag (pcabench/studies/*/plan.py: each preset names its flag, choice and help): a flag of
    one preset is a switch, a flag several share takes their choices (the first one's when none is given). A
    flag that is also an option of the scene's (``matrix``: the parser has them too; ``--open``) is that option
    given alone, which the matrix's option offers (:func:`add_parameter_options`)."""
    from pcabench.studies import flags

    taken = {par.dest for par in PARAMETERS} if matrix else set()

    for flag, shared in flags().items():
        sized = [p.help.replace("{size}", "{size:" + p.name + "}") for p in shared]
        if flag in taken:  # the matrix option's help says it (add_parameter_options)
            continue
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


def results_of(args):
    """The results folder ``--results`` or ``--reference`` names (else the user's); both: one line (which one
    was meant is not for the command to guess)."""
    from pcabench import paths

    if getattr(args, "reference", False) and getattr(args, "results", None):
        raise OptionError("--reference and --results each name a results folder: give one of them")
    if getattr(args, "reference", False):
        return paths.reference_results()
    return Path(args.results) if args.results else paths.user_results()
