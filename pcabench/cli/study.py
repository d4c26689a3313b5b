"""A study: a list of runs resolved and checked before the first starts, swept into this machine's store (or
on a Dask cluster), then the reports written and the summary printed.

The command line builds the runs from its options (a preset or a matrix) and hands them here.
"""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

from pcabench import paths
from pcabench.cli.exits import EXIT_OK
from pcabench.cli.options import SCENE_OPTIONS, check_folder, check_wall_option, home_option, preset_given
from pcabench.machine import memory, profiles
from pcabench.spec import SERIAL, OptionError, RunSpec
from solvers import (
    DEFAULT_SCENE,
    DEFAULT_SOLVER,
)


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
    from pcabench.reports.build import write_reports
    from pcabench.store import check_writable, store_name
    from pcabench.studies.paper.summary import summary

    if cluster:
        from pcabench.execute.cluster import check_address, cluster_sweep, dask_distributed

        check_address(cluster)  # before the header: a bad address is one line, nothing printed first

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
        own = own_run_ids(store_path, specs)
    if reports is None:
        return 0
    from pcabench.cli.report import report_progress

    written = write_reports(results, reports, progress=report_progress)
    report_progress("")
    for p in written:
        print(f"wrote {p}", file=sys.stderr)
    if not cluster:
        table = summary(results, profile["id"], own)
        if table:
            print(table)
        report = next((p for p in written if p.name == "report.md" and p.parent.name.startswith(profile["id"])), None)
        if report:
            print(f"\nReport with every table and figure: {report}")
    return 0


def own_run_ids(store_path: Path, specs: list[RunSpec]) -> set:
    """The run ids of the rows in ``store_path`` that are ``specs``' runs by this code on this machine and host
    (run now or found stored)."""
    from pcabench.machine.profiles import machine_id
    from pcabench.spec import row_identity
    from pcabench.store import read_rows, store_files
    from pcabench.store.provenance import code_key, host_id

    keys = {s.resolved().key(machine_id(), code_key(), host_id()) for s in specs}  # as the sweep keys its runs
    rows = read_rows(store_files(store_path))
    return {r["run_id"] for r in rows if row_identity(r) in keys}


def study_specs(args) -> tuple[str, list[RunSpec]]:
    """The preset named by the flags, or the matrix built from the scene options."""
    from pcabench.studies import DEFAULT_PRESET, PRESETS, flags, matrix, named_by, preset

    given = [flag for flag in flags() if preset_given(args, flag)]
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
    value = getattr(args, given[0].replace("-", "_")) if given else None
    name = named_by(given[0], True if value == [] else value) if given else DEFAULT_PRESET
    scened = [p.option for p in PRESETS.all().values() if p.scened]
    if scene != [DEFAULT_SCENE] and (len(scene) > 1 or not PRESETS.get(name).scened):
        raise OptionError(
            f"--scene with a preset: one scene, with {' or '.join(scened)} (the other presets choose their own scenes)"
        )
    return name, preset(name, scene[0])


def cmd_study(args) -> int:
    from pcabench.studies import budget

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
