"""``pcabench profile``, ``cache``, ``gpu-check`` and ``check-solver``: this machine, its compiled loops, its GPU and a
solver's conformance."""

from __future__ import annotations

import sys
from pathlib import Path

from pcabench import jsonout, paths
from pcabench.cli.options import check_folder, home_option
from pcabench.spec import OptionError


def cmd_profile(args) -> int:
    from pcabench.machine import profiles

    profile = profiles.capture(with_gpu=not args.no_gpu)
    if args.asv:
        from pcabench.machine import asv

        print(asv.write(profile))
        return 0
    if args.save:
        out = check_folder(args.out, "--out") if args.out else check_folder(paths.user_profiles(), home_option())
        print(f"wrote {profiles.save(profile, out)}", file=sys.stderr)
    jsonout.emit(jsonout.dumps(profile, indent=2))
    return 0


def cmd_gpu_check(args) -> int:
    from pcabench.gpu.check import gpu_check
    from pcabench.studies.paper.gpu import FULL, PAPER_STAGES, REHEARSAL

    plan = REHEARSAL if args.rehearse else FULL  # the paper's sizes; its stages with the check's own
    out, results, reports = Path(args.out), Path(args.results), Path(args.reports)
    return gpu_check(out, results, reports, plan, budget_s=args.budget, rehearse=args.rehearse, given=PAPER_STAGES)


def cmd_check_solver(args) -> int:
    from pcabench.conformance import main as check_solver

    return check_solver(args.name, quick=args.quick, as_json=args.json)


def cmd_cache(args) -> int:
    from solvers import jitcache

    root = jitcache.cache_root()
    blocked = next((p for p in (root, *root.parents) if p.exists() and not p.is_dir()), None)
    if blocked is not None:  # runs warn and compile in memory; here it is the whole answer
        raise OptionError(
            f"the JIT cache root {root} cannot be a folder: {blocked} is a file "
            f"(set ${jitcache.ENV} or $XDG_CACHE_HOME to a folder)"
        )
    if args.clear:
        freed = jitcache.clear()
        print(f"cleared {root / 'jit'} ({freed / 2**20:.1f} MiB); the next run of each configuration compiles again")
        return 0
    entries = jitcache.entries()
    if args.json:
        jsonout.emit(jsonout.dumps({"root": str(root), "target": jitcache.target(), "entries": entries}, indent=2))
        return 0
    size = sum(e["bytes"] for e in entries)
    print(f"JIT cache  {root / 'jit'}  (${jitcache.ENV} moves it)")
    print(f"this machine's target  {jitcache.target()}")
    print(
        f"{len(entries)} specialised modules, {sum(e['functions'] for e in entries)} compiled functions, "
        f"{size / 2**20:.1f} MiB"
    )
    for e in entries:
        here = "" if e["target"] == jitcache.target() else f"  ({e['target']})"
        print(f"  {e['module']:<34} {e['functions']:>2} functions {e['bytes'] / 2**10:>6.0f} KiB{here}")
        print(f"      {e['specialisation']}")
    return 0
