"""Run one scene on one solver: the six timed stages, blow-up detection, errors.

A run that blows up (non-finite fields, or max|u| past the scene's bound) stops
at once and is recorded with status ``unstable`` and its step; a device
out-of-memory is recorded as ``out-of-memory``. Neither is a crash.
"""

from __future__ import annotations

import contextlib
import math
import os
import sys

import numpy as np

from pcabench.errors import StoreError
from pcabench.execute.clock import clock_for
from pcabench.machine.memory import is_out_of_memory
from pcabench.spec import RunSpec
from pcabench.store.record import RunRecord
from solvers import SceneError, jitcache, make_solver
from solvers.boundaries.bodies import BodyEntered
from solvers.corrections import SingularMoments
from solvers.fields import Fields
from solvers.physics.integrators import step_program
from solvers.reference.dispersion import predicted_primary
from solvers.scenes.base import plane_z, scored_axes

FIELD_NAMES = ("x", "y", "u", "v", "drho")  # a run's final fields (solvers.interface.Fields), each one per particle
FIELD_NAMES_3D = ("z", "w")  # and a 3D run's


def field_names(fields) -> tuple:
    """The per-particle fields ``fields`` holds: FIELD_NAMES, and a 3D run's z and w."""
    return FIELD_NAMES + (FIELD_NAMES_3D if getattr(fields, "z", None) is not None else ())


PROBE_SAMPLES = 1000  # the most readings a run records at each probe point (every few steps, evenly)


TIME_RTOL = 1e-6  # the fields' time against steps x dt (a sum of steps rounds at 1e-16 a step)


def fields_problem(fields, n_particles: int, t_expected: float | None = None) -> str:
    """Why ``fields`` (solvers.interface.Fields) are not a run's result for ``n_particles`` ('' if they are; a
    scene's ``n_scored``: an open edge's layers are not in them): an array of another length, or values that
    are not finite, or a time that is not, or (``t_expected``: the steps taken x dt, s) another time than the
    steps reach: a solver's word for its own time is checked, never taken."""
    for name in field_names(fields):
        values = np.asarray(getattr(fields, name))
        if values.shape != (n_particles,):
            return f"its field {name} has shape {values.shape}, not ({n_particles},) (one value per particle)"
        if not np.issubdtype(values.dtype, np.number) or not np.isfinite(values).all():
            return f"its field {name} holds values that are not finite numbers"
    if not math.isfinite(float(fields.t)) or fields.t < 0:
        return f"its time t = {fields.t!r} is not a finite time >= 0"
    if t_expected is not None and not abs(float(fields.t) - t_expected) <= TIME_RTOL * max(t_expected, 1e-300):
        return f"its time t = {float(fields.t):.9g} s is not the {t_expected:.9g} s its steps reach (steps x dt)"
    return ""


def reflected(scene, fields) -> dict:
    """What the open edges of a run sent back, apart from the method's own dispersive tail: the `linear` run's
    primary field against the dispersion prediction on an unbounded lattice (a perfect absorber's answer, exact
    for `linear`: solvers/reference/dispersion.unbounded) at its sites, ``reflected_amplitude`` (the largest
    difference over the initial pulse's peak) and ``reflected_energy`` (the sum of its squares over the initial
    primary field's, per site). Nothing for a closed scene, or for the moving models, whose prediction is their
    linear part only. The run's scorer adds it (:func:`score`), so that a prediction is never scored by itself."""
    if scene.model != "linear" or not scene.open or scene.body is not None or scene.dims == 3:  # no prediction
        return {}
    primary = fields.drho if scene.kind.primary == "drho" else fields.u
    d = np.asarray(primary, float) - predicted_primary(scene, fields)
    x, y = scored_axes(scene)
    gx, gy = np.meshgrid(x, y)
    u0, _v0, drho0 = scene.kind.initial_fields(scene, gx.ravel(), gy.ravel(), np)
    start = np.asarray(drho0 if scene.kind.primary == "drho" else u0, float)
    if not np.all(np.isfinite(d)):
        return {"reflected_amplitude": float("nan"), "reflected_energy": float("nan")}
    return {
        "reflected_amplitude": float(np.abs(d).max() / np.abs(start).max()),
        "reflected_energy": float(np.mean(d**2) / np.mean(start**2)),
    }


