"""The benchmark suites themselves: the ratio checker can fail, and no suite touches CUDA at import."""

from __future__ import annotations

import subprocess
import sys

import pytest


def ci_module(name: str):
    """benchmarks/ci/<name>.py, loaded from its file (a folder of scripts and pytest-benchmark's suite, no
    package, so that asv never imports it)."""
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "benchmarks" / "ci" / f"{name}.py"
    spec = importlib.util.spec_from_file_location(f"ci_{name}", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


check = ci_module("check_ratios").check


def medians(ll_step=1.0, ap_step=3.0, parts=(0.1, 0.8, 0.1)):
    out = {}
    for solver, step in (("linkedlist-cpu", ll_step), ("allpair-cpu", ap_step)):
        out[(solver, "float64", 1000, "step")] = step
        for stage, share in zip(("snp", "pi", "su"), parts):
            out[(solver, "float64", 1000, stage)] = step * share
    return out


def test_ratio_checks_pass_and_fail():
    assert check(medians()) == []
    slow = check(medians(ll_step=4.0))
    assert len(slow) == 1 and "not faster than all-pair" in slow[0]
    off = check(medians(parts=(0.1, 0.5, 0.1)))
    assert len(off) == 2 and all("SNP+PI+SU" in f for f in off)
    assert "no benchmark pairs" in check({})[0]


def test_benchmark_modules_import_without_cuda():
    code = (
        "import sys; sys.path.insert(0, '.')\n"
        "import benchmarks.bench_step, benchmarks.bench_gpu, benchmarks.bench_accuracy, "
        "benchmarks.bench_memory, benchmarks.bench_jit, benchmarks.common\n"
        "bad = [m for m in sys.modules if m.startswith(('cupy', 'numba.cuda'))]\n"
        "assert not bad, bad"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr


def test_every_builtin_scene_is_benchmarked_and_each_walled_one_beside_a_free_twin_of_its_size():
    """The suites' scene lists (asv's TrackSceneError and TimeWallStep, pytest-benchmark's scene step, the
    conformance scenes) hold every built-in scene kind; each walled scene in TimeWallStep has a free twin
    there with the same particle count and box, so that the step's difference is the wall's."""
    from benchmarks.bench_accuracy import TrackSceneError
    from benchmarks.bench_step import WALL_DX, WALL_PAIRS, TimeWallStep
    from pcabench.conformance import SCENES
    from solvers import Scene
    from solvers.scenes import scenes

    SCENE_CASES = ci_module("test_stages").SCENE_CASES

    builtin = {name for name, kind in scenes().items() if type(kind).__module__.startswith("solvers.scenes.")}
    assert builtin <= set(TrackSceneError.params[0]) and builtin <= set(SCENE_CASES) and builtin <= set(SCENES)
    walled = {name for name in builtin if Scene(**SCENES[name]).walls}
    assert walled == {"plane-wall", "pulse-wall"} and set(TimeWallStep.params[0]) == set(WALL_PAIRS)

    def lattice(name):
        box = {k: v for k, v in WALL_PAIRS[name].items() if k != "strip"}
        strip = Scene.thinnest_strip(WALL_DX) if WALL_PAIRS[name].get("strip") else None
        s = Scene(name=name, dx=WALL_DX, strip_height=strip, **box)
        return s.n_particles, s.x_lo, s.y_lo, s.width, s.height, bool(s.walls)

    lattices = [lattice(name) for name in WALL_PAIRS]
    with_wall = {lat[:-1] for lat in lattices if lat[-1]}
    without = {lat[:-1] for lat in lattices if not lat[-1]}
    assert len(with_wall) == len(walled) and with_wall == without, lattices


def test_the_step_guard_warns_past_its_threshold_and_fails_only_when_asked(monkeypatch, capsys):
    """benchmarks/ci/step_guard.py's verdict on each side's best run (the runs themselves faked here)."""
    guard = ci_module("step_guard")

    if guard.commit_of("HEAD~1") is None:
        pytest.skip("no earlier commit in this checkout")
    times = {"then": [530.0, 500.0], "now": [600.0, 640.0]}  # best: then 500, now 600 ns (20 % slower)
    calls = []

    def step_ns(tree, env, args):
        side = "now" if tree == guard.ROOT else "then"
        calls.append(side)
        return times[side][sum(c == side for c in calls) % 2]

    monkeypatch.setattr(guard, "export", lambda commit, folder: folder)
    monkeypatch.setattr(guard, "imports_from", lambda tree, env: True)
    monkeypatch.setattr(guard, "step_ns", step_ns)
    assert guard.main(["--pairs", "2"]) == 0
    out = capsys.readouterr().out
    assert "WARNING" in out and "now/then 1.200" in out
    assert calls == ["then", "now", "now", "then"]  # alternating, the order flipped each pair
    assert guard.main(["--pairs", "2", "--fail"]) == 1
    capsys.readouterr()
    times["now"] = [540.0, 545.0]  # 8 %: within the 10 %
    assert guard.main(["--pairs", "2", "--fail"]) == 0 and "WARNING" not in capsys.readouterr().out
    assert guard.main(["--pairs", "2", "--fail", "--threshold", "0.05"]) == 1


@pytest.mark.tier2  # two trees' step timed alternating: 20 s (the second tier)
def test_the_step_guard_runs_each_side_from_its_own_tree(tmp_path):
    """End to end at 400 particles against HEAD exported by git archive: each side imports its own tree."""
    guard = ci_module("step_guard")

    if guard.commit_of("HEAD") is None:
        pytest.skip("not a git checkout")
    cmd = [sys.executable, "benchmarks/ci/step_guard.py", "--against", "HEAD", "--pairs", "1", "--dx", "1"]
    out = subprocess.run(cmd + ["--steps", "2"], capture_output=True, text=True, cwd=guard.ROOT, timeout=600)
    assert out.returncode == 0, out.stdout + out.stderr
    assert "pair 1: then" in out.stdout and "now/then" in out.stdout
