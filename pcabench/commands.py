"""Command lines that make a run again, written from its whole spec: the one place a printed ``pcabench run``
comes from (advise's answer, the report's, a failed run's hint).

Every scene parameter away from its scene kind's default is written as the option that sets it (the
parameter table, pcabench/parameters.py), every word quoted for the shell (shlex): a stored row from a
shared store cannot plant shell syntax in a line the user pastes.
"""

from __future__ import annotations

import math
import shlex

from pcabench.parameters import PARAMETERS, number_word
from pcabench.spec import SERIAL, RunSpec
from solvers import DEFAULT_SCENE, DEFAULT_SOLVER, kernel_named, resolve_pair_loop

DOMAIN = ("x_min", "x_max", "y_min", "y_max")
NO_OPTION = ("rho0", "c0", "blowup_factor")  # Scene parameters a command line does not set


def _same(a, b) -> bool:
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        return math.isclose(a, b, rel_tol=1e-12, abs_tol=1e-15)
    return a == b


def run_words(spec: RunSpec) -> tuple[list[str], list[str]]:
    """(the words of the ``pcabench run`` command that makes ``spec``'s run again, the scene parameters no
    option can set where they are away from their defaults: a run a command line cannot make)."""
    return words_of(spec.solver, spec.scene, spec.threads, spec.pair_loop)


def words_of(solver: str, scene, threads=SERIAL, pair_loop: str = "") -> tuple[list[str], list[str]]:
    """:func:`run_words` of a run given by parts (a stored run's solver need not be installed here)."""
    words = ["pcabench", "run", "--solver", solver or DEFAULT_SOLVER]
    if scene.name != DEFAULT_SCENE:
        words += ["--scene", scene.name]
    words += ["--dx", number_word(scene.dx)]
    words += ["--t-end", number_word(scene.t_end)] if scene.t_end is not None else ["--steps", str(scene.steps)]
    unset = []
    domain = {k: getattr(scene, k) for k in DOMAIN}
    defaults = {k: scene.default_of(k) for k in DOMAIN}
    wall_written = False
    if not all(_same(domain[k], defaults[k]) for k in DOMAIN):
        try:
            sized = scene.kind.sized_domain(scene.x_max - scene.x_min)
        except ValueError:
            sized = None
        if sized is not None and all(_same(domain[k], sized[k]) for k in DOMAIN):
            words += ["--domain-size", number_word(scene.x_max - scene.x_min)]
            wall_written = True
        elif not all(_same(domain[k], defaults[k]) for k in DOMAIN if k != "x_max"):
            unset += [k for k in DOMAIN if k != "x_max" and not _same(domain[k], defaults[k])]
    if scene.strip_height is not None:
        words += ["--strip-height", number_word(scene.strip_height)]
    for x, y in scene.probes:
        words += ["--probe", f"{number_word(x)},{number_word(y)}"]
    for par in (p for p in PARAMETERS if p.field != "name"):  # every parameter the table declares
        value, default = getattr(scene, par.field), scene.default_of(par.field)
        if _same(value, default):
            continue
        if par.field == "x_max" and (wall_written or not scene.kind.walls):
            if not wall_written:
                unset.append("x_max")  # a wall-less scene's right edge: only --domain-size sets it
            continue
        if par.field == "cutoff_factor" and kernel_named(scene.kernel).support is not None:
            continue  # a compact kernel is cut at its support, whatever the factor says
        words += par.words(value)
    unset += [k for k in NO_OPTION if not _same(getattr(scene, k), scene.default(k))]
    if int(threads) != SERIAL:
        words += ["--threads", str(int(threads))]
    if pair_loop not in ("", "auto"):
        try:
            chosen = resolve_pair_loop(solver, scene, "auto")
        except Exception:  # noqa: BLE001 - a solver not installed here: its loop is written as stored
            chosen = None
        if pair_loop != chosen:
            words += ["--pair-loop", pair_loop]
    return words, unset


def run_command(spec: RunSpec) -> str:
    """:func:`run_words` as one line for the shell, with a note of what it cannot set (if anything)."""
    return line_of(*run_words(spec))


def line_of(words: list[str], unset: list[str]) -> str:
    """Command words as one line for the shell (shlex), with a note of what they cannot set (if anything)."""
    line = shlex.join(words)
    return line + (f"  # not settable from the command line: {', '.join(unset)}" if unset else "")
