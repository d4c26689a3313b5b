"""The conformance suite: what every solver must do, checked on the solver itself.

Every registered solver passes it (tests/test_conformance.py), and a plug-in
author runs it on their own solver, the way scikit-learn's ``check_estimator``
serves estimator authors::

    pcabench check-solver NAME [--quick] [--json]

    from pcabench.conformance import assert_conforms
    assert_conforms(MySolver, quick=True)  # AssertionError listing what failed

Each check is a small function below whose docstring says what it
guarantees: agreement with the all-pair reference to round-off for every
configuration the class claims, neighbour counting without side effects,
``memory_bytes`` as an upper bound, threaded runs equal to serial ones, timed
stages and a blow-up reported as unstable with its step, and the class's
claims (precisions, models, integrators, kernels, corrections, boundaries) true both ways.
A check that needs what this machine lacks (no GPU: SolverUnavailable) is
skipped with the reason, never failed. The GPU solver runs them in numba's
CUDA simulator when ``NUMBA_ENABLE_CUDASIM=1`` is set.

The scenes are tiny (dx = 1 m: 320, 400 and twice 182 particles, a few steps), so the
suite's time is numba's compilation of each configuration (``--quick``: the
defaults and each claimed value once, not the full product).
"""

from __future__ import annotations

import gc
import itertools
import json
import math
import os
import sys
import time
import tracemalloc
from contextlib import contextmanager
from dataclasses import asdict, dataclass

import numpy as np

from solvers import (
    DEFAULT_SCENE,
    INTEGRATORS,
    MODELS,
    PRECISIONS,
    Scene,
    SceneError,
    SolverUnavailable,
    kernel_names,
    scenes,
    solver_class,
)
from solvers.corrections import DEFAULT_CORRECTION, correction_names
from solvers.interface import STAGES, Solver
from solvers.physics.integrators import advance_steps, evolve
from solvers.registry import SOLVERS

REFERENCE = "allpair-cpu"  # the all-pair search: every pair tested, no cell list to get wrong
TOLERANCE = {"float64": 1e-12, "float32": 2e-5}  # relative to the field's max: round-off of a few steps
# the paper's scene at 3,200 particles, checked once with the defaults: a solver wrong only past the tiny lattices'
# few hundred particles (its cells, blocks or threads laid out otherwise) fails here
LARGER = "plane-pulse-3200"
LARGER_SCENE = dict(dx=0.5, x_min=-20.0, x_max=20.0)


def scene_cases() -> dict[str, dict]:
    """The conformance scenes (Scene fields, name included): every registered scene kind at its smallest
    (SceneKind.smallest: free-x, x-periodic, walled at one and at both x ends, a body), with open edges where the
    kind has such a case (``<name>-open``, SceneKind.smallest_open), and :data:`LARGER`. Read at each check: a
    scene kind registered since (a plug-in) is checked too, with no list to edit."""
    out = {}
    for name, kind in scenes().items():
        out[name] = {"name": name, **kind.smallest}
        if kind.smallest_open is not None:
            out[f"{name}-open"] = {"name": name, **kind.smallest_open}
    out[LARGER] = dict(LARGER_SCENE)
    return out


SCENES = scene_cases()  # the built-in kinds' (the GPU check's rehearsal plan reads them at import)
AXES = ("precision", "model", "integrator", "kernel", "correction")  # Scene fields a class claims values of
ALL_VALUES = {"precision": PRECISIONS, "model": MODELS, "integrator": INTEGRATORS}  # kernels, corrections: all_values
CLAIMS = {
    "precision": "precisions",
    "model": "models",
    "integrator": "integrators",
    "kernel": "kernels",
    "correction": "corrections",
}


def all_values(axis: str) -> tuple:
    """Every value of Scene field ``axis``: the kernels and corrections are their registries' now (one registered
    later counts)."""
    if axis == "kernel":
        return kernel_names()
    if axis == "correction":
        return correction_names()
    return ALL_VALUES[axis]


PYTHON_OBJECTS = 16 * 1024  # B: the interpreter's own objects in a run (solver, dicts, scalars; ~9 KiB measured)
BLOWUP = dict(model="linear", integrator="euler", cfl=5.0, steps=200)  # forward Euler far past its CFL


