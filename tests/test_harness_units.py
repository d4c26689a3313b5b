"""Units of the harness that break first: the thread policy, run identity, the time predictor, the clock."""

from __future__ import annotations

import math
import time

import numba
import pytest

from pcabench import store
from pcabench.execute.clock import HostClock
from pcabench.predict import CACHED_JIT, COLD_JIT, START_UP, jit_seconds, predicted_seconds, step_model
from pcabench.spec import ALL_CORES, OptionError, RunSpec, identity, resolve_threads, row_identity, usable_cores
from pcabench.store.record import STEP_STAGES, RunRecord, step_seconds
from solvers import STAGES, Scene


# ---------------------------------------------------------------- the thread policy
def test_threads_policy_one_spelling_each():
    assert resolve_threads(1, "linkedlist-cpu") == 1
    assert resolve_threads("1", "linkedlist-cpu") == 1
    assert resolve_threads(ALL_CORES, "linkedlist-cpu") == usable_cores()
    assert resolve_threads("ALL", "linkedlist-cpu") == usable_cores()
    assert resolve_threads(ALL_CORES, "allpair-cpu") == 1  # "every core" of a serial solver is one


@pytest.mark.parametrize(
    "threads,solver,words",
    [
        (0, "linkedlist-cpu", ">= 1"),
        ("two", "linkedlist-cpu", "'all'"),
        (2, "allpair-cpu", "allpair-cpu is serial"),
        (2, "linkedlist-gpu", "linkedlist-gpu is serial"),
        (numba.config.NUMBA_NUM_THREADS + 1, "linkedlist-cpu", "between 1 and"),
    ],
)
def test_bad_threads_name_the_option(threads, solver, words):
    with pytest.raises(OptionError, match="--threads") as exc:
        resolve_threads(threads, solver)
    assert words in str(exc.value)


# ---------------------------------------------------------------- run identity
def test_a_spec_and_its_stored_row_have_one_identity():
    spec = RunSpec("linkedlist-cpu", Scene(dx=1.0, steps=3, cfl=0.3), ALL_CORES, "quick").resolved()
    assert RunSpec.from_json(spec.to_json()) == spec
    record = RunRecord.from_spec(spec.resolved(), "machine-a")
    record.preset, record.code, record.host = spec.preset, "abc", "h1"
    row = store.to_row(record)
    key = spec.key("machine-a", "abc", "h1")
    assert row_identity(row) == key  # the code key, whatever the commit: a commit of documents reruns nothing
    assert row_identity(dict(row, commit="other")) == key
    # a different scene, thread count, preset, machine, code or host is another run
    others = [
        identity(spec.solver, spec.threads, spec.scene.replace(cfl=0.2), "quick", "machine-a", "abc", "h1"),
        identity(spec.solver, spec.threads + 1, spec.scene, "quick", "machine-a", "abc", "h1"),
        identity(spec.solver, spec.threads, spec.scene, "paper", "machine-a", "abc", "h1"),
        identity(spec.solver, spec.threads, spec.scene, "quick", "machine-b", "abc", "h1"),
        identity(spec.solver, spec.threads, spec.scene, "quick", "machine-a", "abd", "h1"),
        identity(spec.solver, spec.threads, spec.scene, "quick", "machine-a", "abc", "h2"),
    ]
    assert key not in others and len(set(others)) == len(others)


# ---------------------------------------------------------------- the predictor
def _ok_row(solver, n_dx, step_s, steps=10, threads=1):
    scene = Scene(dx=n_dx, steps=steps)
    stages = {s: 0.0 for s in STAGES}
    stages["pi"] = step_s * steps
    return {
        "status": "ok",
        "solver": solver,
        "threads": threads,
        "scene": scene.as_dict(),
        "n_particles": scene.n_particles,
        "steps": steps,
        "stages": stages,
    }


