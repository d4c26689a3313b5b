"""Sweeps: a matrix of runs, each in its own process, stored as it finishes.

    pcabench study --quick     # a few minutes on a laptop CPU, then the report
    pcabench study --paper     # the paper's CPU matrix, as far as the budgets allow
    pcabench study --stability # where methods fail: CFL, h/dx, integrator, precision, run length
    pcabench study --solver allpair-cpu linkedlist-cpu --dx 1 0.5 --steps 10   # a matrix

Each run is a child process with a time budget: a crash, hang or
out-of-memory in one run is recorded (status error / timeout /
out-of-memory) and the sweep goes on. Every finished run is appended to the
store at once; a rerun skips the runs the store already holds for this
machine (hardware profile and host), commit and preset, so an interrupted
sweep resumes where it stopped.
Runs predicted to take longer than the run budget are stored as ``skipped``.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

from pcabench import store
from pcabench.profiles import profile_id as this_profile_id
from pcabench.provenance import git_commit, host_id
from pcabench.record import RunRecord, step_seconds
from solvers import Scene, make_solver

RESULTS_DIR = Path("reports/results")


def all_cores() -> int:
    """Threads a ``threads: 0`` spec means: every core numba may use here."""
    import os

    import numba

    usable = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1
    return max(1, min(usable, numba.config.NUMBA_NUM_THREADS))


def resolve(spec: dict) -> dict:
    """``spec`` with ``threads: 0`` replaced by this machine's core count."""
    if spec.get("threads", 1) == 0:
        spec = dict(spec, threads=all_cores() if spec["solver"] == "linkedlist-cpu" else 1)
    return spec


def _key(spec: dict, profile: str, commit: str, host: str) -> str:
    """What identifies a run for resuming: solver, threads, scene, preset, machine, commit and host."""
    return json.dumps([spec["solver"], spec.get("threads", 1) or 1, Scene(**spec["scene"]).as_dict(),
                       spec.get("preset", ""), profile, commit, host], sort_keys=True, default=str)


def _failed_record(spec, status, message, profile, seconds=None) -> RunRecord:
    return RunRecord.before_run(Scene(**spec["scene"]), spec["solver"], spec.get("threads", 1), status=status,
                                message=message if seconds is None else f"{message} (after {seconds:.0f} s)",
                                profile_id=profile, preset=spec.get("preset", ""))


def sweep(runs: list[dict], store_path: Path, run_budget: float, sweep_budget: float,
          stream=sys.stderr) -> int:
    """Run ``runs`` (skipping those already stored), one child process each. Returns runs made.

    Before each run its time is predicted from this machine's finished runs
    (``predict.py``); a run predicted past ``run_budget`` is stored as
    ``skipped`` with the prediction instead of being run into the wall.
    """
    from pcabench.predict import predicted_seconds

    profile, commit, host = this_profile_id(), git_commit(), host_id()
    rows = store.read_rows(store_path) if Path(store_path).exists() else []
    done = {_key({"solver": r["solver"], "threads": r.get("threads", 1), "scene": _scene_kwargs(r),
                  "preset": r.get("preset", "")}, r["profile_id"], r["commit"], r.get("host", ""))
            for r in rows}
    mine = [r for r in rows if r.get("profile_id") == profile]
    t_start, made = time.perf_counter(), 0
    for i, spec in enumerate(runs, 1):
        spec = resolve(spec)
        label = f"[{i}/{len(runs)}] {spec['solver']}" + (f" x{spec['threads']}" if spec.get("threads", 1) > 1
                                                          else "") + " " + " ".join(
            f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}" for k, v in spec["scene"].items())
        if _key(spec, profile, commit, host) in done:
            print(f"{label}: already stored", file=stream, flush=True)
            continue
        elapsed = time.perf_counter() - t_start
        left = sweep_budget - elapsed
        if left <= 0:
            print(f"{label}: sweep budget spent, stopping (rerun to resume)", file=stream, flush=True)
            break
        scene = Scene(**spec["scene"])
        seconds, why = predicted_seconds(spec, scene, mine)
        if seconds is not None and seconds > run_budget:
            store.append(_failed_record(spec, "skipped", f"{why} > run budget {run_budget:.0f} s", profile),
                         store_path)
            print(f"{label}: skipped, {why}", file=stream, flush=True)
            continue
        t0 = time.perf_counter()
        cmd = [sys.executable, "-m", "pcabench.study", "--child", json.dumps(spec), "--store", str(store_path)]
        env = dict(os.environ, PCABENCH_COMMIT=commit)  # every run of a sweep carries the sweep's commit
        try:
            proc = subprocess.run(cmd, capture_output=True, text=True, timeout=min(run_budget, left), env=env)
            if proc.returncode != 0:
                status = "out-of-memory" if proc.returncode in (-9, 137) else "error"
                store.append(_failed_record(spec, status, proc.stderr.strip()[-400:], profile,
                                            time.perf_counter() - t0), store_path)
        except subprocess.TimeoutExpired:
            if left < run_budget:  # the sweep's budget ran out, not the run's: nothing to record
                print(f"{label}: sweep budget spent during the run, not stored (rerun to resume)",
                      file=stream, flush=True)
                break
            store.append(_failed_record(spec, "timeout", f"past the run budget of {run_budget:.0f} s", profile,
                                        time.perf_counter() - t0), store_path)
        made += 1
        last = store.read_rows(store_path)[-1]
        mine.append(last)
        eta = (time.perf_counter() - t_start) / made * (len(runs) - i)
        step_ms = 1e3 * step_seconds(last["stages"], last["steps"])
        print(f"{label}: {last['status']}, step {step_ms:.2f} ms, MSE {_fmt_err(last.get('mse'))}, "
              f"{time.perf_counter() - t0:.1f} s (sweep eta <= {eta / 60:.1f} min)", file=stream, flush=True)
    return made


