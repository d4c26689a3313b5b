"""All of the GPU work in one command, within one time budget, rehearsed where there is no GPU.

    pcabench gpu-check --out DIR [--budget SECONDS]      # on a GPU machine
    pcabench gpu-check --rehearse --out DIR              # anywhere: the same script in numba's simulator

A GPU machine is lent rarely and briefly, so the first real run has to work
and bring everything back from one call. The check runs these stages
(:func:`stages`: its own, :data:`OWN`, the paper's among them from its folder
(``pcabench/studies/paper/gpu.py``), and each other study's from its folder,
``pcabench/studies/<study>/gpu.py``, found by the registry
:data:`pcabench.gpu.stage.STAGES`; a stage is one function of the shared
:class:`~pcabench.gpu.stage.Check`) in order of value, each given what is
left of the budget, and stops cleanly when the budget is spent, keeping what
it has:

1. ``profile``: the hardware profile, with the card's measured ceilings
   (device copy bandwidth, FP32 and FP64 FMA rates, the SM clock);
2. ``compare``: linkedlist-gpu against linkedlist-cpu, every model and precision;
   the studies' stages: ``walls`` the same on the scenes with rigid walls
   (plane-wall, pulse-wall: mirror particles), linear and lagrangian, both
   precisions; ``open`` on open edges (the 2D pulse's open square with the PML,
   the paper's pulse's open x with the sponge), and the time per step closed and
   open, alternating; ``body`` on the workshop's cylinder, each boundary method
   (ghost particles); ``high-order`` with the gradient correction;
3. ``sweep``: linkedlist-gpu, lagrangian Verlet, both precisions, 100K to 62.5M
   particles on the paper's domain, steps sized to the budget; runs go to the
   results store (preset ``gpu``, the paper's plan) through the ordinary sweep, in this process
   so that kernels compile once;
4. ``graph``: the step captured as a CUDA graph against plain launches, in the
   same process, alternating, best of several rounds, and their fields compared;
5. ``cpu``: linkedlist-cpu on this host (one thread and every core): Table 6's
   same-machine CPU column;
6. ``asv``: asv's GPU benchmarks at HEAD and at the H100's commit, when asv
   and the history were brought along (tools/device_payload.py carries them);
7. ``bench``: the pytest-benchmark suite's JSON; ``pytest-gpu``: the GPU tests;
8. ``ncu``: Nsight Compute's speed-of-light section of one step's kernels;
9. the reports, regenerated from the store.

Everything to bring back ends up in DIR: ``gpu_check.md`` (tables),
``gpu_check.log`` is the caller's, and ``gpu_check.tar.gz`` (store, profile,
reports, JSON and logs), at most a few files of a few MiB.

The full plan was sized from the H100 run at bf587a5 (one lagrangian step at
62.5M particles: 98 ms float32, 170 ms float64; 5-8 s to copy the fields back
and sort them on the host at that size; about 20 s of compilation per
process) to take about 6 minutes of an H200, leaving a default budget of
8 minutes some slack. The rehearsal runs every stage end to end at a few
hundred particles in the simulator (the graph and the ceilings need a GPU
and say so), which is what CI runs so that the script cannot rot.
"""

from __future__ import annotations

import json
import os
import shutil
import sys
import tarfile
import time
from pathlib import Path

from pcabench.gpu.ceilings import measure_ceilings
from pcabench.gpu.plan import Budget, Plan
from pcabench.gpu.stage import STAGES, Check, Stage
from pcabench.gpu.tables import markdown
from pcabench.gpu.tools import ncu_command, run_logged
from pcabench.spec import OptionError
from pcabench.store import store_name
from pcabench.store.safeio import fresh, own_folder, write_file
from solvers.gpu.device import device_backend, simulated

H100_COMMIT = "bf587a5"  # the commit the H100 was measured at: asv compares the cards there


# ---------------------------------------------------------------- the check's own stages
def measure(c: Check):
    if c.cupy is None:
        c.profile["measured"] = {"note": "rehearsal: no GPU, no ceilings"}
    else:
        c.profile["measured"] = measure_ceilings(c.cupy)
    from pcabench.machine import profiles

    profiles.save(c.profile)
    write_file(c.out / "profile.json", json.dumps(c.profile, indent=2) + "\n")