@dataclass
class CheckResult:
    """One check's outcome: ``status`` ok, failed or skipped, with the reason (failed, skipped) or a note."""

    name: str
    status: str
    message: str = ""
    seconds: float = 0.0

    @property
    def failed(self) -> bool:
        return self.status == "failed"

    def line(self) -> str:
        """``name: ok``, ``name: FAILED: reason`` or ``name: skipped: reason`` (one line)."""
        word = {"ok": "ok", "failed": "FAILED", "skipped": "skipped"}[self.status]
        text = " ".join(self.message.split())
        sep = " " if self.status == "ok" else ": "
        note = f"{sep}({text})" if self.status == "ok" and text else (f"{sep}{text}" if text else "")
        return f"{self.name}: {word}{note} [{self.seconds:.1f} s]"


class Skip(Exception):
    """Raised by a check that cannot run here; the message is the reason."""


class Failure(AssertionError):
    """Raised by a check that found the solver wrong; the message lists what."""


# ---------------------------------------------------------------- the solver under test
SIMULATED_MOST = 4_000  # particles of a case run in numba's CUDA simulator (Python threads: seconds a step)
QUADRATIC_MOST = 5_000  # particles of a case an all-pair class checks itself on (N^2 pairs a sweep)


class Subject:
    """The class under test, its configurations and their runs (each run once, shared by the checks)."""

    def __init__(self, cls: type[Solver], quick: bool):
        self.cls, self.quick = cls, quick
        self.steps = 2 if quick else 6
        # numba-cuda's simulator runs a GPU class's threads in Python: the larger lattice is checked on a card only
        self.simulated = cls.device == "gpu" and os.environ.get("NUMBA_ENABLE_CUDASIM") == "1"
        self.runs: dict = {}
        self.cases = scene_cases()  # every scene kind registered now, at its smallest

    def default(self, axis: str) -> str:
        """The Scene's default value of ``axis`` if the class claims it, else its first claimed value."""
        claimed = getattr(self.cls, CLAIMS[axis])
        return Scene.default(axis) if Scene.default(axis) in claimed else claimed[0]

    def claimed_scenes(self) -> list[str]:
        """The scene cases whose boundaries the class claims."""
        return [
            name
            for name in self.cases
            if name != LARGER and set(self.scene(name=name).boundaries) <= set(self.cls.boundaries)
        ]

    def run_scenes(self) -> list[str]:
        """The claimed scene cases the checks run: in numba's CUDA simulator those of at most ``SIMULATED_MOST``
        particles (a GPU class's larger cases, the 3D body's, are run on a card: ``pcabench gpu-check``); for a
        class whose cost grows as N^2 (all-pair) those of at most ``QUADRATIC_MOST`` (its larger cases run as the
        reference of every cell list's agreement)."""
        most = SIMULATED_MOST if self.simulated else QUADRATIC_MOST if self.cls.order >= 2 else None
        claimed = self.claimed_scenes()
        return [name for name in claimed if most is None or self.scene(name=name).n_particles <= most]

    def scene(self, name: str = "plane-pulse", steps: int | None = None, **method) -> Scene:
        """A conformance scene: ``name``'s tiny lattice with the class's defaults and ``method`` on top."""
        base = {axis: self.default(axis) for axis in AXES if getattr(self.cls, CLAIMS[axis], None)}
        case = self.cases[name]
        if needs_correction(case) and base.get("correction") == DEFAULT_CORRECTION:
            base.pop("correction")  # the case's own (a 3D body's wall is the corrected operators')
        return Scene(**{**case, "steps": steps or self.steps, **base, **method})

    def configurations(self) -> list[dict]:
        """(scene name, method, pair loop) to check: the full product, or (quick) the defaults and each
        claimed value once, and each walled scene with every claimed model (a wall's mirrors are set once for
        particles that stay on the lattice and follow moving ones every step: two paths)."""
        axes = {axis: tuple(getattr(self.cls, CLAIMS[axis])) for axis in AXES}
        axes["scene"] = tuple(self.run_scenes())
        axes["pair_loop"] = tuple(self.cls.pair_loops)
        base = {axis: (self.default(axis) if axis in AXES else values[0]) for axis, values in axes.items()}
        larger = [{**base, "scene": LARGER}] if "plane-pulse" in axes["scene"] and not self.simulated else []
        if not self.quick:
            every = [dict(zip(axes, values)) for values in itertools.product(*axes.values())]
            return [c for c in every if self.runs_loop(c)] + larger
        out = [base, *larger]
        for axis, values in axes.items():
            out += [{**base, axis: value} for value in values if value != base[axis]]
        out = [c for c in out if self.runs_loop(c)]
        walled = [name for name in axes["scene"] if Scene(**self.cases[name]).walls]
        out += [
            {**base, "scene": name, "model": model}
            for name in walled
            for model in axes["model"]
            if model != base["model"]
        ]
        return out

    def runs_loop(self, config: dict) -> bool:
        """Whether the configuration's pair loop is one the class runs on its scene (``pair_loops_for``: a 3D
        scene sums its pairs on the fly)."""
        if config["scene"] == LARGER:
            return True
        case = self.cases[config["scene"]]
        if needs_correction(case) and config.get("correction") == DEFAULT_CORRECTION:
            return False  # a 3D body is refused uncorrected (its one wall is the corrected operators')
        return config["pair_loop"] in self.cls.pair_loops_for(Scene(**case))

    def scene_of(self, config: dict) -> Scene:
        return self.scene(config["scene"], **{axis: config[axis] for axis in AXES})

    def make(self, threads: int = 1, pair_loop: str = "auto") -> Solver:
        self.cls.available()
        return self.cls(threads=threads, pair_loop=pair_loop)

    def evolve(self, scene: Scene, threads: int = 1, pair_loop: str = "auto", reference: bool = False, between=None):
        """(final fields, solver) of ``scene`` stepped with the primitives; each one run once.
        ``between(solver)`` is called after every step."""
        pair_loop = self.cls.pair_loops_for(scene)[0] if pair_loop == "auto" and not reference else pair_loop
        key = (reference, scene, threads, pair_loop, between is None)
        if between is not None or key not in self.runs:
            solver = solver_class(REFERENCE)() if reference else self.make(threads, pair_loop)
            solver.input(scene)
            solver.init()
            each = None if between is None else (lambda: between(solver))
            advance_steps(solver, scene.integrator, scene.n_steps, each=each)
            result = (solver.output(), solver)
            if between is not None:
                return result
            self.runs[key] = result
        return self.runs[key]