def test_predictor_fits_the_power_law_and_extrapolates():
    rows = [_ok_row("allpair-cpu", dx, 1e-3 * (1.0 / dx) ** 4) for dx in (1.0, 0.5, 0.25)]  # t ~ N^2
    spec = RunSpec("allpair-cpu", Scene(dx=0.125, steps=10))
    a, b, sizes = step_model(spec, rows)
    assert b == pytest.approx(2.0) and sizes == [1000, 4000, 16000]
    seconds, why = predicted_seconds(spec, rows)
    # start-up + a load from the JIT cache (the configuration ran before) + steps x step at 64K
    assert seconds == pytest.approx(START_UP + CACHED_JIT + 10 * 1e-3 * 8.0**4)
    assert "N^2.00" in why
    # one size only: the algorithm's order; other solvers, threads or failed runs are not used
    one = [_ok_row("linkedlist-cpu", 1.0, 2e-3)]
    ll = RunSpec("linkedlist-cpu", Scene(dx=0.5, steps=10))
    assert step_model(ll, one)[1] == 1.0
    assert predicted_seconds(ll, one)[0] == pytest.approx(START_UP + CACHED_JIT + 10 * 2e-3 * 4)
    # a configuration not run before pays a compile: the median of the host's cold compiles, else COLD_JIT
    f32 = RunSpec("linkedlist-cpu", Scene(dx=0.5, steps=10, precision="float32"))
    f32_rows = [dict(one[0], scene=dict(one[0]["scene"], precision="float32"))]  # the step model's data
    assert predicted_seconds(f32, f32_rows, cached=False)[0] == pytest.approx(START_UP + COLD_JIT + 10 * 2e-3 * 4)
    measured = [dict(one[0], jit_cached=False, jit_seconds=9.0), dict(one[0], jit_cached=True, jit_seconds=0.25)]
    assert jit_seconds(ll, measured, cached=False) == 9.0 and jit_seconds(ll, measured, cached=True) == 0.25
    assert predicted_seconds(RunSpec("allpair-cpu", Scene(dx=0.5, steps=10)), one) == (None, "")
    assert predicted_seconds(ll, [dict(one[0], status="error")]) == (None, "")


def test_a_threaded_run_is_predicted_from_serial_runs_by_the_hosts_measured_efficiency():
    """A first run on two threads: the serial runs inform it, each thread beyond one gaining what this host measured
    on a scene run at both counts (the 3D sphere on two threads was predicted 194 s from 2D pair-list rows on
    two threads; it takes about an hour). Rows of the spec's own loop come before another loop's."""
    ll2 = RunSpec("linkedlist-cpu", Scene(dx=0.5, steps=10), 2).resolved()
    serial = _ok_row("linkedlist-cpu", 1.0, 2e-3)
    serial["pair_loop"] = ll2.pair_loop
    # ideal without a measured pair: half the serial step
    assert predicted_seconds(ll2, [serial], cached=True)[0] == pytest.approx(START_UP + CACHED_JIT + 10 * 1e-3 * 4)
    # a scene at both counts: 1.6 times faster on two threads is an efficiency of 0.8
    pair = [dict(serial, scene=dict(serial["scene"], t_end=None, steps=3)), None]
    pair[1] = dict(pair[0], threads=2, stages=dict(pair[0]["stages"], pi=pair[0]["stages"]["pi"] / 1.6))
    seconds = predicted_seconds(ll2, [serial, *pair], cached=True)[0]
    assert seconds == pytest.approx(START_UP + CACHED_JIT + 10 * 2e-3 * 4 / 1.6), seconds
    # a row on the spec's threads but another loop (ten times cheaper) is not used while its own loop has rows
    other = dict(serial, threads=2, pair_loop="gather" if ll2.pair_loop == "list" else "list")
    other["stages"] = dict(serial["stages"], pi=serial["stages"]["pi"] / 10)
    assert predicted_seconds(ll2, [serial, other], cached=True)[0] == pytest.approx(
        START_UP + CACHED_JIT + 10 * 1e-3 * 4
    )


def test_a_3d_run_is_predicted_from_3d_runs_by_the_neighbours_its_sphere_holds():
    """In 3D a particle's neighbours go as 4 pi / 3 (cutoff / dx)^3: a 3D run of another kernel informs the fit by
    that ratio (the fourth-order kernel's 894 neighbours against Wendland C2's 80), and the host's 3D runs are
    used before its 2D ones (whose pairs cost another price)."""
    cube = dict(name="acoustic-pulse-3d", steps=10, model="linear")
    row = _ok_row("linkedlist-cpu", 0.5, 0.1, steps=10)
    three = Scene(0.5, **cube, kernel="wendland-c2", h_factor=1.3)
    row3 = dict(row, scene=three.as_dict(), n_particles=three.n_particles)
    high = Scene(0.5, **cube, kernel="laguerre-gauss", h_factor=1.5, cutoff_factor=4.0)
    spec = RunSpec("linkedlist-cpu", high)
    ratio = (high.cutoff / three.cutoff) ** 3  # (6 dx / 2.6 dx)^3 the neighbours; the kernel not run here: compiled
    slow2d = dict(row, stages=dict(row["stages"], pi=100.0))  # a 2D row a hundred times dearer: not used
    for rows in ([row3], [row3, slow2d]):
        assert predicted_seconds(spec, rows)[0] == pytest.approx(START_UP + COLD_JIT + 10 * 0.1 * ratio, rel=1e-9)


