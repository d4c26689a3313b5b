"""A solver prepared for benchmarking, shared by the asv suite and the pytest-benchmark suite.

It lives beside the asv suite, not in the package, because asv benchmarks
older commits with the suite of the working tree: this file uses only the
solver interface (Scene, make_solver, step_program) that every commit has.
The solvers are the top-level package ``solvers``; commits before the layout
change had them at ``pcabench.solvers``, so :data:`solvers` is whichever exists.

``Prepared(solver, precision, dx)`` compiles (outside any timed region), places
the particles and takes the first step, so that the timed calls are steady
state: ``step()`` is one whole step, ``stage("pi")`` only that stage's
operations of one step (the stages of a step add up to the step). Each call
ends with ``synchronize()``, so a GPU's queued work is inside the timing.

Nothing here touches CUDA at import: ``gpu_available()`` imports CuPy only
when asked, and a GPU solver is built only when one exists.
"""

from __future__ import annotations

import abc
import functools
import os
import subprocess
import sys
from importlib import import_module


def _solver_package():
    """``solvers``, or ``pcabench.solvers`` in commits before the layout change (a leftover folder of one
    layout can make the other name importable as an empty namespace: the one with Scene is the one)."""
    for name in ("solvers", "pcabench.solvers"):
        try:
            package = import_module(name)
        except ImportError:
            continue
        if hasattr(package, "Scene"):
            return package
    raise ImportError("no solver package: neither solvers nor pcabench.solvers has Scene")


solvers = _solver_package()

Scene, make_solver = solvers.Scene, solvers.make_solver


def _module(*names: str):
    """The first of ``names`` (under the solver package) that imports: where a module lives in this commit's
    layout (solvers/reference/, solvers/physics/ since issue 40; the package's root before)."""
    for name in names:
        try:
            return import_module(f"{solvers.__name__}.{name}")
        except ImportError:
            continue
    raise ImportError(f"none of {', '.join(names)} in {solvers.__name__}")


analytic_errors = _module("reference.analytic", "analytic").errors
step_program = _module("physics.integrators", "integrators").step_program


def solver_names(device: str | None = None) -> list:
    """The solvers to benchmark: every registered one (plug-ins included), or those on ``device`` (cpu, gpu).
    Commits before the registry (2026-11-30) had these three built in."""
    if hasattr(solvers, "registry"):
        return [name for name, cls in solvers.registry().items() if device in (None, cls.device)]
    builtin = {"allpair-cpu": "cpu", "linkedlist-cpu": "cpu", "linkedlist-gpu": "gpu"}
    return [name for name, where in builtin.items() if device in (None, where)]


def is_gpu(solver: str) -> bool:
    return solver in solver_names("gpu")


def is_all_pairs(solver: str) -> bool:
    """Whether ``solver`` tests every pair (O(N^2)), so that it stops at ALLPAIR_MAX_N."""
    if hasattr(solvers, "registry"):
        return solvers.solver_class(solver).order >= 2
    return solver == "allpair-cpu"


def thinnest_strip(dx: float) -> float:
    """The thinnest y-periodic strip Scene accepts at ``dx``, m (older commits: the harness's presets)."""
    if hasattr(Scene, "thinnest_strip"):
        return Scene.thinnest_strip(dx)
    from pcabench.presets import strip_height  # commits before Scene owned the strip rule

    return strip_height(dx)


# Particle counts: seconds on a laptop CPU by default; PCABENCH_BENCH_LARGE=1 adds 100K and 400K.
SMALL_DX = (1.0, 0.5, 0.25)  # 1K, 4K, 16K particles on the paper's domain
LARGE_DX = (0.1, 0.05)
GPU_DX = (0.1, 0.05, 0.025)  # 100K .. 1.6M; large adds 10M
GPU_LARGE_DX = (0.01,)
ALLPAIR_MAX_N = 16_000  # all-pair is O(N^2): 16K is about 1 s per step on a laptop core


def large() -> bool:
    return os.environ.get("PCABENCH_BENCH_LARGE", "") not in ("", "0")


def cpu_dx() -> tuple:
    return SMALL_DX + (LARGE_DX if large() else ())


