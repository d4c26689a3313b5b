"""asv's smoke run: a few benchmarks, once each, in this environment, with every tracked file left as it is.

    python -m pcabench.bench.asv_smoke              # about 30 s on two cores; prints the timings
    python -m pcabench.bench.asv_smoke --check      # `asv check` first (CI)

asv writes ``machine.json`` and ``benchmarks.json`` into its results folder
even on a dry run, and the committed ``reports/asv/results`` hold real
measurements. :func:`scratch_config` writes a copy of ``asv.conf.json`` (an
ignored ``.asv-*.conf.json`` at the root, so the config's relative paths still
hold) whose results folder is a scratch one; the README, ``.ci/run`` and
``device_payload`` all run asv through it.
"""

from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]  # the checkout: pcabench/bench/ is two folders down
RESULTS_LINE = '"results_dir": "reports/asv/results"'
SCRATCH = Path(".asv") / "smoke" / "results"  # under the ignored .asv/
# One benchmark of each kind, at the smallest size (asv matches "name(param, ...)"): a timed step of both CPU
# solvers, the stage shares, the JIT time in a fresh interpreter, and a GPU step (skips cleanly without a GPU).
SELECTION = (
    r"TimeStep\.time_step\('(allpair|linkedlist)-cpu', 'float64', 1\.0\)",
    r"TrackStageShare\.track_share\('float64', 'pi'\)",
    r"TrackJIT\.track_jit_seconds\('linkedlist-cpu', 'float64', 'cached'\)",
    r"TimeGPUStep\.time_step\('float32', 0\.1\)",
)


def scratch_config(results: Path, root: Path = ROOT, name: str = "smoke") -> Path:
    """``root/.asv-<name>.conf.json``: ``root``'s asv.conf.json with its results in ``results`` (made absolute)."""
    text = (root / "asv.conf.json").read_text()
    if RESULTS_LINE not in text:
        raise RuntimeError(f"{root / 'asv.conf.json'} has no line {RESULTS_LINE}: update pcabench/bench/asv_smoke.py")
    config = root / f".asv-{name}.conf.json"
    config.write_text(text.replace(RESULTS_LINE, json.dumps({"results_dir": str(Path(root, results).resolve())})[1:-1]))
    return config


def main(argv=None) -> int:
    from pcabench.usage import Parser  # a usage error is one line, exit code 2

    p = Parser(prog="python -m pcabench.bench.asv_smoke", description=__doc__.split("\n")[0])
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
        from pcabench.bench import asv_machine
        from pcabench.machine.profiles import capture

        machine = asv_machine.write(capture())
    config = scratch_config(args.results)
    asv = [sys.executable, "-m", "asv", "--config", str(config)]
    t0 = time.perf_counter()
    if args.check and subprocess.run([*asv, "check", "--python=same"], cwd=ROOT).returncode:
        return 1
    run = [
        *asv,
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
