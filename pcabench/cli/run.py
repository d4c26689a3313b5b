"""``pcabench run``: one scene on one solver, its stage table or its stored record as JSON."""

from __future__ import annotations

import contextlib
import sys
from pathlib import Path

from pcabench import jsonout
from pcabench.cli.exits import EXIT_OK, EXIT_RUN_FAILED
from pcabench.cli.options import check_output_path, scene_from_args
from pcabench.execute.progress import Progress
from pcabench.spec import SERIAL, OptionError, RunSpec


# ---------------------------------------------------------------- commands
def cmd_run(args) -> int:
    from pcabench.execute.run import run, solver_output_to_stderr
    from pcabench.machine.profiles import machine_id
    from pcabench.store import to_row

    scene = scene_from_args(args)
    from pcabench.cli.study import check_specs

    # resolved once, and checked: the solver can run here (a GPU for a GPU solver), before anything is printed
    (spec,) = check_specs([RunSpec(args.solver, scene, args.threads or SERIAL, pair_loop=args.pair_loop or "auto")])
    if args.fields is not None:
        if args.fields.strip() and (args.fields.endswith("/") or Path(args.fields).is_dir()):
            args.fields = str(Path(args.fields) / fields_name(spec))  # a folder: a file named by the run in it
        elif args.fields.strip() and not args.fields.endswith((".npz", ".vtu")):
            args.fields += ".npz"  # as numpy.savez names it
        if args.fields.endswith(".vtu") and vtu_available():
            raise OptionError(vtu_available())
        check_output_path(args.fields, "--fields")
    if args.run_budget is not None and not args.run_budget > 0:
        raise OptionError(f"--run-budget must be > 0 seconds (got {args.run_budget})")
    if args.results is not None and not args.store:
        raise OptionError("--results names where --store keeps the run: give --store too")
    store_path = None
    if args.store:  # checked before the run: a record with nowhere to go is found out first
        from pcabench import paths
        from pcabench.store import check_writable, store_name

        store_path = check_writable(Path(args.results or paths.user_results()) / store_name(machine_id()))
    if not args.json:
        print(f"pcabench run: {spec.label}; {scene.describe()}", flush=True)
    for caution in scene.cautions:  # before the work: the user may stop it
        print(f"pcabench run: warning: {caution}", file=sys.stderr, flush=True)
    if args.run_budget is not None:  # in a child, as a sweep runs it: the budget holds whatever the solver does
        record = run_in_child(spec, args)
    else:
        progress = None if args.quiet else Progress(args.solver)
        with solver_output_to_stderr(args.json), contained():
            record = run(spec, machine_id(), fields_path=args.fields, progress=progress)
    if store_path is not None:
        from pcabench.store import append

        append(record, store_path)
    if args.json:  # the record as a store holds it: the whole scene, so the run can be made again from it
        jsonout.emit(jsonout.dumps(to_row(record)))  # strict JSON: null, never NaN
    else:
        print(record.text(scene))
    went = [("fields", args.fields)] if args.fields and Path(args.fields).is_file() else []
    went += [("record", store_path)] if store_path is not None else []
    for what, path in went:  # where they went (on stderr beside --json's one object)
        print(f"{what:<17}{path}", file=sys.stderr if args.json else sys.stdout)
    return EXIT_OK if record.status == "ok" else EXIT_RUN_FAILED


@contextlib.contextmanager
def contained():
    """Within: what the run starts ends with it, as a sweep's run (pcabench/execute/containment.py): this process
    adopts the descendants that leave it (a plug-in's daemon, double-forked) and, after the run, ends every child
    it did not have before, with its group, so none outlives the run or holds its output pipes open."""
    from pcabench.execute import containment

    adopting = containment.become_subreaper()
    known = containment.children()
    try:
        yield
    finally:
        ended = containment.end_adopted(known) if adopting else 0
        containment.stop_subreaper()
        if ended:
            print(f"pcabench run: ended {ended} process(es) the run left running", file=sys.stderr)


def vtu_available() -> str:
    """'' where a .vtu can be written here, else the one line that says how (pcabench/execute/vtu.py)."""
    from pcabench.execute.vtu import available

    return available()


def fields_name(spec: RunSpec) -> str:
    """The file a run's fields take in a folder given to --fields: solver, scene, dx, model, steps."""
    s = spec.scene
    return f"{spec.solver}_{s.name}_dx{s.dx:g}_{s.model}_{s.n_steps}steps.npz"


def run_in_child(spec: RunSpec, args):
    """``pcabench run --run-budget S``: the run in a child process of its own group (as a sweep's,
    :func:`pcabench.execute.sweep.run_child`), killed with all it started at S seconds, whether or not the solver
    returns to Python (a compiled loop, a solver that ignores signals); its record."""
    import subprocess

    from pcabench.execute.sweep import failed_record, run_child
    from pcabench.machine.profiles import machine_id
    from pcabench.store.provenance import git_commit
    from pcabench.store.record import RunRecord

    stream = None if args.quiet else sys.stderr
    try:
        row = run_child(spec, args.run_budget, git_commit(), machine_id(), stream=stream, fields_to=args.fields)
    except subprocess.TimeoutExpired:
        return failed_record(spec, "timeout", f"past the run budget of {args.run_budget:g} s", machine_id())
    return RunRecord.from_row(row)