def test_the_eta_counts_only_the_runs_that_will_run():
    """A run predicted past the run budget will be skipped: the ETA counts nothing for it and says so (it said
    12.9 minutes with one left, counting a run the sweep then skipped)."""
    from pcabench.execute.sweep import eta_text

    rows = [_ok_row("allpair-cpu", dx, 1e-3 * (1.0 / dx) ** 4) for dx in (1.0, 0.5, 0.25)]  # t ~ N^2
    small = RunSpec("allpair-cpu", Scene(dx=1.0, steps=10))
    huge = RunSpec("allpair-cpu", Scene(dx=0.0625, steps=10))  # predicted 655 s
    quick = predicted_seconds(small, rows)[0]
    text = eta_text([small, huge], rows, None, run_budget=60.0)
    said = f"eta {quick / 60:.1f} min (1 of 1 runs predicted from this host's timings; 1 to be skipped past the "
    assert text == said + "run budget)", text
    assert f"{(quick + predicted_seconds(huge, rows)[0]) / 60:.1f} min" in eta_text([small, huge], rows, None)


# ---------------------------------------------------------------- the clock and step time
def test_host_clock_books_each_operation_to_its_stage():
    clock = HostClock()
    clock.time("pi", time.sleep, 0.02)
    clock.time("pi", time.sleep, 0.01)
    clock.time("su", lambda: None)
    totals = clock.totals()
    assert set(totals) == set(STAGES)
    assert 0.03 <= totals["pi"] < 0.5 and totals["snp"] == 0.0 and clock.calls["pi"] == 2


def test_step_seconds_is_the_step_stages_per_step():
    stages = {s: 0.0 for s in STAGES}
    stages.update(input=5.0, init=7.0, output=9.0, snp=1.0, pi=2.0, su=3.0)
    assert STEP_STAGES == ("snp", "pi", "su")
    assert step_seconds(stages, 3) == pytest.approx(2.0)
    assert math.isfinite(step_seconds(stages, 0))  # a run that failed before its first step


def test_a_gpu_check_stage_that_fails_or_lacks_time_does_not_stop_the_next():
    """The GPU check's stages (pcabench/gpu/check.py stages(): its own and the studies'): a stage that raises is
    recorded as failed, one
    the budget cannot start is recorded as not run, and the stages after them still run."""
    from pathlib import Path

    from pcabench.gpu import check as G
    from pcabench.gpu import plan
    from pcabench.gpu import stage as S
    from pcabench.studies.paper.gpu import PAPER_STAGES, REHEARSAL

    ran = []

    def broken(c):
        raise RuntimeError("no card")

    def fine(c):
        ran.append("fine")

    budget = plan.Budget(100.0)
    budget.say = lambda *a, **k: None  # quiet
    check = S.Check(REHEARSAL, Path("."), budget, {"stages": []}, {"id": "m"}, None, Path("s.jsonl"), True, {})
    for stage in (S.Stage("broken", 0, broken), S.Stage("greedy", 1e9, fine), S.Stage("fine", 0, fine)):
        G.run_stage(stage, check)
    status = {s["stage"]: s["status"] for s in check.state["stages"]}
    assert status["broken"].startswith("failed: RuntimeError: no card")
    assert status["greedy"].startswith("not run:") and status["fine"] == "ok" and ran == ["fine"]
    assert [s.name for s in G.stages(PAPER_STAGES)][:4] == ["profile", "compare", "walls", "sweep"]  # by value