def asv(c: Check) -> bool:
    from pcabench.gpu.asv_stage import run_asv_gpu

    c.state["asv"] = run_asv_gpu(
        c.out / "asv",
        commits=("HEAD", H100_COMMIT),
        budget_s=min(150, c.budget.left()),
        bench=c.plan.asv_bench,
        asv_args=("--quick",),
    )
    return all(r.get("returncode") == 0 for r in c.state["asv"])


def bench(c: Check) -> bool:
    json_path = c.out / f"pytest-benchmark_{c.profile['id']}.json"
    cmd = [
        sys.executable,
        "-m",
        "pytest",
        "-o",
        "addopts=",
        "-p",
        "no:cacheprovider",
        "benchmarks/ci",
        "--benchmark-only",
        f"--benchmark-json={json_path}",
        "-q",
    ]
    if c.rehearse:
        cmd += ["-k", "linkedlist and step"]
    c.state["bench"] = run_logged(cmd, c.out / "pytest_benchmark.log", min(120, c.budget.left()), c.env)
    return c.state["bench"]["exit"] == 0


def pytest_gpu(c: Check) -> bool:
    c.state["pytest_gpu"] = run_logged(
        [sys.executable, "-m", "pytest", "-m", "gpu", "-q", "-p", "no:cacheprovider", "tests"],
        c.out / "pytest_gpu.log",
        min(150, c.budget.left()),
        c.env,
    )
    return c.state["pytest_gpu"]["exit"] in (0, 5)  # 5: every GPU test deselected or skipped (rehearsal)


def ncu(c: Check) -> bool:
    if shutil.which("ncu") is None or c.cupy is None:
        c.state["ncu"] = {"status": "no ncu or no GPU here"}
        return True
    c.state["ncu"] = run_logged(ncu_command(c.plan, c.out), c.out / "ncu.log", min(90, c.budget.left()), c.env)
    return c.state["ncu"]["exit"] == 0


# Each one's seconds to start (what it needs at the least), its work and its place: the studies' stages (walls 20,
# open 40, body 50, high-order 60; STAGES, each study's gpu.py) run between them, in order of value.
OWN = (
    Stage("profile", 0, measure, order=0),
    Stage("asv", 60, asv, order=90),
    Stage("bench", 60, bench, order=100),
    Stage("pytest-gpu", 40, pytest_gpu, order=110),
    Stage("ncu", 45, ncu, order=120),
)


def stages(given: tuple = ()) -> list[Stage]:
    """Every stage the check runs, in order: its own, those its caller ``given`` (the paper study's: the command
    line hands them in, pcabench/studies/paper/gpu.py) and each study's registered one (read at each check). A
    study's gpu.py that does not load, or a study's stage named like one of the check's own, is one failed
    stage: the check still runs every other stage (the given ones too) and brings back what it has."""
    own = {s.name for s in (*OWN, *given)}
    try:
        studies = list(STAGES.all().values())
        clash = sorted(own & {s.name for s in studies})
        if clash:
            raise ValueError(f"a study's GPU stage takes the check's own name {', '.join(clash)}")
    except Exception as exc:  # noqa: BLE001 - reported as a failed stage, never the check's end
        why = f"the studies' GPU stages (pcabench/studies/*/gpu.py): {type(exc).__name__}: {exc}"

        def failed(c):
            raise RuntimeError(why)

        studies = [Stage("studies", 0, failed, order=15)]
    return sorted((*OWN, *given, *studies), key=lambda s: (s.order, s.name))


def run_stage(stage: Stage, c: Check) -> None:
    """Run ``stage`` if its seconds are left; record its status and keep going on failure."""
    t0 = time.perf_counter()
    if c.budget.left() < stage.need_s:
        status = f"not run: {c.budget.left():.0f} s left, needs about {stage.need_s:.0f}"
    else:
        c.budget.say(f"{stage.name} ...")
        try:
            value = stage.work(c)
            status = "ok" if value is not False else "failed"
        except Exception as exc:  # noqa: BLE001 - one stage's failure must not lose the others' results
            status = f"failed: {type(exc).__name__}: {str(exc)[:300]}"
    c.state["stages"].append({"stage": stage.name, "status": status, "seconds": time.perf_counter() - t0})
    c.budget.say(f"{stage.name}: {status}")


