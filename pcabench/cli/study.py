"""A study: a list of runs resolved and checked before the first starts, swept into this machine's store (or
on a Dask cluster), then the reports written and the summary printed.

The command line builds the runs from its options (a preset or a matrix) and hands them here.
"""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

from pcabench.machine import memory, profiles
from pcabench.spec import RunSpec


def bounded_spec(spec: RunSpec) -> RunSpec:
    """``spec`` resolved with its scene bounded by the memory available here (a SceneError if it does not
    fit), so that ``auto`` takes the pair list only where it fits."""
    return dataclasses.replace(spec, scene=memory.bounded(spec.scene)).resolved()


def check_specs(specs: list[RunSpec]) -> list[RunSpec]:
    """Every spec resolved, its memory and its solver checked before the first run (exits 2 or 3, not
    mid-sweep)."""
    from solvers import make_solver

    resolved, solvers = [], {}
    for spec in specs:
        spec = bounded_spec(spec)
        key = (spec.solver, spec.threads, spec.pair_loop)
        if key not in solvers:
            solvers[key] = make_solver(*key)
        solvers[key].check_scene(spec.scene)
        resolved.append(spec)
    return resolved


def run_study(
    name: str,
    specs: list[RunSpec],
    results: Path,
    reports: Path | None,
    run_budget: float,
    sweep_budget: float,
    cluster: str | None = None,
    retry_failed: bool = False,
) -> int:
    """Sweep ``specs`` (preset ``name``) into ``results`` with ``run_budget`` seconds per run and
    ``sweep_budget`` in all, then write the reports into ``reports`` (None: no reports) and print the
    summary table; 0 (a failed run is a stored row, not an error)."""
    from pcabench.execute.sweep import sweep
    from pcabench.reports import summary, write_reports
    from pcabench.store import check_writable, store_name

    if cluster:
        from pcabench.execute.cluster import cluster_sweep, dask_distributed

        dask_distributed()  # one line naming the extra, before anything else
        print(
            f"pcabench study ({name}): {len(specs)} runs on the Dask cluster {cluster}, "
            f"{run_budget:.0f} s per run at most, stores in {results}",
            file=sys.stderr,
            flush=True,
        )
        cluster_sweep(specs, results, run_budget, cluster, retry_failed=retry_failed, sweep_budget=sweep_budget)
    else:
        profile = profiles.capture()
        store_path = results / store_name(profile["id"])
        check_writable(store_path)
        profiles.save(profile)
        print(
            f"pcabench study ({name}): {len(specs)} runs on {profile['id']}, {run_budget:.0f} s per run at most, "
            f"store {store_path}",
            file=sys.stderr,
            flush=True,
        )
        sweep(specs, store_path, run_budget, sweep_budget, retry_failed=retry_failed)
    if reports is None:
        return 0
    written = write_reports(results, reports)
    for p in written:
        print(f"wrote {p}", file=sys.stderr)
    if not cluster:
        table = summary(results, profile["id"])
        if table:
            print(table)
        report = next((p for p in written if p.name == "report.md" and p.parent.name.startswith(profile["id"])), None)
        if report:
            print(f"\nReport with every table and figure: {report}")
    return 0