def test_the_gpu_checks_walls_stage_passes_only_what_agrees_and_shows_its_rows():
    """The walls stage (GPU against CPU on the walled scenes) fails on a row past its precision's tolerance or
    on no rows, and the check's tables list its rows; the rehearsal's walled scenes are check-solver's tiny ones."""
    from pcabench.conformance import SCENES
    from pcabench.gpu import agreement, tables
    from pcabench.studies.walls import gpu as walls_gpu
    from solvers import Scene

    row = {"scene": "pulse-wall", "N": 182, "precision": "float32", "model": "lagrangian", "dx": 1.0, "steps": 3}
    assert agreement.agrees([{**row, "max_rel_diff_u": 5e-5, "max_rel_diff_drho": 1e-5}])
    assert not agreement.agrees([{**row, "max_rel_diff_u": 5e-4, "max_rel_diff_drho": 1e-5}])
    assert not agreement.agrees([{**row, "precision": "float64", "max_rel_diff_u": 5e-5, "max_rel_diff_drho": 0.0}])
    assert not agreement.agrees([])
    text = tables.markdown(
        {"id": "m"},
        {
            "budget_s": 1,
            "elapsed_s": 1,
            "stages": [],
            "walls": [{**row, "max_rel_diff_u": 5e-5, "max_rel_diff_drho": 0}],
        },
    )
    assert "## Rigid walls" in text and "| pulse-wall | 182 | float32 | lagrangian | 1.0 | 3 | 5.00e-05 |" in text
    assert {Scene(**w).name for w in walls_gpu.cases(False).scenes} == {"plane-wall", "pulse-wall"}
    assert set(walls_gpu.cases(False).models) == {"linear", "lagrangian"}
    assert walls_gpu.cases(True).scenes and all(
        w in SCENES.values() and Scene(**w).walls for w in walls_gpu.cases(True).scenes
    )


def test_the_gpu_checks_open_stage_compares_open_scenes_and_tables_their_cost():
    """The open stage runs open scenes (the rehearsal's: check-solver's open square, free y edges and the PML)
    against the CPU, and the check's tables list them and the layer's cost on the GPU."""
    from pcabench.conformance import SCENES
    from pcabench.gpu import tables
    from pcabench.studies.open_edges import gpu as open_gpu
    from solvers import Scene

    assert open_gpu.cases(True).scenes == (SCENES["acoustic-pulse-open"],)
    assert {Scene(**s).open for s in open_gpu.cases(False).scenes} == {"x", "xy"}
    assert all(Scene(**s).open for s in open_gpu.cases(False).cost + open_gpu.cases(True).cost)
    row = {"scene": "acoustic-pulse", "N": 324, "precision": "float64", "model": "lagrangian", "dx": 1.0, "steps": 3}
    cost = {"scene": "plane-pulse", "dx": 0.025, "open": "x", "absorber": "sponge", "N": 1984000}
    cost.update(closed_N=1600000, step_ms=3.1, closed_ms=2.5, ratio=1.24)
    text = tables.markdown(
        {"id": "m"},
        {
            "budget_s": 1,
            "elapsed_s": 1,
            "stages": [],
            "open": [{**row, "max_rel_diff_u": 1e-14, "max_rel_diff_drho": 0}],
            "open_cost": [cost],
        },
    )
    assert "## Open edges" in text and "| acoustic-pulse | 324 | float64 | lagrangian | 1.0 | 3 | 1.00e-14 |" in text
    assert "| plane-pulse | 0.025 | x | sponge | 1,600,000 | 1,984,000 | 2.5 | 3.1 | 1.240 |" in text


def test_the_gpu_checks_body_stage_compares_the_cylinder_with_each_boundary_method():
    """The body stage runs the cylinder (the rehearsal's: check-solver's, one method, model and precision; on a
    card the workshop's at dx 0.04 with both boundary methods) against the CPU, and the tables list it."""
    from pcabench.conformance import SCENES
    from pcabench.gpu import tables
    from pcabench.studies.cylinder import gpu as cylinder_gpu
    from pcabench.studies.high_order import gpu as high_order_gpu
    from solvers import Scene
    from solvers.boundaries.bodies import boundary_method_names

    assert cylinder_gpu.cases(True).scenes == (SCENES["cylinder"],)
    assert all(Scene(**s).body is not None for s in cylinder_gpu.cases(False).scenes + cylinder_gpu.cases(True).scenes)
    from solvers.boundaries.bodies import boundary_method_named

    # every boundary method has a stage: the ghosts' in the body stage, a corrected method's wall (weak) in the
    # high-order stage
    corrected = {s["boundary_method"] for s in high_order_gpu.cases(False).scenes if "boundary_method" in s}
    assert set(cylinder_gpu.cases(False).methods) | corrected == set(boundary_method_names())
    assert all(boundary_method_named(m).needs_correction for m in corrected)
    row = {"scene": "cylinder (rings)", "N": 1376, "precision": "float32", "model": "lagrangian", "dx": 0.125}
    text = tables.markdown(
        {"id": "m"},
        {"budget_s": 1, "elapsed_s": 1, "stages": [], "body": [{**row, "steps": 3, "max_rel_diff_u": 2e-7,
                                                                  "max_rel_diff_drho": 1e-7}]},
    )  # fmt: skip
    assert "## A rigid cylinder" in text and "| cylinder (rings) | 1,376 | float32 | lagrangian | 0.125 | 3 |" in text


