"""``pcabench report`` and ``pcabench runs``: the reports from the stores, and the stored runs as a table."""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

from pcabench import paths
from pcabench.cli.options import check_folder, home_option
from pcabench.errors import NoResults
from pcabench.spec import OptionError


def cmd_report(args) -> int:
    from pcabench.reports import write_reports

    results, reports = args.results, args.out
    if args.reference:
        if paths.checkout() is None:
            raise OptionError("--reference needs a source checkout (its reports/ folder)")
        results, reports = results or paths.reference_results(), reports or paths.reference_reports()
    results, reports = results or paths.user_results(), reports or paths.user_reports()
    check_folder(reports, "--out" if args.out else "--reference" if args.reference else home_option())
    for p in write_reports(Path(results), Path(reports), scene=args.scene):
        print(f"wrote {p}", file=sys.stderr)
    return 0


def cmd_runs(args) -> int:

    import pandas as pd

    from pcabench.reports.frame import load
    from pcabench.store import runs

    results = args.results or (paths.reference_results() if args.reference else paths.user_results())
    with warnings.catch_warnings():
        warnings.simplefilter("default")
        df = load(results)
    if df.empty:
        raise NoResults(f"no stored runs in {results}: run `pcabench study` first, or use --reference")
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
