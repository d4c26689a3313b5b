"""The ``pcabench`` command line.

    pcabench run --solver linkedlist-cpu --dx 0.1 --t-end 10
    pcabench profile
    pcabench study --quick | --paper | --stability
    pcabench report

Bad input ends with one line naming the parameter and its allowed range, and
exit code 2; a run that fails (unstable, out of memory) is reported with its
status and exit code 1.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
import time

from solvers import INTEGRATORS, MODELS, PRECISIONS, SOLVERS, Scene, SceneError, SolverUnavailable


class Progress:
    """Step progress on stderr, at most every ``every`` seconds, with an ETA."""

    def __init__(self, label: str, every: float = 2.0, stream=sys.stderr):
        self.label, self.every, self.stream = label, every, stream
        self.t0 = self.last = time.perf_counter()

    def __call__(self, done: int, total: int) -> None:
        now = time.perf_counter()
        if done <= 1:  # the clock starts with the first step, after compilation
            self.t0 = self.last = now
            return
        if now - self.last < self.every and done < total:
            return
        self.last = now
        rate = (now - self.t0) / max(done, 1)
        eta = rate * (total - done)
        self.stream.write(f"\r{self.label}: step {done}/{total} ({100 * done / total:5.1f} %), "
                          f"eta {eta:6.1f} s ")
        if done == total:
            self.stream.write("\n")
        self.stream.flush()


def _positive_int(name):
    def parse(text):
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{name} must be an integer >= 1 (got {text!r})")
        if value < 1:
            raise argparse.ArgumentTypeError(f"{name} must be an integer >= 1 (got {value})")
        return value
    return parse


def _number(name):
    def parse(text):
        try:
            value = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{name} must be a number (got {text!r})")
        if not math.isfinite(value):
            raise argparse.ArgumentTypeError(f"{name} must be finite (got {text!r})")
        return value
    return parse


def add_scene_options(p: argparse.ArgumentParser) -> None:
    p.add_argument("--precision", default="float64", choices=PRECISIONS)
    p.add_argument("--dx", type=_number("--dx"), required=True, help="lattice spacing, m (paper: 1 .. 0.004)")
    end = p.add_mutually_exclusive_group()
    end.add_argument("--steps", type=_positive_int("--steps"), help="number of steps (default 100, the paper's)")
    end.add_argument("--t-end", type=_number("--t-end"), help="physical end time, s")
    p.add_argument("--model", default="lagrangian", choices=MODELS)
    p.add_argument("--integrator", default="verlet", choices=INTEGRATORS)
    p.add_argument("--strip-height", type=_number("--strip-height"),
                   help="replace the 20 m height by a y-periodic strip of this height, m")
    p.add_argument("--cutoff", type=_number("--cutoff"), default=3.0, help="kernel cutoff in units of h (default 3)")
    p.add_argument("--h-factor", type=_number("--h-factor"), default=2.13, help="h / dx (default 2.13)")
    p.add_argument("--cfl", type=_number("--cfl"), default=0.2, help="dt * c0 / dx (default 0.2)")


def scene_from_args(args) -> Scene:
    return Scene(dx=args.dx, precision=args.precision, model=args.model, integrator=args.integrator,
                 steps=args.steps, t_end=args.t_end, strip_height=args.strip_height,
                 cutoff_factor=args.cutoff, h_factor=args.h_factor, cfl=args.cfl)


def cmd_run(args) -> int:
    from pcabench.run import run
    from pcabench.profiles import profile_id

    scene = scene_from_args(args)
    if not args.json:
        print(f"pcabench run: {args.solver}, {scene.describe()}", flush=True)
    progress = None if args.quiet else Progress(args.solver)
    record = run(scene, args.solver, threads=args.threads, fields_path=args.fields,
                 progress=progress, profile_id=profile_id())
    if args.json:
        out = {key: getattr(record, key) for key in record.CONTRACT}
        out["threads"] = record.threads
        out["message"] = record.message
        print(json.dumps(out, allow_nan=True))
    else:
        print(record.stage_table())
        print(f"particles        {record.n_particles:,}")
        print(f"steps            {record.steps} (t = {record.t_end:.6g} s)")
        print(f"mean neighbours  {record.mean_neighbours:.2f}")
        print(f"MSE (rel. RMS)   {record.mse:.6g}")
        print(f"ME (max, m/s)    {record.me:.6g}")
        print(f"status           {record.status}"
              + (f" at step {record.failed_step}" if record.failed_step else ""))
        if record.message:
            print(f"message          {record.message.splitlines()[0]}")
    return 0 if record.status == "ok" else 1


def cmd_profile(args) -> int:
    from pcabench import profiles

    profile = profiles.capture(with_gpu=not args.no_gpu)
    if args.asv:
        from pcabench import asv_machine

        print(asv_machine.write(profile))
        return 0
    if args.save:
        path = profiles.save(profile, args.out)
        print(f"wrote {path}", file=sys.stderr)
    print(json.dumps(profile, indent=2))
    return 0


def cmd_gpu_check(args) -> int:
    from pcabench.gpu_check import main as gpu_main

    return gpu_main(args.rest)


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="pcabench", description=__doc__.split("\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)

    p = sub.add_parser("run", help="run one scene on one solver and print the stage table")
    p.add_argument("--solver", required=True, choices=SOLVERS)
    add_scene_options(p)
    p.add_argument("--threads", type=_positive_int("--threads"), help="threads for linkedlist-cpu (default: serial)")
    p.add_argument("--fields", help="write the final fields (x, y, u, v, drho, t) to this .npz")
    p.add_argument("--json", action="store_true", help="print exactly one JSON object on stdout")
    p.add_argument("--quiet", action="store_true", help="no progress on stderr")
    p.set_defaults(func=cmd_run)

    p = sub.add_parser("profile", help="capture this machine's hardware profile")
    p.add_argument("--save", action="store_true", help="store it under hardware_profiles/")
    p.add_argument("--out", help="folder to store it in (default: the package's hardware_profiles/)")
    p.add_argument("--no-gpu", action="store_true")
    p.add_argument("--asv", action="store_true",
                   help="write this machine's entry into ~/.asv-machine.json and print its name (for --machine)")
    p.set_defaults(func=cmd_profile)

    from pcabench.study import add_study_commands

    add_study_commands(sub)
    p = sub.add_parser("gpu-check", add_help=False,
                       help="on a GPU machine: GPU tests, CPU comparison, timing sweep, profile")
    p.set_defaults(func=cmd_gpu_check)
    return parser


def main(argv=None) -> int:
    parser = build_parser()
    args, rest = parser.parse_known_args(argv)
    if args.command != "gpu-check" and rest:
        parser.error(f"unrecognized arguments: {' '.join(rest)}")
    args.rest = rest
    try:
        return args.func(args)
    except SceneError as exc:
        parser.exit(2, f"pcabench: error: {exc}\n")
    except SolverUnavailable as exc:
        parser.exit(3, f"pcabench: {exc}\n")
    except KeyboardInterrupt:
        parser.exit(130, "pcabench: interrupted\n")


if __name__ == "__main__":
    sys.exit(main())