def needs_correction(case: dict) -> bool:
    """Whether a conformance scene is run only with a kernel correction (a 3D body: solvers/boundaries/body3d.py)."""
    kind = scenes()[case.get("name", DEFAULT_SCENE)]
    return bool(kind.body and kind.dims == 3)


def label(config: dict) -> str:
    return "/".join(str(config[k]) for k in ("scene", *AXES, "pair_loop"))


def compare(got, ref, scene: Scene, tol: float) -> list[str]:
    """Where fields ``got`` differ from ``ref`` by more than ``tol`` of the field's max: velocity (u, v),
    displacement from the lattice (x, y, across a periodic seam by the nearest image) and drho."""
    ids = np.arange(scene.n_particles)
    column = ids % scene.nx
    row = ids // scene.nx % scene.ny
    if scene.dims == 3:  # the output's particles: an open face's layer left out
        layer = ids // (scene.nx * scene.ny)
        scored = scene.scored_3d(column, row, layer)
    else:
        scored = scene.scored(column, row)  # the output's particles: an open edge's layer left out
    x0 = (scene.x_lo + (column + 0.5) * scene.dx)[scored]
    y0 = (scene.y_lo + (row + 0.5) * scene.dx)[scored]

    def seam(d, period):
        return d - period * np.rint(d / period) if period else d

    axes = [("x", x0, scene.width if scene.periodic_x else 0), ("y", y0, scene.height if scene.periodic_y else 0)]
    velocity = ["u", "v"]
    if scene.dims == 3:
        z0 = (scene.z_lo + (layer + 0.5) * scene.dx)[scored]
        axes.append(("z", z0, scene.depth if scene.periodic_z else 0))
        velocity.append("w")
    groups = {
        "velocity": ([getattr(got, c) for c in velocity], [getattr(ref, c) for c in velocity]),
        "displacement": (
            [seam(getattr(got, c) - at, period) for c, at, period in axes],
            [seam(getattr(ref, c) - at, period) for c, at, period in axes],
        ),
        "drho": ([got.drho], [ref.drho]),
    }
    out = []
    for what, (g, r) in groups.items():
        scale = max(float(np.abs(a).max()) for a in r)
        diff = max(float(np.abs(a - b).max()) if np.all(np.isfinite(a)) else math.inf for a, b in zip(g, r))
        if not diff <= tol * scale:
            rel = diff / scale if scale else diff
            out.append(f"{what} differs by {rel:.3g} of its max (tolerance {tol:g})")
    return out


def first_line(text) -> str:
    return (text or "").strip().splitlines()[0] if (text or "").strip() else ""