def _fmt_err(x):
    return "-" if x is None else f"{x:.4g}"


def _scene_kwargs(row: dict) -> dict:
    fields = Scene.__dataclass_fields__
    return {k: v for k, v in (row.get("scene") or {}).items() if k in fields and k != "memory_limit_bytes"}


def child(spec_json: str, store_path: str) -> int:
    from pcabench.run import run

    spec = json.loads(spec_json)
    record = run(Scene(**spec["scene"]), spec["solver"], threads=spec.get("threads"), profile_id=this_profile_id())
    record.preset = spec.get("preset", "")
    store.append(record, store_path)
    return 0


def runs_from_args(args) -> tuple[str, list[dict]]:
    """The preset named by the flags, or the matrix built from --solver/--dx/... options."""
    from pcabench.presets import matrix, preset

    if args.dx:
        return "matrix", matrix(args.solver or ["linkedlist-cpu"], args.dx, args.precision or ["float64"],
                                args.model or ["lagrangian"], args.integrator or ["verlet"], args.cfl or [0.2],
                                args.h_factor or [2.13], steps=args.steps, t_end=args.t_end, strip=args.strip,
                                threads=args.threads)
    name = "paper" if args.paper else "stability" if args.stability else "quick"
    return name, preset(name)


def cmd_study(args) -> int:
    from pcabench import profiles
    from pcabench.presets import RUN_BUDGET
    from pcabench.reports import write_reports
    from solvers import SceneError

    name, runs = runs_from_args(args)
    solvers = {}
    for spec in map(resolve, runs):  # validate the whole matrix before the first run
        key = (spec["solver"], spec.get("threads", 1))
        if key not in solvers:  # SceneError (bad threads) or SolverUnavailable (no GPU): exit before running
            solvers[key] = make_solver(*key)
        solvers[key].check_scene(Scene(**spec["scene"]))
    run_budget = args.run_budget if args.run_budget is not None else RUN_BUDGET[name]
    for flag, value in (("--run-budget", run_budget), ("--sweep-budget", args.sweep_budget)):
        if not value > 0:
            raise SceneError(f"{flag} must be > 0 seconds (got {value})")
    profile = profiles.capture()
    profiles.save(profile)
    store_path = Path(args.results) / f"{profile['id']}.jsonl"
    print(f"pcabench study ({name}): {len(runs)} runs on {profile['id']}, {run_budget:.0f} s per run at most, "
          f"store {store_path}", file=sys.stderr, flush=True)
    sweep(runs, store_path, run_budget, args.sweep_budget)
    if args.no_report:
        return 0
    paths = write_reports(Path(args.results), Path(args.reports))
    for p in paths:
        print(f"wrote {p}", file=sys.stderr)
    return 0


def cmd_report(args) -> int:
    from pcabench.reports import write_reports

    for p in write_reports(Path(args.results), Path(args.reports)):
        print(f"wrote {p}", file=sys.stderr)
    return 0


def add_study_commands(sub) -> None:
    from pcabench.cli import _number, _positive_int
    from solvers import INTEGRATORS, MODELS, PRECISIONS, SOLVERS

    p = sub.add_parser("study", help="run a sweep (each run in its own process) and write the report",
                       description="Run a preset, or the product of the matrix options, one process per run.")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--quick", action="store_true", help="a few minutes on a laptop CPU (default)")
    g.add_argument("--paper", action="store_true", help="the paper's CPU matrix, within the budgets")
    g.add_argument("--stability", action="store_true",
                   help="CFL x integrator x h/dx, run length and float32: the stability map")
    m = p.add_argument_group("matrix (instead of a preset: the product of these lists)")
    m.add_argument("--dx", nargs="+", type=_number("--dx"), help="lattice spacings, m")
    m.add_argument("--solver", nargs="+", choices=SOLVERS)
    m.add_argument("--precision", nargs="+", choices=PRECISIONS)
    m.add_argument("--model", nargs="+", choices=MODELS)
    m.add_argument("--integrator", nargs="+", choices=INTEGRATORS)
    m.add_argument("--cfl", nargs="+", type=_number("--cfl"))
    m.add_argument("--h-factor", nargs="+", type=_number("--h-factor"))
    end = m.add_mutually_exclusive_group()
    end.add_argument("--steps", type=_positive_int("--steps"))
    end.add_argument("--t-end", type=_number("--t-end"))
    m.add_argument("--strip", action="store_true", help="the thinnest y-periodic strip instead of 20 m")
    m.add_argument("--threads", type=_positive_int("--threads"), default=1)
    p.add_argument("--results", default=str(RESULTS_DIR), help="folder of result stores (*.jsonl)")
    p.add_argument("--reports", default="reports", help="folder for the reports")
    p.add_argument("--run-budget", type=float, help="seconds per run before it is a timeout "
                   "(default: quick 120, paper 900, stability 120, matrix 900)")
    p.add_argument("--sweep-budget", type=float, default=4 * 3600.0, help="seconds for the whole sweep")
    p.add_argument("--no-report", action="store_true", help="store the runs, do not write the reports")
    p.set_defaults(func=cmd_study)
    p = sub.add_parser("report", help="regenerate the reports from the stored results")
    p.add_argument("--results", default=str(RESULTS_DIR))
    p.add_argument("--reports", default="reports")
    p.set_defaults(func=cmd_report)


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--child", required=True)
    ap.add_argument("--store", required=True)
    a = ap.parse_args()
    sys.exit(child(a.child, a.store))
