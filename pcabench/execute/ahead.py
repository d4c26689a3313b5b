"""A local sweep's loops compiled ahead, side by side: before the first run, each set of loops the runs will need
and the disk cache does not hold yet (a built-in CPU solver, serial, per precision and kernel) is compiled by a
process of its own, as many at once as there are cores, instead of one after another inside the first run of
each. The runs then load them (pcabench/execute/preload.py) and time no compile; the sweep says how long the
compiling took. A cold quick study compiles four sets: 16 s one after another, about half that on two cores."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time

AHEAD = "PCABENCH_AHEAD"  # a worker's environment: a JSON list of the RunSpecs whose loops it warms up
WARMED = ("linkedlist-cpu", "allpair-cpu")  # built-in CPU solvers whose serial warm-up starts no thread


def groups(specs: list) -> list[list]:
    """``specs`` by the loops they compile (solver, precision, kernel), serial built-in CPU solvers only."""
    by: dict = {}
    for spec in specs:
        if spec.solver in WARMED and spec.threads == 1:
            by.setdefault((spec.solver, spec.scene.precision, spec.scene.kernel), []).append(spec)
    return list(by.values())


def weight(part: list) -> float:
    """A group's compile, relative: the cell list's loops (its pair list, cells, sort) about three times the
    all-pair's (6.8 and 5.0 s against 1.7 and 2.5 s here), for each scene and model its runs take."""
    kinds = {(s.scene.name, s.scene.model, s.pair_loop) for s in part}
    return (3.0 if part[0].solver == "linkedlist-cpu" else 1.0) * len(kinds) ** 0.5


def cores() -> int:
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not Linux
        return os.cpu_count() or 1


def compile_ahead(specs: list, stream=sys.stderr) -> tuple[int, float]:
    """Warm up one spec of each model, scene and pair loop of every group (:func:`groups`) in worker processes,
    at most one per core, the groups dealt among them: (sets of loops compiled, wall s). Nothing where there are
    fewer than two groups or cores (one after another is what the runs do anyway)."""
    parts = groups(specs)
    workers = min(cores(), len(parts))
    if workers < 2:
        return 0, 0.0
    t0 = time.perf_counter()
    dealt: list[list] = [[] for _ in range(workers)]
    load = [0.0] * workers
    for part in sorted(parts, key=weight, reverse=True):  # the dearest first, each to the least loaded worker
        i = load.index(min(load))
        dealt[i] += part
        load[i] += weight(part)
    procs = [
        subprocess.Popen(
            [sys.executable, "-m", "pcabench.execute.ahead"],
            env={**os.environ, AHEAD: "[" + ",".join(s.to_json() for s in mine) + "]"},
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            text=True,
        )
        for mine in dealt
    ]
    compiled = 0
    for proc in procs:
        out, _ = proc.communicate()
        try:
            compiled += int(json.loads(out.strip().splitlines()[-1])["compiled"])
        except (ValueError, IndexError, KeyError, TypeError):  # a worker that failed: its runs compile as before
            pass
    seconds = time.perf_counter() - t0
    if compiled:
        print(
            f"compiled ahead: {compiled} sets of loops in {seconds:.1f} s on {workers} processes, before the first run "
            "(the runs load them)",
            file=stream,
            flush=True,
        )
    return compiled, seconds


def main() -> None:
    """A worker: each spec's solver warmed up on a tiny scene (compiling what the cache lacks); prints how many
    warm-ups compiled something."""
    from pcabench.spec import RunSpec
    from solvers import jitcache
    from solvers.interface import tiny_scene
    from solvers.registry import make_solver

    seen, compiled = set(), 0
    for spec in (RunSpec.from_json(json.dumps(s)) for s in json.loads(os.environ.get(AHEAD) or "[]")):
        sc = spec.scene
        key = (spec.solver, spec.pair_loop, sc.name, sc.model, sc.precision, sc.kernel, sc.correction, sc.integrator)
        if key in seen:
            continue
        seen.add(key)
        before = jitcache.counts()["compiled"]
        try:
            solver = make_solver(spec.solver, threads=1, pair_loop=spec.pair_loop)
            solver.input(tiny_scene(sc))
            solver.warmup()
        except Exception:  # noqa: BLE001 - whatever it is, its run will meet it and say so
            continue
        compiled += jitcache.counts()["compiled"] > before
    print(json.dumps({"compiled": compiled}))


if __name__ == "__main__":
    main()
