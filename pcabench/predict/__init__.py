"""Predict a run's wall time from the finished runs of the same solver, to skip hopeless sizes.

The time of one step is fitted as ``a * N**b`` over this host's finished runs
of the same solver, precision and model (any protocol), the closest kind
first: of the spec's dimension, then its pair loop (a 2D linear run's pair
list costs a tenth of a gather), then its thread count; a run of another
thread count is scaled by the thread ratio times this host's measured parallel
efficiency (the same scene at two counts; ideal where none). Per neighbour for the cell lists:
their step time is taken proportional to the neighbours per particle, pi
(cutoff / dx)^2 in 2D and 4 pi / 3 (cutoff / dx)^3 in 3D, so runs of another
kernel or h/dx inform the fit. With two or more sizes ``b`` is fitted (bounded to half and
one and a half times the solver's ``order``); with one, ``b`` is the order
(2 for all-pair, 1 for a cell list). A run's time is
its steps times the step, plus the child process's start-up, plus its JIT:
a cold compile for the first run of a compiled configuration (solver,
precision, kernel, threaded or not) this host has not run before, a load
from the JIT cache (solvers/jitcache.py) otherwise, each the median of this
host's stored runs that did so. A run whose predicted time exceeds the run
budget is recorded as ``skipped`` with the prediction, instead of being run
into the wall.
"""

from __future__ import annotations

import json
import math

import numpy as np

from pcabench.store.record import step_seconds
from solvers import resolve_pair_loop, solver_class
from solvers.physics.integrators import sweeps_per_step

START_UP = 2.0  # s: a child process's start, imports, scoring and hand-back, JIT aside (1.9 s measured here)
COLD_JIT = 6.0  # s: compiling a configuration's loops, where no stored run says (5-12 s measured here)
CACHED_JIT = 0.5  # s: loading them from the JIT cache, where no stored run says (0.3-0.4 s measured here)


def variant(solver: str, threads, scene: dict) -> tuple:
    """What decides which loops a run compiles: solver, precision, kernel, and whether it runs threads."""
    return solver, scene.get("precision"), scene.get("kernel") or "gaussian", int(threads or 1) > 1


def spec_variant(spec) -> tuple:
    return variant(spec.solver, spec.threads, spec.scene.as_dict())


def row_variant(row: dict) -> tuple:
    return variant(row.get("solver"), row.get("threads"), row.get("scene") or {})


def jit_seconds(spec, rows: list[dict], cached: bool) -> float:
    """The JIT a run of ``spec`` pays, s: the median of this host's stored runs of its solver that compiled
    (``cached`` False) or loaded from the cache (True), else :data:`COLD_JIT` / :data:`CACHED_JIT`."""
    seen = [
        float(r["jit_seconds"])
        for r in rows
        if r.get("solver") == spec.solver and r.get("jit_cached") is cached and r.get("jit_seconds") is not None
    ]
    if seen:
        return float(np.median(seen))
    return CACHED_JIT if cached else COLD_JIT


def _same_config(row: dict, spec) -> bool:
    rs, scene = row.get("scene") or {}, spec.scene
    return (
        row.get("status") == "ok"
        and row.get("solver") == spec.solver
        and rs.get("precision") == scene.precision
        and rs.get("model") == scene.model
        and (row.get("steps") or 0) > 0
    )


def _threads(row: dict) -> int:
    return int(row.get("threads") or 1)


def parallel_efficiency(rows: list[dict], threads: int | None = None) -> float:
    """This host's speed-up per thread, measured: the median over scenes run at one thread and at more (same solver,
    loop and scene) of (serial step / threaded step) / threads, at ``threads`` where the host ran that count (else
    at every count); 1 (ideal) where it ran none."""
    serial, threaded = {}, []
    for row in rows:
        if row.get("status") != "ok" or not (row.get("steps") or 0) > 0:
            continue
        key = (row.get("solver"), row.get("pair_loop"), json.dumps(row.get("scene") or {}, sort_keys=True))
        step = step_seconds(row["stages"], row["steps"])
        if _threads(row) == 1:
            serial.setdefault(key, []).append(step)
        else:
            threaded.append((key, _threads(row), step))
    ratios = {}
    for key, n, step in threaded:
        if key in serial and step > 0:
            ratios.setdefault(n, []).append(min(serial[key]) / step / n)
    chosen = ratios.get(threads) or [r for values in ratios.values() for r in values]
    return float(np.median(chosen)) if chosen else 1.0


def _dims(scene: dict) -> int:
    """The dimension of a stored scene (its kind's; 2 for a name this checkout does not know)."""
    from solvers import scenes

    kind = scenes().get(scene.get("name") or "plane-pulse")
    return int(getattr(kind, "dims", 2))


