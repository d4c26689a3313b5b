"""Sweeps: a matrix of runs, each in its own process, stored as it finishes.

    pcabench study --quick     # a few minutes on a laptop CPU, then the report
    pcabench study --paper     # the paper's CPU matrix, as far as the budgets allow

Each run is a child process with a time budget: a crash, hang or
out-of-memory in one run is recorded (status error / timeout /
out-of-memory) and the sweep goes on. Every finished run is appended to the
store at once; a rerun skips the runs the store already holds for this
machine and commit, so an interrupted sweep resumes where it stopped.
"""
from __future__ import annotations

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

from pcabench import store
from pcabench.hardware_profiles import profile_id as this_profile_id
from pcabench.provenance import git_commit, package_versions
from pcabench.record import RunRecord
from pcabench.solvers import Scene

RESULTS_DIR = Path("reports/results")


def strip_height(dx: float, cutoff_factor: float = 3.0, h_factor: float = 2.13) -> float:
    """The thinnest y-periodic strip the cell list accepts at ``dx``, m."""
    import math

    return math.ceil(3 * cutoff_factor * h_factor * (1 + 1e-9)) * dx


def preset(name: str) -> list[dict]:
    """The run matrix of a preset: dicts of solver, threads and Scene keyword arguments."""
    runs = []
    if name == "quick":
        # Table 4/5 and Fig. 10: stage times of the paper's scene (lagrangian, full domain)
        for dx in (1.0, 0.5, 0.25):
            runs.append({"solver": "linkedlist-cpu", "scene": {"dx": dx, "steps": 20}})
        # Fig. 9: all-pair against linked list
        for dx in (1.0, 0.5):
            runs.append({"solver": "allpair-cpu", "scene": {"dx": dx, "steps": 20}})
        # Fig. 8: error against dx at a fixed physical time, on the strip
        for model in ("linear", "lagrangian"):
            for dx in (0.4, 0.2, 0.1):
                runs.append({"solver": "linkedlist-cpu",
                             "scene": {"dx": dx, "t_end": 10.0, "model": model, "strip_height": strip_height(dx)}})
    elif name == "paper":
        for dx in (1.0, 0.5, 0.25, 0.1, 0.05):
            runs.append({"solver": "linkedlist-cpu", "scene": {"dx": dx, "steps": 100}})
            runs.append({"solver": "linkedlist-cpu", "threads": 2, "scene": {"dx": dx, "steps": 100}})
        for dx in (1.0, 0.5, 0.25, 0.1):
            runs.append({"solver": "allpair-cpu", "scene": {"dx": dx, "steps": 100}})
        for model in ("linear", "fixed", "lagrangian"):
            for precision in ("float64", "float32"):
                for dx in (0.4, 0.2, 0.1, 0.05, 0.025):
                    runs.append({"solver": "linkedlist-cpu", "threads": 2, "scene": {
                        "dx": dx, "t_end": 10.0, "model": model, "precision": precision,
                        "strip_height": strip_height(dx)}})
                for dx in (0.1, 0.05, 0.01, 0.004):
                    runs.append({"solver": "linkedlist-cpu", "threads": 2, "scene": {
                        "dx": dx, "steps": 100, "model": model, "precision": precision,
                        "strip_height": strip_height(dx)}})
    else:
        raise ValueError(f"preset must be quick or paper (got {name!r})")
    return runs


def _key(spec: dict, profile: str, commit: str) -> str:
    return json.dumps([spec["solver"], spec.get("threads", 1), Scene(**spec["scene"]).as_dict(), profile, commit],
                      sort_keys=True, default=str)


def _failed_record(spec, status, message, profile, seconds) -> RunRecord:
    scene = Scene(**spec["scene"])
    nan = float("nan")
    return RunRecord(solver=spec["solver"], precision=scene.precision, model=scene.model,
                     integrator=scene.integrator, dx=scene.dx, n_particles=scene.n_particles, steps=0,
                     t_end=0.0, stages={s: 0.0 for s in ("input", "init", "snp", "pi", "su", "output")},
                     jit_seconds=0.0, mse=nan, me=nan, mean_neighbours=nan, status=status, failed_step=None,
                     threads=spec.get("threads", 1), steps_requested=scene.n_steps, scene=scene.as_dict(),
                     message=f"{message} (after {seconds:.0f} s)", profile_id=profile,
                     commit=git_commit(), versions=package_versions())


