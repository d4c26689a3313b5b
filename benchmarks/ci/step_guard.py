"""The paper's scene's step, this checkout against an earlier commit, alternating in one run: a warning
(exit 0), or with ``--fail`` exit 1, when this checkout's step is more than ``--threshold`` slower.

    python benchmarks/ci/step_guard.py                      # against HEAD~1, 4 pairs, warn past 10 %
    python benchmarks/ci/step_guard.py --against f13fa50 --fail
    python benchmarks/ci/step_guard.py -- --pair-loop gather  # options after -- go to pcabench run

Each side is ``pcabench run --solver linkedlist-cpu --dx 0.05 --steps 10 --json`` (400K particles on the
paper's full domain, serial float64, the scene's default model) in a fresh interpreter of its own
(``PCABENCH_FORKSERVER=0``), importing its own tree (``PYTHONPATH``; the earlier commit comes from ``git
archive``, the environment is this one). The figure is the stage clock's SNP + PI + SU per particle-step:
compiling stays out of it. The sides alternate (then/now, now/then, ...) and each side's best run counts, so a
neighbour's job on a shared machine can only slow a run down, not tilt the ratio. Without git or without the
commit (a shallow CI checkout), one line says so and the guard is skipped (exit 0), unless ``--against``
was given.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
STAGES = ("snp", "pi", "su")


def positive(kind, name):
    def parse(text):
        try:
            value = kind(text)
        except ValueError:
            value = None
        if value is None or not value > 0:
            raise argparse.ArgumentTypeError(f"{name} must be a number > 0 (got {text!r})")
        return value

    return parse


def commit_of(rev: str) -> str | None:
    out = subprocess.run(
        ["git", "-C", str(ROOT), "rev-parse", "--verify", "--quiet", f"{rev}^{{commit}}"],
        capture_output=True,
        text=True,
    )
    return out.stdout.strip() or None if out.returncode == 0 else None


def export(commit: str, folder: Path) -> Path:
    """The commit's tree, unpacked in ``folder`` (no .git: it imports as code only)."""
    archive = subprocess.run(
        ["git", "-C", str(ROOT), "archive", "--format=tar", commit], capture_output=True, check=True
    )
    subprocess.run(["tar", "-x", "-C", str(folder)], input=archive.stdout, check=True)
    return folder


def side_env(tree: Path, commit: str, home: Path) -> dict:
    env = dict(os.environ)
    env.update(
        PYTHONPATH=str(tree),
        PCABENCH_FORKSERVER="0",
        PCABENCH_HOME=str(home),
        PCABENCH_COMMIT=commit,
        PCABENCH_CACHE=str(home / "cache"),
    )
    return env


def imports_from(tree: Path, env: dict) -> bool:
    code = "import pcabench, solvers; print(pcabench.__file__); print(solvers.__file__)"
    out = subprocess.run([sys.executable, "-c", code], env=env, cwd=tree, capture_output=True, text=True)
    return out.returncode == 0 and all(Path(p).resolve().is_relative_to(tree.resolve()) for p in out.stdout.split())


def step_ns(tree: Path, env: dict, run_args: list) -> float:
    """One run's SNP + PI + SU per particle-step, ns."""
    cmd = [sys.executable, "-m", "pcabench.cli", "run", "--solver", "linkedlist-cpu", "--json", "--quiet", *run_args]
    out = subprocess.run(cmd, env=env, cwd=tree, capture_output=True, text=True)
    if out.returncode != 0:
        raise SystemExit(f"step guard: {' '.join(cmd[2:])} in {tree} failed: {out.stderr.strip()[-400:]}")
    rec = json.loads(out.stdout)
    return 1e9 * sum(rec["stages"][s] for s in STAGES) / (rec["n_particles"] * rec["steps"])


class Parser(argparse.ArgumentParser):
    def error(self, message):  # one line, no usage
        self.exit(2, f"{self.prog}: error: {message}\n")


def main(argv=None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    run_args = argv[argv.index("--") + 1 :] if "--" in argv else []
    argv = argv[: argv.index("--")] if "--" in argv else argv
    p = Parser(prog="step_guard.py", description=__doc__.split("\n\n")[0])
    p.add_argument("--against", help="the earlier commit (default: HEAD~1)")
    p.add_argument("--pairs", type=positive(int, "--pairs"), default=4, help="alternating pairs of runs (default 4)")
    p.add_argument("--dx", type=positive(float, "--dx"), default=0.05, help="lattice spacing, m (default 0.05: 400K)")
    p.add_argument("--steps", type=positive(int, "--steps"), default=10, help="steps a run (default 10)")
    p.add_argument(
        "--threshold", type=positive(float, "--threshold"), default=0.10, help="slower by more than this warns (0.10)"
    )
    p.add_argument("--fail", action="store_true", help="exit 1 past the threshold (default: a warning, exit 0)")
    args = p.parse_args(argv)
    then = commit_of(args.against or "HEAD~1")
    if then is None:
        if args.against:
            p.exit(2, f"step_guard.py: error: --against {args.against!r} is not a commit of {ROOT}\n")
        print("step guard: skipped: no earlier commit here (git history absent or shallow)")
        return 0
    now = commit_of("HEAD") or "unknown"
    dirty = subprocess.run(["git", "-C", str(ROOT), "status", "--porcelain", "-uno"], capture_output=True, text=True)
    now_label = now[:10] + (" with uncommitted changes" if dirty.stdout.strip() else "")
    run_args = ["--dx", repr(args.dx), "--steps", str(args.steps), *run_args]
    with tempfile.TemporaryDirectory(prefix="pcabench-step-guard-") as tmp:
        tmp = Path(tmp)
        (tmp / "then").mkdir()
        sides = {
            "then": (export(then, tmp / "then"), side_env(tmp / "then", then, tmp / "home-then")),
            "now": (ROOT, side_env(ROOT, now, tmp / "home-now")),
        }
        for name, (tree, env) in sides.items():
            if not imports_from(tree, env):
                p.exit(2, f"step_guard.py: error: the {name} side does not import its own tree {tree}\n")
        best = {"then": float("inf"), "now": float("inf")}
        print(f"step guard: {' '.join(run_args)}; then {then[:10]}, now {now_label}", flush=True)
        for i in range(args.pairs):
            order = ("then", "now") if i % 2 == 0 else ("now", "then")
            ns = {side: step_ns(*sides[side], run_args) for side in order}
            for side, t in ns.items():
                best[side] = min(best[side], t)
            print(f"  pair {i + 1}: then {ns['then']:.0f} ns, now {ns['now']:.0f} ns a particle-step", flush=True)
    ratio = best["now"] / best["then"]
    verdict = "slower" if ratio > 1 else "faster"
    print(
        f"step guard: best then {best['then']:.0f} ns, now {best['now']:.0f} ns: now/then {ratio:.3f} "
        f"({abs(ratio - 1):.1%} {verdict})"
    )
    if ratio > 1 + args.threshold:
        past = f"{ratio - 1:.1%} slower than {then[:10]}'s (threshold {args.threshold:.0%})"
        print(f"step guard: WARNING: the step is {past}")
        return 1 if args.fail else 0
    return 0


if __name__ == "__main__":
    sys.exit(main())
