"""asv's smoke run: a few benchmarks, once each, in this environment, with every tracked file left as it is.

    python benchmarks/ci/asv_smoke.py              # about 30 s on two cores; prints the timings
    python benchmarks/ci/asv_smoke.py --check      # `asv check` first (CI)

Its results go to a scratch folder through a scratch copy of asv.conf.json (pcabench/machine/asv.py
``scratch_config``), so the committed ``reports/asv/results`` stay as they are. A script, not a module of the
asv suite: benchmarks/ci/ has no ``__init__.py``, so asv never imports it.
"""

from __future__ import annotations

import subprocess
import sys
import time
from pathlib import Path

from pcabench.machine import asv

ROOT = Path(__file__).resolve().parents[2]  # the checkout: benchmarks/ci/ is two folders down
SCRATCH = asv.SCRATCH  # under the ignored .asv/
# One benchmark of each kind, at the smallest size (asv matches "name(param, ...)"): a timed step of both CPU
# solvers, the stage shares, the JIT time in a fresh interpreter, and a GPU step (skips cleanly without a GPU).
SELECTION = (
    r"TimeStep\.time_step\('(allpair|linkedlist)-cpu', 'float64', 1\.0\)",
    r"TrackStageShare\.track_share\('float64', 'pi'\)",
    r"TrackJIT\.track_jit_seconds\('linkedlist-cpu', 'float64', 'cached'\)",
    r"TimeGPUStep\.time_step\('float32', 0\.1\)",
)


def main(argv=None) -> int:
    from pcabench.usage import Parser  # a usage error is one line, exit code 2

    p = Parser(prog="python benchmarks/ci/asv_smoke.py", description=__doc__.split("\n")[0])
    p.add_argument("--machine", help="asv's machine name (default: `pcabench profile --asv`, which writes it)")
    p.add_argument(
        "--results", type=Path, default=SCRATCH, help=f"the scratch results folder (default {SCRATCH}, git-ignored)"
    )
    p.add_argument("--check", action="store_true", help="run `asv check` first")
    args = p.parse_args(argv)
    if args.results.resolve().is_relative_to((ROOT / "reports").resolve()):
        print(
            f"asv_smoke: error: --results {args.results}: under reports/, where the committed results are; "
            "pick a scratch folder",
            file=sys.stderr,
        )
        return 2
    machine = args.machine
    if not machine:
        from pcabench.machine.profiles import capture

        machine = asv.write(capture())
    config = asv.scratch_config(args.results, ROOT)
    command = [sys.executable, "-m", "asv", "--config", str(config)]
    t0 = time.perf_counter()
    if args.check and subprocess.run([*command, "check", "--python=same"], cwd=ROOT).returncode:
        return 1
    run = [
        *command,
        "run",
        "--python=same",
        "--quick",
        "--show-stderr",
        "--machine",
        machine,
        *(a for b in SELECTION for a in ("-b", b)),
    ]
    rc = subprocess.run(run, cwd=ROOT).returncode
    print(f"asv smoke run: exit {rc} in {time.perf_counter() - t0:.0f} s; results in {args.results}", file=sys.stderr)
    return rc


if __name__ == "__main__":
    sys.exit(main())