def sweep(runs: list[dict], store_path: Path, run_budget: float, sweep_budget: float,
          stream=sys.stderr) -> int:
    """Run ``runs`` (skipping those already stored), one child process each. Returns runs made."""
    profile, commit = this_profile_id(), git_commit()
    done = {_key({"solver": r["solver"], "threads": r.get("threads", 1), "scene": _scene_kwargs(r)}, r["profile_id"],
                 r["commit"]) for r in store.read_rows(store_path)} if store_path.exists() else set()
    t_start, made = time.perf_counter(), 0
    for i, spec in enumerate(runs, 1):
        label = f"[{i}/{len(runs)}] {spec['solver']} " + " ".join(f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}"
                                                               for k, v in spec["scene"].items())
        if _key(spec, profile, commit) in done:
            print(f"{label}: stored, skipped", file=stream, flush=True)
            continue
        left = sweep_budget - (time.perf_counter() - t_start)
        if left <= 0:
            print(f"{label}: sweep budget spent, stopping (rerun to resume)", file=stream, flush=True)
            break
        t0 = time.perf_counter()
        cmd = [sys.executable, "-m", "pcabench.study", "--child", json.dumps(spec), "--store", str(store_path)]
        try:
            proc = subprocess.run(cmd, capture_output=True, text=True, timeout=min(run_budget, left))
            if proc.returncode != 0:
                status = "out-of-memory" if proc.returncode in (-9, 137) else "error"
                store.append(_failed_record(spec, status, proc.stderr.strip()[-400:], profile,
                                            time.perf_counter() - t0), store_path)
        except subprocess.TimeoutExpired:
            store.append(_failed_record(spec, "timeout", f"past the run budget of {run_budget:.0f} s", profile,
                                        time.perf_counter() - t0), store_path)
        made += 1
        last = store.read_rows(store_path)[-1]
        print(f"{label}: {last['status']}, step {1e3 * _step(last):.2f} ms, MSE {last.get('mse')}, "
              f"{time.perf_counter() - t0:.1f} s", file=stream, flush=True)
    return made


def _step(row):
    st = row.get("stages") or {}
    return (st.get("snp", 0) + st.get("pi", 0) + st.get("su", 0)) / max(row.get("steps") or 1, 1)


def _scene_kwargs(row: dict) -> dict:
    fields = Scene.__dataclass_fields__
    return {k: v for k, v in (row.get("scene") or {}).items() if k in fields and k != "memory_limit_bytes"}


def child(spec_json: str, store_path: str) -> int:
    from pcabench.run import run

    spec = json.loads(spec_json)
    record = run(Scene(**spec["scene"]), spec["solver"], threads=spec.get("threads"), profile_id=this_profile_id())
    store.append(record, store_path)
    return 0


def cmd_study(args) -> int:
    from pcabench import hardware_profiles
    from pcabench.reports import write_reports

    from pcabench.solvers import SceneError

    for flag, value in (("--run-budget", args.run_budget), ("--sweep-budget", args.sweep_budget)):
        if not value > 0:
            raise SceneError(f"{flag} must be > 0 seconds (got {value})")
    name = "paper" if args.paper else "quick"
    runs = preset(name)
    profile = hardware_profiles.capture()
    hardware_profiles.save(profile)
    store_path = Path(args.results) / f"{profile['id']}.jsonl"
    print(f"pcabench study --{name}: {len(runs)} runs on {profile['id']}, store {store_path}",
          file=sys.stderr, flush=True)
    sweep(runs, store_path, args.run_budget, args.sweep_budget)
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
    p = sub.add_parser("study", help="run a sweep (each run in its own process) and write the report")
    g = p.add_mutually_exclusive_group()
    g.add_argument("--quick", action="store_true", help="a few minutes on a laptop CPU (default)")
    g.add_argument("--paper", action="store_true", help="the paper's CPU matrix, within the budgets")
    p.add_argument("--results", default=str(RESULTS_DIR), help="folder of result stores (*.jsonl)")
    p.add_argument("--reports", default="reports", help="folder for the reports")
    p.add_argument("--run-budget", type=float, default=900.0, help="seconds per run before it is a timeout")
    p.add_argument("--sweep-budget", type=float, default=4 * 3600.0, help="seconds for the whole sweep")
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
