"""Run one scene on one solver: the six timed stages, blow-up detection, errors.

A run that blows up (non-finite fields, or max|u| past the scene's bound) stops
at once and is recorded with status ``unstable`` and its step; a device
out-of-memory is recorded as ``out-of-memory``. Neither is a crash.
"""

from __future__ import annotations

import contextlib
import math
import os
import signal
import sys

from solvers import SceneError, jitcache, make_solver
from solvers.integrators import step_program

from .clock import clock_for
from .memory import is_out_of_memory
from .record import RunRecord
from .spec import RunSpec


def run(spec: RunSpec, machine: str = "", fields_path=None, progress=None) -> RunRecord:
    """Run ``spec`` on machine ``machine`` (its :func:`~pcabench.profiles.machine_id`); its record.

    ``spec`` is resolved where the command or sweep starts (an unresolved one is resolved here, for
    scripts). Never raises for a failed run: bad input (SceneError) is the caller's to report."""
    spec = spec.resolved()
    scene = spec.scene
    solver = make_solver(spec.solver, threads=spec.threads, pair_loop=spec.pair_loop)
    record = RunRecord.from_spec(spec, machine)
    step = 0
    try:
        clock = None
        # JIT compilation and the first launch, on a tiny scene, outside the timed region.
        solver.input(scene)
        before = jitcache.counts()["compiled"]
        record.jit_seconds = solver.warmup()
        record.jit_cached = jitcache.counts()["compiled"] == before
        solver = make_solver(spec.solver, threads=spec.threads, pair_loop=spec.pair_loop)
        clock = clock_for(solver)
        clock.time("input", solver.input, scene)
        clock.time("init", solver.init)
        bound = scene.blowup_factor * scene.mach * scene.c0
        for step in range(1, scene.n_steps + 1):
            for stage, op in step_program(scene.integrator, solver, first=(step == 1)):
                clock.time(stage, op)
            amp = solver.amplitude()
            if not math.isfinite(amp) or amp > bound:
                record.status, record.failed_step = "unstable", step
                record.message = (
                    f"max|u| = {amp:.3g} m/s at step {step} (bound {bound:.3g} = blowup_factor * mach * c0)"
                )
                break
            if progress is not None:
                progress(step, scene.n_steps)
        record.steps = step
        fields = clock.time("output", solver.output)
        if fields_path is not None:
            fields.save(fields_path)
        record.stages = clock.totals()
        record.t_end = fields.t
        if record.status != "unstable":
            record.status = "ok"
            measures = scene.kind.errors(scene, fields)  # against the scene's exact linear solution
            record.mse, record.me = measures.pop("mse"), measures.pop("me")
            record.errors = measures
            if scene.kind.has_isothermal:  # every model against the nonlinear physics: which model a scene needs
                record.mse_isothermal = scene.kind.isothermal_errors(scene, fields)
            record.mean_neighbours = solver.mean_neighbours()
    except SceneError:
        raise  # bad input is the caller's to report, not a run result
    except Exception as exc:  # noqa: BLE001 - a failed run is a result, not a crash
        record.steps = step
        record.failed_step = step or None
        record.status = "out-of-memory" if is_out_of_memory(exc) else "error"
        record.message = f"{type(exc).__name__}: {exc}"
        if clock is not None:
            try:
                record.stages = clock.totals()
            except Exception:  # noqa: BLE001
                pass
        if record.status == "error":
            import traceback

            record.message += "\n" + traceback.format_exc(limit=8)
    return record


class RunBudgetSpent(BaseException):
    """``pcabench run --run-budget`` ran out (a BaseException: a run records every Exception as its own)."""


@contextlib.contextmanager
def run_budget(seconds: float | None):
    """RunBudgetSpent in this (main) thread once ``seconds`` have passed (checked between Python steps of
    the run, so a step of compiled code ends first); nothing if ``seconds`` is None."""
    if seconds is None:
        yield
        return

    def spent(signum, frame):
        raise RunBudgetSpent()

    before = signal.signal(signal.SIGALRM, spent)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, before)


@contextlib.contextmanager
def solver_output_to_stderr(on: bool):
    """With ``on``, whatever the run prints on stdout (Python's sys.stdout and file descriptor 1, so compiled
    code too) goes to stderr: `run --json` prints exactly one object on stdout, whatever the solver prints."""
    if not on:
        yield
        return
    sys.stdout.flush()
    saved = os.dup(1)
    os.dup2(2, 1)
    try:
        with contextlib.redirect_stdout(sys.stderr):
            yield
    finally:
        sys.stdout.flush()
        os.dup2(saved, 1)
        os.close(saved)