# ---------------------------------------------------------------- the check
TOOLS = {"asv": "asv", "pytest": "pytest-gpu", "pytest_benchmark": "bench"}  # module -> the stage that runs it


def missing_tools() -> list[str]:
    """The Python tools a stage needs that this environment lacks (each with the extra that installs it)."""
    import importlib.util

    extra = {"asv": "bench", "pytest": "test", "pytest_benchmark": "bench"}
    return [
        f"{module} (its {stage!r} stage; pip install -e '.[{extra[module]}]')"
        for module, stage in TOOLS.items()
        if importlib.util.find_spec(module) is None
    ]


def gpu_check(
    out: Path,
    results: Path,
    reports: Path,
    plan: Plan,
    budget_s: float = 480.0,
    rehearse: bool = False,
    given: tuple = (),
) -> int:
    """Every stage of :func:`stages` (with the caller's ``given`` ones) within ``budget_s`` seconds, at the sizes
    of ``plan``; 0 when every stage that ran passed, else 1.

    With ``rehearse`` (no GPU needed) the kernels run in numba's CUDA simulator at a few hundred particles.
    """
    out = own_folder(out, "--out")  # never a link: the check writes and bundles everything in it
    missing = missing_tools()  # before any stage: a tool found missing 290 s in is minutes of a loan lost
    if missing:
        raise OptionError(f"gpu-check needs {', '.join(missing)}: none of its stages was run")
    if rehearse:
        from numba.core import config

        os.environ["NUMBA_ENABLE_CUDASIM"] = "1"  # for the child processes (asv, pytest)
        config.reload_config()  # and this one: numba read its settings when the solver registry imported it
    from pcabench.machine import profiles
    from pcabench.reports.build import write_reports
    from pcabench.store.provenance import git_commit

    budget = Budget(budget_s)
    _cuda, cupy = device_backend()  # raises SolverUnavailable with a clear message (no GPU, no simulator)
    state = {"budget_s": budget_s, "commit": git_commit(), "rehearsal": rehearse or simulated(), "stages": []}
    profile = profiles.capture()
    c = Check(
        plan,
        out,
        budget,
        state,
        profile,
        cupy,
        Path(results) / store_name(profile["id"]),
        rehearse,
        dict(os.environ, PCABENCH_COMMIT=state["commit"]),
    )
    every = stages(given)
    for stage in every:
        run_stage(stage, c)

    state["elapsed_s"] = budget.elapsed()
    text = markdown(profile, state, every)
    write_file(out / "gpu_check.md", text)
    write_file(out / "gpu_check.json", json.dumps(state, indent=1, default=str) + "\n")
    print(text, flush=True)
    try:
        for p in write_reports(Path(results), Path(reports)):
            print(f"wrote {p}", file=sys.stderr)
    except Exception as exc:  # noqa: BLE001 - the tarball must still be written
        state["stages"].append({"stage": "reports", "status": f"failed: {exc}", "seconds": 0.0})
    bundle(out, Path(results), Path(reports), profile["id"])
    budget.say(f"done; bring back {out / 'gpu_check.tar.gz'}")
    return 0 if all(s["status"] == "ok" or s["status"].startswith("not run") for s in state["stages"]) else 1


def bundle(out: Path, results: Path, reports: Path, machine: str) -> Path:
    """One tarball of what to bring back: the check's files, this machine's store and profile, the reports."""
    from pcabench import paths

    path = fresh(out / "gpu_check.tar.gz")
    with tarfile.open(path, "w:gz") as tar:
        for f in sorted(out.iterdir()):
            if f.name != path.name and (f.is_file() or f.is_dir()):
                tar.add(f, arcname=f"check/{f.name}")
        for f in sorted(results.glob(f"{machine}--*.jsonl")):
            tar.add(f, arcname=f"store/{f.name}")
        profile = paths.user_profiles() / f"{machine}.json"
        if profile.exists():
            tar.add(profile, arcname=f"profiles/{profile.name}")
        if reports.is_dir():
            tar.add(reports, arcname="reports")
    return path