def _reach(solver: str, scene: dict) -> float:
    """The work of a particle's step, relative: the neighbours per particle the cutoff holds, pi (cutoff / dx)^2 in
    2D and 4 pi / 3 (cutoff / dx)^3 in 3D (1 for all-pair), times the integrator's sweeps over Verlet's (RK4: 4)."""
    sweeps = sweeps_per_step(scene.get("integrator") or "verlet") / sweeps_per_step("verlet")
    if "all-pairs" in solver_class(solver).pair_loops or not scene.get("cutoff") or not scene.get("dx"):
        return sweeps
    ratio = scene["cutoff"] / scene["dx"]
    return sweeps * (4.0 * math.pi / 3.0 * ratio**3 if _dims(scene) == 3 else math.pi * ratio**2)


def _kinship(row: dict, spec, loop: str) -> tuple:
    """How far a stored run is from ``spec``: (another dimension, another pair loop, another thread count); a row
    that names no loop (stored before rows did) is of any."""
    return (
        _dims(row["scene"]) != spec.scene.dims,
        row.get("pair_loop") not in (None, "", loop),
        _threads(row) != int(spec.threads),
    )


def step_model(spec, rows: list[dict]):
    """``(a, b, sizes)`` of the fitted step time ``a * N**b`` (s) at ``spec``'s neighbours per particle and
    threads, or None without data; fitted to the closest kind of stored run there is (:func:`_kinship`), the next
    kind where the closest has no usable timing."""
    reach = _reach(spec.solver, spec.scene.as_dict())
    same = [row for row in rows if _same_config(row, spec)]
    loop = resolve_pair_loop(spec.solver, spec.scene, spec.pair_loop)
    kinds: dict = {}
    for row in same:
        kinds.setdefault(_kinship(row, spec, loop), []).append(row)
    pts: dict = {}
    for kind in sorted(kinds):
        efficiency = parallel_efficiency(rows, int(spec.threads)) if kind[2] else 1.0
        for row in kinds[kind]:
            scale = reach / _reach(spec.solver, row["scene"])
            if _threads(row) != int(spec.threads):  # each thread beyond one gains the host's measured efficiency
                scale *= _speedup(_threads(row), efficiency) / _speedup(int(spec.threads), efficiency)
            pts.setdefault(int(row["n_particles"]), []).append(scale * step_seconds(row["stages"], row["steps"]))
        pts = {n: v for n, v in pts.items() if n > 0 and min(v) > 0}
        if pts:
            break
    if not pts:
        return None
    pts = {n: float(np.median(v)) for n, v in pts.items()}
    n = np.array(sorted(pts), float)
    t = np.array([pts[k] for k in sorted(pts)])
    if len(n) >= 2:
        b = float(np.polyfit(np.log(n[-3:]), np.log(t[-3:]), 1)[0])  # the three largest sizes
        order = solver_class(spec.solver).order
        # never flatter than half the order nor steeper than one and a half times it: two small sizes (caches, a
        # busy neighbour) can fit any slope, and a steep one extrapolated 100x in N overestimates 100-fold
        b = min(max(b, order * 0.5), order * 1.5)
    else:
        b = solver_class(spec.solver).order
    a = float(t[-1] / n[-1] ** b)
    return a, b, [int(k) for k in n]


def _speedup(threads: int, efficiency: float) -> float:
    return threads * efficiency if threads > 1 else 1.0


def predicted_seconds(spec, rows: list[dict], cached: bool | None = None):
    """``(seconds, why)`` for the RunSpec ``spec`` from ``rows`` of this host, or ``(None, "")`` without data.
    ``cached``: whether its loops are in the JIT cache (None: where a stored row ran its configuration)."""
    scene = spec.scene
    model = step_model(spec, rows)
    if model is None:
        return None, ""
    if cached is None:
        cached = spec_variant(spec) in {row_variant(r) for r in rows}
    a, b, sizes = model
    step = a * scene.n_particles**b
    jit = jit_seconds(spec, rows, cached)
    seconds = START_UP + jit + scene.n_steps * step
    sizes_txt = ", ".join(f"{n:,}" for n in sizes[-3:])
    why = (
        f"predicted {seconds:.3g} s ({scene.n_steps} steps x {1e3 * step:.3g} ms, {jit:.2g} s of JIT "
        f"{'cached' if cached else 'compiling'}; step time ~ N^{b:.2f} fitted to N = {sizes_txt} on this host)"
    )
    return (seconds if math.isfinite(seconds) else None), why