def gpu_dx() -> tuple:
    return GPU_DX + (GPU_LARGE_DX if large() else ())


@functools.lru_cache(maxsize=None)
def gpu_available() -> bool:
    """A real CUDA device with CuPy and numba-cuda (never the simulator)."""
    if os.environ.get("NUMBA_ENABLE_CUDASIM") == "1":
        return False
    try:
        gpu = import_module(f"{solvers.__name__}.linkedlist_gpu")
        device_backend, simulated = gpu.device_backend, gpu.simulated

        return not simulated() and device_backend()[1] is not None
    except Exception:  # noqa: BLE001 - no CuPy, no driver, no device
        return False


class Unsupported(Exception):
    """This combination is not benchmarked here (no GPU; all-pair past ALLPAIR_MAX_N)."""


class Prepared:
    """One solver at steady state on the paper's scene (or ``scene`` overrides)."""

    def __init__(self, solver: str, precision: str = "float64", dx: float = 0.5, threads=1, pair_loop=None, **scene):
        self.scene = Scene(dx=dx, precision=precision, **{"steps": 100, **scene})
        if is_gpu(solver) and not gpu_available():
            raise Unsupported("no CUDA GPU here")
        if is_all_pairs(solver) and self.scene.n_particles > ALLPAIR_MAX_N:
            raise Unsupported(f"all-pair past {ALLPAIR_MAX_N:,} particles")
        self.name = solver
        # pair_loop: commits before the pair list have none (Unsupported there)
        options = {"threads": threads} if pair_loop is None else {"threads": threads, "pair_loop": pair_loop}
        try:
            self.solver = make_solver(solver, **options)
        except TypeError as exc:
            raise Unsupported(f"this commit's solvers take no pair_loop ({exc})") from None
        self.solver.input(self.scene)
        self.jit_seconds = self.solver.warmup()
        self.solver = make_solver(solver, **options)
        self.solver.input(self.scene)
        self.solver.init()
        self.program = step_program(self.scene.integrator, self.solver, first=False)
        for _, op in step_program(self.scene.integrator, self.solver, first=True):
            op()
        self.solver.synchronize()

    @property
    def n_particles(self) -> int:
        return self.scene.n_particles

    def step(self) -> None:
        """One whole step (SNP + PI + SU)."""
        for _, op in self.program:
            op()
        self.solver.synchronize()

    def stage(self, name: str) -> None:
        """Only the ``name`` operations of one step (snp, pi or su)."""
        for stage, op in self.program:
            if stage == name:
                op()
        self.solver.synchronize()

    def errors(self):
        """Errors of u against the analytic pulse at the solver's current time."""
        f = self.solver.output()
        return analytic_errors(self.scene, f.x, f.u, f.t)


class StageBenchmarks(abc.ABC):
    """asv time_ benchmarks of one step and of each stage of ``self.p``, the Prepared that ``setup`` makes.

    Abstract, so that asv does not collect it where it is defined or imported.
    """

    @abc.abstractmethod
    def setup(self, *params):
        """Make ``self.p``; raise NotImplementedError to skip these parameters."""

    def time_step(self, *_):
        self.p.step()

    def time_snp(self, *_):
        self.p.stage("snp")

    def time_pi(self, *_):
        self.p.stage("pi")

    def time_su(self, *_):
        self.p.stage("su")


def jit_seconds_in_fresh_process(solver: str, precision: str, cache: str | None = None) -> float:
    """Compilation time of ``solver`` in a fresh interpreter, s, with the JIT cache (solvers/jitcache.py) in
    the folder ``cache`` (None: the user's): an empty folder times a cold compile, as a new user's first
    run meets it; a folder a run has filled times the load from the cache, as every later run meets it."""
    code = (
        f"from {solvers.__name__} import Scene, make_solver\n"
        f"s = make_solver({solver!r}); s.input(Scene(dx=1.0, precision={precision!r}))\n"
        "print(s.warmup())"
    )
    env = dict(os.environ, **({"PCABENCH_CACHE": cache} if cache else {}))
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=600, env=env)
    if proc.returncode != 0:
        raise RuntimeError(proc.stderr.strip()[-400:])
    return float(proc.stdout.strip().splitlines()[-1])