def host(solver: Solver, arr) -> np.ndarray:
    return np.array(solver.to_host(arr), copy=True)


def snapshot(solver: Solver) -> dict:
    """Every array the solver holds (its per-particle arrays, saved copies and array attributes) and its time,
    as host copies."""
    out = {f"arrays[{k}]": host(solver, v) for k, v in solver.arrays.items()}
    out.update({f"saved[{k}]": host(solver, v) for k, v in solver.saved.items()})
    out.update(
        {
            k: host(solver, v)
            for k, v in vars(solver).items()
            if isinstance(v, np.ndarray) or hasattr(v, "__cuda_array_interface__")
        }
    )
    out["t"] = np.array(solver.t)
    return out


def changed(before: dict, after: dict) -> list[str]:
    return sorted(
        k
        for k in before.keys() | after.keys()
        if k not in before or k not in after or not np.array_equal(before[k], after[k], equal_nan=True)
    )


def lattice_neighbours(scene: Scene) -> float:
    """The mean count of other lattice particles within the cutoff (periodic axes by the nearest image), and
    of mirror particles across each rigid wall (the wall half a spacing past the edge column: column c's
    image is column -1 - c across the left wall, 2 nx - 1 - c across the right one), by brute force in NumPy.
    A body's ghost particles count where its boundary method places them (rings: off the lattice)."""
    if scene.dims == 3:
        return lattice_neighbours_3d(scene)
    ids = np.arange(scene.n_particles)
    column, y = ids % scene.nx, (ids // scene.nx) * scene.dx
    if scene.body is not None:
        from solvers.boundaries.body import RigidBody

        x = scene.x_lo + (column + 0.5) * scene.dx
        _role, sx, sy = RigidBody(scene).place(x, scene.y_lo + y + 0.5 * scene.dx)
        px, py = x + sx, y + sy
        d2 = (px[:, None] - px[None, :]) ** 2 + (py[:, None] - py[None, :]) ** 2
        return float(((d2 < scene.cutoff**2).sum() - scene.n_particles) / scene.n_particles)
    images = {"x_min": -1 - column, "x_max": 2 * scene.nx - 1 - column}
    dy = y[:, None] - y[None, :]
    if scene.periodic_y:
        dy -= scene.height * np.rint(dy / scene.height)
    count = -scene.n_particles  # each particle itself
    for others in (column, *(images[edge] for edge in scene.walls)):
        dx = (column[:, None] - others[None, :]) * scene.dx
        if scene.periodic_x:
            dx -= scene.width * np.rint(dx / scene.width)
        count += int((dx * dx + dy * dy < scene.cutoff**2).sum())
    return float(count / scene.n_particles)


def lattice_neighbours_3d(scene: Scene) -> float:
    """:func:`lattice_neighbours` of a 3D lattice (the nearest image along each periodic axis)."""
    ids = np.arange(scene.n_particles)
    count = -scene.n_particles
    d2 = np.zeros((scene.n_particles, scene.n_particles))
    for site, n, periodic in (
        (ids % scene.nx, scene.nx, scene.periodic_x),
        (ids // scene.nx % scene.ny, scene.ny, scene.periodic_y),
        (ids // (scene.nx * scene.ny), scene.nz, scene.periodic_z),
    ):
        d = (site[:, None] - site[None, :]).astype(float)
        if periodic:
            d -= n * np.rint(d / n)
        d2 += (d * scene.dx) ** 2
    return float((count + int((d2 < scene.cutoff**2).sum())) / scene.n_particles)


@contextmanager
def registered(cls: type[Solver]):
    """``cls`` found under its name by the solver registry (for the harness's own runs) while the block runs
    (a class the registry holds already is left as it is)."""
    if SOLVERS.all().get(cls.name) is cls:
        yield cls
    else:
        with SOLVERS.registered(cls):
            yield cls


# ---------------------------------------------------------------- the checks
CHECKS: list = []


def check(fn):
    """Register ``fn(subject) -> str`` (a note) as a check; it raises Failure or Skip."""
    CHECKS.append(fn)
    return fn


@check
def agreement(subject: Subject) -> str:
    """The final fields (u, v, drho and the displacement from the lattice) agree with the all-pair
    reference (``allpair-cpu``) to round-off (float64: 1e-12 of the field's max; float32: 2e-5) after a few
    steps, for every model, precision, integrator, kernel, pair loop and scene the class claims (quick:
    the defaults and each claimed value once)."""
    configs, problems, failed = subject.configurations(), [], 0
    for config in configs:
        scene = subject.scene_of(config)
        ref, _ = subject.evolve(scene, reference=True)
        try:
            got, _ = subject.evolve(scene, pair_loop=config["pair_loop"])
        except SceneError as exc:
            problems.append(f"{label(config)}: refused ({exc})")
            failed += 1
            continue
        found = compare(got, ref, scene, TOLERANCE[scene.precision])  # a configuration may differ in several fields
        problems += [f"{label(config)}: {p}" for p in found]
        failed += bool(found)
    if problems:
        raise Failure(
            f"{failed} of {len(configs)} configurations: "
            + "; ".join(problems[:6])
            + ("; ..." if len(problems) > 6 else "")
        )
    return f"{len(configs)} configurations"


@check
def neighbours(subject: Subject) -> str:
    """``mean_neighbours`` equals the lattice's count of neighbours within the cutoff (at t = 0, for each
    claimed scene and kernel), leaves every array the solver holds (and its time) exactly as it was, and
    counting between steps changes no result beyond round-off."""
    problems, kernels = [], subject.cls.kernels if not subject.quick else (subject.default("kernel"),)
    for name, kernel in itertools.product(subject.run_scenes(), kernels):
        scene = subject.scene(name, kernel=kernel)
        solver = subject.make()
        solver.input(scene)
        solver.init()
        counted, expected = solver.mean_neighbours(), lattice_neighbours(scene)
        if counted != expected:
            problems.append(f"{name}/{kernel}: {counted:g} neighbours on the lattice, not {expected:g}")
    scene = subject.scene(model="lagrangian" if "lagrangian" in subject.cls.models else subject.default("model"))
    touched = set()

    def count(solver):
        before = snapshot(solver)
        solver.mean_neighbours()
        touched.update(changed(before, snapshot(solver)))

    counted, _ = subject.evolve(scene, between=count)
    plain, _ = subject.evolve(scene)
    if touched:
        problems.append(f"counting changed {', '.join(sorted(touched))}")
    problems += [f"counting between steps: {p}" for p in compare(counted, plain, scene, TOLERANCE[scene.precision])]
    if problems:
        raise Failure("; ".join(problems))
    return f"lattice count {lattice_neighbours(subject.scene()):g} ({subject.scene().kernel})"


@check
def memory(subject: Subject) -> str:
    """``memory_bytes(scene, pair_loop)`` is an upper bound of the memory a run allocates: the peak traced
    by tracemalloc (NumPy's allocations are traced) over input, init and two steps, compiled beforehand,
    on a lattice of 1,280 particles, for each pair loop and precision with the default and the rk2
    integrator (which keeps copies of the state; full: every integrator and kernel correction). The trace also
    counts the interpreter's own objects (the solver, its dicts, scalars: about 9 KiB), allowed ``PYTHON_OBJECTS``.
    On a GPU: CuPy's memory pool after the same; in numba's CUDA simulator
    (host arrays and Python threads, not a device) skipped."""
    cls = subject.cls
    if cls.device == "gpu":
        probe = subject.make()
        if probe.xp is np:
            raise Skip(
                "numba's CUDA simulator holds host arrays and Python threads, not device memory: checked on a GPU"
            )
    integrators = [i for i in (subject.default("integrator"), "rk2") if i in cls.integrators]
    if not subject.quick:
        integrators = list(cls.integrators)
    precisions = list(cls.precisions)
    corrections = [subject.default("correction")] if subject.quick else list(cls.corrections)
    notes, problems = [], []
    for pair_loop, integrator, precision, correction in itertools.product(
        cls.pair_loops, dict.fromkeys(integrators), precisions, corrections
    ):
        scene = subject.scene(integrator=integrator, precision=precision, dx=0.5, steps=2, correction=correction)
        bound = cls.memory_bytes(scene, pair_loop)
        subject.evolve(scene, pair_loop=pair_loop)  # compiled and first launched outside the measurement
        used = measure(subject, scene, pair_loop)
        what = f"{pair_loop}/{integrator}/{precision}" + ("" if correction == DEFAULT_CORRECTION else f"/{correction}")
        over = f" (+{used - bound:,} B: within the {PYTHON_OBJECTS:,} B of Python objects allowed)"
        notes.append(f"{what} {used / bound:.1%}" + (over if bound < used <= bound + PYTHON_OBJECTS else ""))
        if used > bound + PYTHON_OBJECTS:
            problems.append(
                f"{what}: a run allocates {used:,} B, more than "
                f"memory_bytes {bound:,} B and {PYTHON_OBJECTS:,} B of Python objects"
            )
    if problems:
        raise Failure("; ".join(problems))
    return "peak of the bound (memory_bytes; a run may exceed it by its Python objects alone): " + ", ".join(notes)


def measure(subject: Subject, scene: Scene, pair_loop: str) -> int:
    """Bytes allocated at the peak of input, init and ``scene``'s steps on a new solver."""
    solver = subject.make(pair_loop=pair_loop)
    if solver.xp is not np:  # CuPy: its pool keeps what the run took
        pool = solver.xp.get_default_memory_pool()
        pool.free_all_blocks()
        start = pool.total_bytes()
        run_steps(solver, scene)
        solver.synchronize()
        return pool.total_bytes() - start
    gc.collect()
    tracing = tracemalloc.is_tracing()
    if not tracing:
        tracemalloc.start()
    try:
        tracemalloc.reset_peak()
        start, _ = tracemalloc.get_traced_memory()
        run_steps(solver, scene)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        if not tracing:
            tracemalloc.stop()
    return peak - start


def run_steps(solver: Solver, scene: Scene) -> None:
    evolve(solver, scene)


@check
def threads(subject: Subject) -> str:
    """A threaded class (``threaded = True``) run on 2 threads gives the serial run's fields to round-off,
    for each pair loop and claimed scene with particles that move (skipped for a serial class)."""
    cls = subject.cls
    if not cls.threaded:
        raise Skip(f"{cls.name} is serial (threaded = False)")
    import numba

    if numba.config.NUMBA_NUM_THREADS < 2:
        raise Skip(f"numba may use {numba.config.NUMBA_NUM_THREADS} thread here")
    model = "lagrangian" if "lagrangian" in cls.models else subject.default("model")
    problems, done = [], 0
    for name in subject.claimed_scenes():
        scene = subject.scene(name, model=model)
        for pair_loop in cls.pair_loops_for(scene):
            serial, _ = subject.evolve(scene, pair_loop=pair_loop)
            threaded, _ = subject.evolve(scene, threads=2, pair_loop=pair_loop)
            found = compare(threaded, serial, scene, TOLERANCE[scene.precision])
            problems += [f"{name}/{pair_loop}: {p}" for p in found]
            done += 1
    if problems:
        raise Failure("; ".join(problems))
    return f"{done} configurations on 2 threads"


@check
def stages(subject: Subject) -> str:
    """Run through the harness (pcabench.execute.run.run), the six stages are booked and SNP, PI and SU take time
    (> 0); a run that blows up (forward Euler at CFL 5 on the linear model, 200 steps) is recorded as
    ``unstable`` at the step where its amplitude passes the bound, the same step as the all-pair
    reference's, not as an error."""
    from pcabench.execute.run import run
    from pcabench.spec import RunSpec

    cls, problems = subject.cls, []
    if not cls.name:
        raise Failure("the class has no name: the harness runs solvers by name")
    scene = subject.scene()
    with registered(cls):
        record = run(RunSpec(cls.name, scene, 1, "", cls.pair_loops[0]))
        if record.status != "ok":
            raise Failure(f"a plain run ended {record.status}: {first_line(record.message)}")
        missing = [s for s in STAGES if s not in (record.stages or {})]
        idle = [s for s in ("snp", "pi", "su") if not (record.stages or {}).get(s, 0) > 0]
        if missing or idle:
            problems.append(f"stages missing {missing}, not timed {idle}: {record.stages}")
        if not all(value in getattr(cls, CLAIMS[axis]) for axis, value in BLOWUP.items() if axis in CLAIMS):
            if problems:
                raise Failure("; ".join(problems))
            return "stages timed; blow-up not checked (forward Euler on the linear model is not claimed)"
        blowup = subject.scene(**BLOWUP)
        bad = run(RunSpec(cls.name, blowup, 1, "", cls.pair_loops[0]))
    ref = run(RunSpec(REFERENCE, blowup, 1, "", solver_class(REFERENCE).pair_loops[0]))
    if bad.status != "unstable" or not bad.failed_step:
        problems.append(
            f"a blow-up ended {bad.status!r} (failed step {bad.failed_step}), not unstable: {first_line(bad.message)}"
        )
    elif bad.failed_step != ref.failed_step or bad.steps != bad.failed_step:
        problems.append(
            f"the blow-up stopped at step {bad.failed_step} (steps {bad.steps}), the reference at {ref.failed_step}"
        )
    if problems:
        raise Failure("; ".join(problems))
    return (
        f"snp/pi/su {record.stages['snp']:.2g}/{record.stages['pi']:.2g}/{record.stages['su']:.2g} s; "
        f"blow-up unstable at step {bad.failed_step}"
    )


@check
def claims(subject: Subject) -> str:
    """Each claim the class makes is true both ways: every precision, model, integrator and kernel it claims
    (and every scene whose boundaries it claims: free-x, periodic-x, wall-x) is accepted by ``supports`` and
    runs, finite; every value it does not claim is refused with SceneError by ``supports`` (in one line) and
    by ``input``; its claims name known values, and it has a name, a device and a pair loop."""
    cls, problems = subject.cls, []
    if not cls.name:
        problems.append("the class has no name")
    if cls.device not in ("cpu", "gpu"):
        problems.append(f"device {cls.device!r} is neither cpu nor gpu")
    if not cls.pair_loops:
        problems.append("no pair loop claimed")
    probes = []
    for axis in AXES:
        claimed = getattr(cls, CLAIMS[axis])
        unknown = sorted(set(claimed) - set(all_values(axis)))
        if unknown or not claimed:
            what = "unknown " + ", ".join(unknown) if unknown else "none"
            problems.append(f"{CLAIMS[axis]} {tuple(claimed)}: {what}")
        probes += [(f"{axis} {value}", subject.scene(**{axis: value}), value in claimed) for value in all_values(axis)]
    probes += [
        (f"scene {name}", subject.scene(name), name in subject.claimed_scenes())
        for name in subject.cases
        if name != LARGER
    ]
    ran = 0
    for what, scene, claimed in probes:
        try:
            cls.supports(scene)
            accepted, why = True, ""
        except SceneError as exc:
            accepted, why = False, str(exc)
        if claimed and not accepted:
            problems.append(f"{what} is claimed but supports() refuses it: {why}")
        elif not claimed:
            if accepted:
                problems.append(f"{what} is not claimed but supports() accepts it")
            elif len(why.strip().splitlines()) != 1:
                problems.append(f"{what} is refused by supports() in {len(why.strip().splitlines())} lines, not one")
            try:
                subject.make().input(scene)
                problems.append(f"{what} is not claimed but input() accepts it")
            except SceneError:
                pass
    for config in subject.configurations():  # each claimed value (and scene, pair loop) at least once
        try:
            fields, _ = subject.evolve(subject.scene_of(config), pair_loop=config["pair_loop"])
        except SceneError as exc:
            problems.append(f"{label(config)} is claimed but refused: {exc}")
            continue
        if not all(np.isfinite(getattr(fields, f)).all() for f in ("u", "v", "drho", "x", "y")):
            problems.append(f"{label(config)}: fields not finite after {subject.steps} steps")
        ran += 1
    if problems:
        raise Failure("; ".join(problems))
    return f"{len(probes)} claims probed, {ran} claimed configurations ran"


CHECK_NAMES = tuple(fn.__name__ for fn in CHECKS)


# ---------------------------------------------------------------- entry points
def target_class(solver) -> type[Solver]:
    """The class of ``solver``: a registered name (SceneError naming the choices otherwise) or a class."""
    if isinstance(solver, type):
        if not issubclass(solver, Solver):
            raise SceneError(f"solver must be a Solver subclass (got {solver.__name__})")
        return solver
    return solver_class(solver)


def _availability(cls) -> str | None:
    """Why ``cls`` cannot run here (None: it can)."""
    try:
        cls.available()
    except SolverUnavailable as exc:
        return str(exc)
    return None


def run_check(fn, subject: Subject, missing: str | None = None) -> CheckResult:
    """One check on ``subject``: ok, skipped (the machine lacks what it needs) or failed (a crash included)."""
    t0 = time.perf_counter()
    if missing is not None:
        return CheckResult(fn.__name__, "skipped", missing, 0.0)
    try:
        note, status = fn(subject), "ok"
    except (Skip, SolverUnavailable) as exc:
        note, status = str(exc), "skipped"
    except AssertionError as exc:
        note, status = str(exc), "failed"
    except Exception as exc:  # noqa: BLE001 - a solver that crashes fails the check, it does not stop the suite
        note, status = f"{type(exc).__name__}: {exc}", "failed"
    return CheckResult(fn.__name__, status, note or "", time.perf_counter() - t0)


def iter_checks(solver, quick: bool = False, only=None):
    """Run the checks on ``solver`` (a name or a Solver subclass) one at a time: a CheckResult each.
    ``only``: the names of the checks to run (default all, in :data:`CHECK_NAMES` order)."""
    cls = target_class(solver)
    unknown = sorted(set(only or ()) - set(CHECK_NAMES))
    if unknown:
        raise SceneError(f"checks must be among {', '.join(CHECK_NAMES)} (got {', '.join(unknown)})")
    subject, missing = Subject(cls, quick), _availability(cls)
    for fn in CHECKS:
        if not only or fn.__name__ in only:
            yield run_check(fn, subject, missing)


class Check:
    """One conformance check as a pytest case's callable (:func:`parametrize_with_checks`): ``check(solver)``
    passes, raises AssertionError naming what failed, or skips the test where the machine lacks what it needs."""

    def __init__(self, fn, quick: bool, subjects: dict):
        self.fn, self.quick, self.subjects = fn, quick, subjects

    def __repr__(self) -> str:
        return self.fn.__name__

    def __call__(self, solver) -> CheckResult:
        import pytest

        cls = target_class(solver)
        key = (cls, self.quick)
        if key not in self.subjects:  # one subject per solver: its reference runs are shared by its checks
            self.subjects[key] = (Subject(cls, self.quick), _availability(cls))
        result = run_check(self.fn, *self.subjects[key])
        if result.status == "skipped":
            pytest.skip(f"{self.fn.__name__}: {result.message}")
        if result.failed:
            raise AssertionError(result.line())
        return result


def parametrize_with_checks(solvers, quick: bool = True):
    """A pytest parametrize mark over every (solver, check) pair, each its own test case (scikit-learn's
    ``parametrize_with_checks``): ``-k "linkedlist-cpu and agreement"`` runs one. ``solvers``: registered names
    or Solver subclasses (a class need not be registered)::

        @parametrize_with_checks([MySolver])
        def test_my_solver_conforms(solver, check):
            check(solver)
    """
    import pytest

    subjects: dict = {}
    return pytest.mark.parametrize(
        ("solver", "check"),
        [
            pytest.param(solver, Check(fn, quick, subjects), id=f"{getattr(solver, 'name', solver)}-{fn.__name__}")
            for solver in solvers
            for fn in CHECKS
        ],
    )


def check_solver(solver, quick: bool = False, only=None) -> list[CheckResult]:
    """Every check on ``solver`` (a registered name or a Solver subclass): a CheckResult each."""
    return list(iter_checks(solver, quick, only))


def assert_conforms(solver, quick: bool = True, only=None) -> list[CheckResult]:
    """For a plug-in's own tests: AssertionError listing the failed checks, else the results."""
    results = check_solver(solver, quick, only)
    failed = [r for r in results if r.failed]
    if failed:
        name = solver if isinstance(solver, str) else solver.__name__
        raise AssertionError(
            f"{name} fails {len(failed)} conformance check(s):\n" + "\n".join(r.line() for r in failed)
        )
    return results


def main(solver: str, quick: bool = False, as_json: bool = False, out=None) -> int:
    """``pcabench check-solver``: one line per check (or one JSON object); 0 if none failed, else 1."""
    out = out or sys.stdout
    t0 = time.perf_counter()
    from pcabench.execute.progress import Heartbeat

    results, checks = [], iter_checks(solver, quick)
    while True:
        with Heartbeat(f"check-solver {solver}: check {len(results) + 1} running"):  # a check of minutes says so
            result = next(checks, None)
        if result is None:
            break
        results.append(result)
        if not as_json:
            print(result.line(), file=out, flush=True)
    failed = any(r.failed for r in results)
    if as_json:
        text = json.dumps(
            {
                "solver": solver,
                "quick": quick,
                "ok": not failed,
                "seconds": time.perf_counter() - t0,
                "checks": [asdict(r) for r in results],
            }
        )
        if out is sys.stdout:
            from pcabench import jsonout

            jsonout.emit(text)
        else:
            print(text, file=out)
    else:
        word = "FAILED" if failed else "conforms" if any(r.status == "ok" for r in results) else "not checked here"
        print(
            f"{solver}: {word} ({sum(r.status == 'ok' for r in results)} ok, "
            f"{sum(r.failed for r in results)} failed, {sum(r.status == 'skipped' for r in results)} skipped) "
            f"in {time.perf_counter() - t0:.0f} s",
            file=out,
        )
    return 1 if failed else 0