def score(record: RunRecord, scene, fields) -> RunRecord:
    """Score a run that finished its steps (``record``, status not ``unstable``) by its final ``fields``
    against the scene's exact solution: MSE, ME, the scene's other measures and the isothermal MSE, and the
    status ``ok``. ``error`` with one line saying why where the fields are not one finite value per particle at
    the time the record's steps reach, where scoring them raises, or where the error is not finite. The
    harness does this, never the solver: a run's errors are computed, not reported."""
    why = fields_problem(fields, scene.n_scored, t_expected=record.steps * scene.dt)
    if not why:  # the bounds the run checks at every step (run)
        why = past_bound(scene, field_extremes(fields), "reaches", "past the bound the run checks at every step")
    if not why:
        try:
            _measure(record, scene, fields)
        except Exception as exc:  # noqa: BLE001 - whatever the fields make the scorer do: this run's error
            why = f"scoring its fields raised {type(exc).__name__}: {' '.join(str(exc).split())[:200]}"
    if not why and (math.isinf(record.mse) or not math.isfinite(record.me)):  # (NaN: the exact field is 0 there)
        why = f"its error is not a finite number (relative RMS {record.mse!r}, max {record.me!r})"
    if why:
        record.status, record.failed_step = "error", record.steps or None
        record.mse = record.me = float("nan")
        record.errors, record.probes, record.plane, record.mse_isothermal = {}, {}, {}, None
        record.measure, record.headline = "", None
        record.message = (record.message + "\n" if record.message else "") + f"the run's result is not usable: {why}"
        return record
    record.status = "ok"
    return record


def field_extremes(fields) -> dict:
    """:meth:`solvers.interface.Solver.extremes` of final ``fields`` (checked finite and whole)."""
    velocity = [np.asarray(getattr(fields, n), float) for n in ("u", "v", "w") if getattr(fields, n, None) is not None]
    return {
        "velocity": max(float(np.abs(a).max(initial=0.0)) for a in velocity),
        "drho": float(np.abs(np.asarray(fields.drho, float)).max(initial=0.0)),
    }


def past_bound(scene, extremes: dict, verb: str, when: str) -> str:
    """'' where every field of ``extremes`` ({field: max |value|}) is finite and within the scene's blow-up bound
    (Scene.blowup_bounds), else one line naming the first that is not, its value, ``when``, and its bound."""
    for field, (bound, unit, formula) in scene.blowup_bounds.items():
        value = extremes.get(field, 0.0)
        if not math.isfinite(value):
            return f"{field} is not finite {when}"
        if value > bound:
            return f"max|{field}| {verb} {value:.3g} {unit} {when} (bound {bound:.3g} {unit} = {formula})"
    return ""


def _measure(record: RunRecord, scene, fields) -> None:
    """The errors of fields that passed :func:`fields_problem`, into ``record``."""
    record.t_end = float(fields.t)
    measures = dict(scene.kind.errors(scene, fields))  # against the scene's exact linear solution
    record.mse, record.me = measures.pop("mse"), measures.pop("me")
    record.errors = {**measures, **reflected(scene, fields)}  # open edges: what they sent back (linear runs)
    if fields.probes:  # p(t) at the probe points (scored by the scene's errors), kept rounded for the figures
        record.probes = {k: [float(f"{v:.6g}") for v in np.asarray(vals, float)] for k, vals in fields.probes.items()}
    if scene.dims == 3:  # the final drho on the plane nearest z = 0, for the report's slice
        record.plane = plane_z(fields, scene.dx, 0.0)
    if scene.kind.has_isothermal:  # every model against the nonlinear physics: which model a scene needs
        record.mse_isothermal = scene.kind.isothermal_errors(scene, fields)
    record.measure = scene.kind.measure(scene, record.t_end)  # the one error that means something at its end
    record.headline = scene.kind.measure_value(record.measure, record.mse, record.errors)