def _study_folder(tmp_path, name: str, files: dict):
    """A study folder ``name`` with ``files`` ({file name: text}) on the studies' path: undo with the returned
    function (which also forgets its modules and the registries' finds)."""
    import importlib
    import sys

    import pcabench.studies
    from pcabench.gpu.stage import STAGES
    from pcabench.studies import PRESETS

    root = tmp_path / f"house-{name}"
    (root / name).mkdir(parents=True)
    for file, text in {"__init__.py": '"""A test\'s study."""\n', **files}.items():
        (root / name / file).write_text(text)
    pcabench.studies.__path__.append(str(root))
    importlib.invalidate_caches()
    STAGES.cache_clear()
    PRESETS.cache_clear()

    def undo():
        pcabench.studies.__path__.remove(str(root))
        for module in [m for m in sys.modules if m.startswith(f"pcabench.studies.{name}")]:
            del sys.modules[module]
        STAGES.cache_clear()
        PRESETS.cache_clear()

    return undo


def test_a_study_gpu_stage_that_does_not_load_or_takes_a_taken_name_is_one_failed_stage(tmp_path):
    """The GPU check still runs every other stage (a lent machine's minutes are not lost to one study's typo)."""
    from pcabench.gpu import check as G
    from pcabench.studies.paper.gpu import PAPER_STAGES

    undo = _study_folder(tmp_path, "broken_gpu", {"gpu.py": "import a_module_that_is_not_there\n"})
    try:
        names = [s.name for s in G.stages(PAPER_STAGES)]  # the paper's given stages run all the same
        assert "studies" in names and {"profile", "compare", "sweep", "ncu"} <= set(names)
        (failed,) = [s for s in G.stages() if s.name == "studies"]
        with pytest.raises(RuntimeError, match="a_module_that_is_not_there"):
            failed.work(None)
    finally:
        undo()
    clash = "from pcabench.gpu.stage import Stage\nSTAGE = Stage('sweep', 0, lambda c: True, order=5)\n"
    undo = _study_folder(tmp_path, "clashing_gpu", {"gpu.py": clash})
    try:
        (failed,) = [s for s in G.stages(PAPER_STAGES) if s.name == "studies"]
        with pytest.raises(RuntimeError, match="the check's own name sweep"):
            failed.work(None)
        assert [s.name for s in G.stages(PAPER_STAGES)].count("sweep") == 1
    finally:
        undo()
    assert "studies" not in [s.name for s in G.stages()]


def test_two_built_in_studies_of_one_preset_name_are_refused(tmp_path):
    from pcabench.studies import PRESETS

    plan = "from pcabench.studies.preset import Preset\nP = Preset('quick', lambda: [], 1.0, flag='again')\n"
    undo = _study_folder(tmp_path, "again", {"plan.py": plan})
    try:
        with pytest.raises(ValueError, match="two built-in presets share the name 'quick'"):
            PRESETS.all()
    finally:
        undo()
    assert "quick" in PRESETS


def test_listing_the_gpu_stages_imports_no_gpu_library():
    """A study's gpu.py is imported to list the check's stages on any machine (and by CI's rehearsal): it must
    not import CuPy or numba's CUDA at its top."""
    import subprocess
    import sys

    code = (
        "import sys; from pcabench.gpu.check import stages; from pcabench.studies.paper.gpu import PAPER_STAGES; "
        "stages(PAPER_STAGES); "
        "print([m for m in ('cupy', 'numba.cuda', 'numba_cuda') if m in sys.modules])"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[]", out
