"""``pcabench report`` and ``pcabench runs``: the reports from the stores, and the stored runs as a table."""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

from pcabench import paths
from pcabench.cli.options import check_folder, home_option, results_of
from pcabench.errors import NoResults
from pcabench.spec import OptionError


def report_progress(line: str) -> None:
    """A report's progress on stderr: one line rewritten in place on a terminal, a line each elsewhere (a log);
    an empty ``line`` clears it."""
    if sys.stderr.isatty():
        sys.stderr.write("\r\x1b[K" + line)
        sys.stderr.flush()
    elif line:
        print(line, file=sys.stderr, flush=True)


def cmd_report(args) -> int:
    from pcabench.reports.build import write_reports

    results, reports = args.results, args.out
    if args.reference:
        if paths.checkout() is None:
            raise OptionError("--reference needs a source checkout (its reports/ folder)")
        results, reports = results or paths.reference_results(), reports or paths.reference_reports()
    results, reports = results or paths.user_results(), reports or paths.user_reports()
    check_folder(reports, "--out" if args.out else "--reference" if args.reference else home_option())
    written = write_reports(Path(results), Path(reports), scene=args.scene, progress=report_progress)
    report_progress("")
    for p in written:
        print(f"wrote {p}", file=sys.stderr)
    return 0


def check_filters(args, df, results) -> None:
    """Each filter of ``runs`` names something the store can hold: a status a run ends in, a scene, solver and
    model this installation knows, a machine or commit (or code key) prefix of the store's; else one line
    naming the option and what it may be (a filter that matches nothing by a typo is not "no runs")."""
    from pcabench.store import runs
    from pcabench.store.schema import STATUSES
    from solvers import MODELS, scene_names, solver_names

    for option, value, allowed in (
        ("--status", args.status, STATUSES),
        ("--scene", args.scene, scene_names()),
        ("--solver", args.solver, solver_names()),
        ("--model", args.model, MODELS),
    ):
        if value and not any(str(a).startswith(value) for a in allowed):
            raise OptionError(f"{option} {value!r} is none of {', '.join(map(str, allowed))}")
    if args.machine and not runs.machines(df.machine, args.machine):
        raise OptionError(
            f"--machine {args.machine!r} is no machine of {results} (its machines: "
            f"{', '.join(sorted(set(df.machine)))})"
        )
    if args.commit and not (
        df.commit.astype(str).str.startswith(args.commit).any() or runs.codes(df).str.startswith(args.commit).any()
    ):
        raise OptionError(f"--commit {args.commit!r} is the prefix of no commit or code key of {results}")


def cmd_runs(args) -> int:

    import pandas as pd

    from pcabench.reports.frame import load
    from pcabench.store import runs

    results = results_of(args)
    with warnings.catch_warnings():
        warnings.simplefilter("default")
        df = load(results)
    if df.empty:
        raise NoResults(f"no stored runs in {results}: run `pcabench study` first, or use --reference")
    check_filters(args, df, results)
    if args.scene:
        df = df[df.scene == args.scene]
    with pd.option_context("display.max_columns", None, "display.width", 200):
        if args.compare:
            try:
                out = runs.compare(df, *args.compare)
            except KeyError as exc:
                raise OptionError(exc.args[0]) from None
            print(runs.render(out) if not out.empty else "no configuration was run by both")
        else:
            out = runs.table(
                df, solver=args.solver, status=args.status, machine=args.machine, commit=args.commit, model=args.model
            )
            print(runs.render(out.tail(args.limit)) if not out.empty else f"no stored runs match in {results}")
            if len(out) > args.limit:
                print(
                    f"(the last {args.limit} of {len(out)} matching runs, by machine and time; --limit {len(out)} "
                    "shows them all)"
                )
    return 0