def save_fields(fields, path) -> None:
    """Write a run's final fields to the .npz ``path`` (safeio: whole or not at all, no link followed), or to a
    VTK unstructured grid where ``path`` ends in .vtu (pcabench/execute/vtu.py: ParaView opens it)."""
    import io

    from pcabench.store.safeio import write_file

    if str(path).endswith(".vtu"):
        from pcabench.execute.vtu import write_vtu

        return write_vtu(fields, path)
    buffer = io.BytesIO()
    probes = {f"probe.{k}": np.asarray(v, dtype=np.float64) for k, v in (fields.probes or {}).items()}
    np.savez(buffer, **{name: getattr(fields, name) for name in field_names(fields)}, t=fields.t, **probes)
    write_file(path, buffer.getvalue())


def load_fields(path):
    """The fields an .npz of :func:`save_fields` holds (solvers.interface.Fields); OSError or ValueError if it
    is not one."""

    with np.load(path, allow_pickle=False) as data:
        probes = {k[len("probe.") :]: data[k] for k in data.files if k.startswith("probe.")}
        third = {name: data[name] for name in FIELD_NAMES_3D if name in data.files}
        return Fields(**{name: data[name] for name in FIELD_NAMES}, **third, t=float(data["t"]), probes=probes or None)


class Probes:
    """drho at a scene's probe points, read every few steps (at most PROBE_SAMPLES readings, evenly in steps)."""

    def __init__(self, solver, points: dict, n_steps: int):
        self.solver, self.names = solver, list(points)
        self.points = np.array([points[k] for k in self.names], dtype=np.float64)
        self.stride = max(1, math.ceil(n_steps / PROBE_SAMPLES))
        self.t, self.values = [], []

    def read(self, step: int) -> None:
        if step % self.stride == 0:
            self.t.append(self.solver.t)
            self.values.append(self.solver.sample(self.points))

    def series(self) -> dict:
        values = np.array(self.values).reshape(len(self.t), len(self.names))
        return {"t": np.array(self.t), **{k: values[:, i] for i, k in enumerate(self.names)}}


def run(spec: RunSpec, machine: str = "", fields_path=None, progress=None, scored: bool = True) -> RunRecord:
    """Run ``spec`` on machine ``machine`` (its :func:`~pcabench.machine.profiles.machine_id`); its record.

    ``spec`` is resolved where the command or sweep starts (an unresolved one is resolved here, for
    scripts). The final fields go to the .npz ``fields_path`` if given. Without ``scored`` a run that
    finished its steps keeps status ``error`` and no errors: a sweep's child, whose parent scores the fields
    it wrote (:func:`score`). Never raises for a failed run: bad input (SceneError) is the caller's to report."""
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
        points = scene.probe_points()
        probes = Probes(solver, points, scene.n_steps) if points else None
        for step in range(1, scene.n_steps + 1):
            for stage, op in step_program(scene.integrator, solver, first=(step == 1)):
                clock.time(stage, op)
            if probes is not None:
                probes.read(step)  # outside the timed stages, like the amplitude check
            blew = past_bound(scene, solver.extremes(), "=", f"at step {step}")
            if blew:
                record.status, record.failed_step = "unstable", step
                record.message = blew
                break
            if progress is not None:
                progress(step, scene.n_steps)
        record.steps = step
        fields = clock.time("output", solver.output)
        if probes is not None:
            fields.probes = probes.series()
        record.stages = clock.totals()
        record.t_end = float(fields.t)
        if fields_path is not None:
            save_fields(fields, fields_path)
        if record.status != "unstable":
            record.mean_neighbours = solver.mean_neighbours()
            if scored:
                score(record, scene, fields)
    except (SceneError, StoreError):
        raise  # bad input, or a file that cannot be written (a full disk), is the caller's to report
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
        if record.status == "error" and not isinstance(exc, (BodyEntered, SingularMoments)):  # the message says it all
            import traceback

            record.message += "\n" + traceback.format_exc(limit=8)
    return record


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
