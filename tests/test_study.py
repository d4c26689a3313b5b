"""The study: resume after a kill, predicted skips, tables of known values, every figure drawn."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from pcabench import store
from pcabench.reports import frame
from pcabench.reports.build import write_reports
from pcabench.store.record import RunRecord
from pcabench.studies.front.rows import speed_front
from pcabench.studies.paper.rows import (
    accuracy_bars,
    error_series,
    fig9_rows,
    float32_vs_float64,
    simplifications,
    table4,
    table5,
    table6,
)
from pcabench.studies.stability.rows import stability
from solvers import Scene

SWEEP = ["--dx", "1", "0.5", "--solver", "linkedlist-cpu", "allpair-cpu", "--steps", "3", "--no-report"]


def study(results, *args):
    return subprocess.Popen(
        [sys.executable, "-m", "pcabench.cli", "study", *args, "--results", str(results)],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )


def outcome(path):
    """What a sweep found, without its timings: one entry per run."""
    return sorted((r["solver"], r["dx"], r["status"], r["steps"], round(r["mse"], 12)) for r in store.read_rows(path))


def test_killed_sweep_resumes_to_the_same_store(tmp_path):
    whole, killed = tmp_path / "whole", tmp_path / "killed"
    assert study(whole, *SWEEP).wait(timeout=300) == 0
    proc = study(killed, *SWEEP)
    deadline = time.time() + 240
    while time.time() < deadline and proc.poll() is None:
        files = list(killed.glob("*.jsonl"))
        if files and len(store.read_rows(files[0])) >= 1:
            break
        time.sleep(0.05)
    assert proc.poll() is None, "the sweep finished before it could be killed"
    os.killpg(proc.pid, signal.SIGKILL)  # the sweep and its running child, mid-run
    proc.wait()
    path = next(killed.glob("*.jsonl"))
    interrupted = store.read_rows(path)  # readable after the kill
    assert 1 <= len(interrupted) < 4
    assert study(killed, *SWEEP).wait(timeout=300) == 0
    assert outcome(path) == outcome(next(whole.glob("*.jsonl")))
    assert len(outcome(path)) == 4


@pytest.mark.parametrize(
    "args,words",
    [
        (["--dx", "0"], ["dx", "> 0"]),
        (["--dx", "1", "--cfl", "-1"], ["cfl", "[0.001, 50]"]),
        (["--quick", "--run-budget", "0"], ["--run-budget", "> 0"]),
        (["--dx", "1", "--threads", "9999"], ["threads", "between 1 and"]),
        (["--dx", "1", "--solver", "allpair-cpu", "--threads", "2"], ["allpair-cpu is serial"]),
    ],
)
def test_bad_study_input_exits_2_before_any_run(tmp_path, args, words):
    proc = study(tmp_path, *args)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 2 and "Traceback" not in err, err
    assert all(w in err for w in words), err
    assert not list(tmp_path.glob("*.jsonl"))


# ---------------------------------------------------------------- a small fixed results file
def row(
    profile="machine-a",
    solver="linkedlist-cpu",
    threads=1,
    step_ms=(1.0, 4.0, 0.1),
    steps=10,
    mse=0.01,
    status="ok",
    failed_step=None,
    preset="",
    stamp=0,
    message="",
    **scene,
):
    """A stored run with chosen stage times (SNP, PI, SU in ms per step) and error."""
    s = Scene(**scene) if "t_end" in scene else Scene(steps=steps, **scene)
    steps = min(steps, s.n_steps)  # no more than its scene's (the reader checks)
    stages = {
        "input": 0.001,
        "init": 0.002,
        "output": 0.003,
        **{k: v * steps / 1e3 for k, v in zip(("snp", "pi", "su"), step_ms)},
    }
    rec = RunRecord(
        solver=solver,
        precision=s.precision,
        model=s.model,
        integrator=s.integrator,
        dx=s.dx,
        n_particles=s.n_particles,
        steps=steps if status == "ok" else 0,
        t_end=s.t_final,
        stages=stages,
        jit_seconds=1.0,
        mse=mse,
        me=mse / 20,
        mean_neighbours=128.0,
        status=status,
        failed_step=failed_step,
        threads=threads,
        steps_requested=s.n_steps,
        scene=s.as_dict(),
        message=message,
        profile_id=profile,
        commit="abc",
        preset=preset,
        timestamp=f"2026-01-01T00:00:{stamp:02d}+00:00",
    )
    return rec


def fixture_rows():
    rows = []
    # paper scene on machine-a: CPU serial and 2 threads, all-pair, and a GPU at 1,000 and 4,000 particles
    for dx, n_scale in ((1.0, 1), (0.5, 4)):
        rows.append(row(step_ms=(1.0 * n_scale, 4.0 * n_scale, 0.1 * n_scale), dx=dx, steps=10))
        rows.append(row(threads=2, step_ms=(0.5 * n_scale, 2.0 * n_scale, 0.05 * n_scale), dx=dx, steps=10))
        rows.append(row(solver="allpair-cpu", step_ms=(20.0 * n_scale**2, 4.0 * n_scale, 0.1 * n_scale), dx=dx))
        rows.append(row(solver="linkedlist-gpu", precision="float32", step_ms=(0.02, 0.08, 0.01), dx=dx))
    rows.append(row(solver="allpair-cpu", status="skipped", dx=0.25, message="predicted 999 s > run budget"))
    # Fig. 8: linear errors exactly second order; lagrangian stops falling at dx = 0.2
    for dx in (0.4, 0.2, 0.1, 0.05):
        h = Scene.thinnest_strip(dx)
        rows.append(row(model="linear", mse=0.016 * (dx / 0.1) ** 2, dx=dx, t_end=10.0, strip_height=h))
        rows.append(
            row(
                model="linear",
                precision="float32",
                mse=0.016 * (dx / 0.1) ** 2 * (3 if dx == 0.05 else 1),
                dx=dx,
                t_end=10.0,
                strip_height=h,
                step_ms=(0.5, 2.0, 0.05),
            )
        )
        rows.append(
            row(
                model="lagrangian",
                mse={0.4: 0.2, 0.2: 0.05, 0.1: 0.06, 0.05: 0.08}[dx],
                dx=dx,
                t_end=10.0,
                strip_height=h,
                step_ms=(2.0, 4.0, 0.1),
            )
        )
    rows.append(row(model="linear", mse=0.004, dx=0.2, t_end=10.0, step_ms=(10.0, 40.0, 1.0)))  # full domain
    # stability: verlet stable to CFL 4, inaccurate at 5, unstable at 6; euler unstable at once
    for cfl, cls in ((0.2, "ok"), (1.0, "ok"), (4.0, "ok"), (5.0, "inaccurate"), (6.0, "unstable")):
        rows.append(
            row(
                model="linear",
                preset="stability",
                dx=0.25,
                t_end=10.0,
                strip_height=5.0,
                cfl=cfl,
                status="unstable" if cls == "unstable" else "ok",
                failed_step=7 if cls == "unstable" else None,
                mse=0.3 if cls == "inaccurate" else 0.016 * 2.5**2,
            )
        )  # on the linear dx^2 line
    rows.append(
        row(
            model="linear",
            preset="stability",
            dx=0.25,
            t_end=10.0,
            strip_height=5.0,
            cfl=0.2,
            integrator="euler",
            status="unstable",
            failed_step=30,
        )
    )
    # a second machine, merged: a GPU card at 1,000 particles
    rows.append(
        row(profile="machine-b", solver="linkedlist-gpu", precision="float64", step_ms=(0.01, 0.04, 0.005), dx=1.0)
    )
    return rows


@pytest.fixture
def results(tmp_path):
    path = tmp_path / "results"
    for r in fixture_rows():
        store.append(r, path / f"{r.profile_id}.jsonl")
    return path


def test_tables_from_a_fixed_results_file(results):
    df = frame.load(results)
    a = df[df.profile_id == "machine-a"]
    rows4 = table4(a)
    t4 = {(r["config"], r["threads"], r["N"]): r for r in rows4}
    assert t4[("linkedlist-cpu float64", 1, 4000)]["pi"] == pytest.approx(16.0)
    assert t4[("linkedlist-cpu float64", 1, 1000)]["init"] == pytest.approx(2.0)
    assert t4[("linkedlist-cpu float64", 1, 1000)]["protocol"] == "10 steps, full, gather, 1 thread"
    t5 = {(r["config"], r["protocol"], r["N"]): r for r in table5(rows4)}
    assert t5[("linkedlist-cpu float64", "10 steps, full, gather, 2 threads", 1000)]["snp"] == pytest.approx(
        100 * 0.5 / 2.55
    )
    six = {(r["gpu_profile"], r["N"], r["precision"]): r for r in table6(df)}
    assert six[("machine-a", 4000, "float32")]["speedup"] == pytest.approx(4 * 5.1 / 0.11)
    assert six[("machine-a", 4000, "float32")]["speedup_all_cores"] == pytest.approx(4 * 2.55 / 0.11)
    # machine-b has no CPU runs: its row names machine-a's CPU
    assert six[("machine-b", 1000, "float64")]["cpu_profile"] == "machine-a"
    assert six[("machine-b", 1000, "float64")]["speedup"] == pytest.approx(5.1 / 0.055)
    fig9 = {r["N"]: r for r in fig9_rows(a) if r["steps"] == 10}
    assert fig9[4000]["eta"] == pytest.approx((320 + 16 + 0.4) / (4 * 5.1))
    assert fig9[16000]["allpair_status"] == "skipped" and "predicted" in fig9[16000]["allpair_note"]

    series = {(s["model"], s["precision"], s["domain"]): s for s in error_series(a)}
    assert series[("linear", "float64", "strip")]["order"] == pytest.approx(2.0)
    assert series[("lagrangian", "float64", "strip")]["stops_falling"] == pytest.approx(0.2)
    assert {b["verdict"] for b in accuracy_bars(error_series(a))} == {"met"}

    points, limits = stability(a, inaccurate_above=0.15)
    lim = {x["config"].split(",")[0]: x for x in limits}
    # CFL 5 ended bounded but is past verlet's predicted 4.97: unstable by prediction, with its e-foldings
    # the periodic lattice's 4.967, lowered to 4.8 by long runs on the paper's strip (its free ends)
    assert lim["verlet"]["predicted"] == pytest.approx(4.967, abs=1e-3)
    assert lim["verlet"]["stable_cfl"] == 4.8 and lim["verlet"]["limit_from"] == "long runs"
    assert lim["verlet"]["accurate_at"] == [0.2, 1.0, 4.0] and lim["verlet"]["blew_up_at"] == [(6.0, 7)]
    assert [b[0] for b in lim["verlet"]["bounded_past_limit"]] == [5.0]
    assert 0 < lim["verlet"]["bounded_past_limit"][0][2] < 37
    assert lim["euler"]["stable_cfl"] == 0 and lim["euler"]["accurate_at"] == []
    assert lim["euler"]["blew_up_at"] == [(0.2, 30)]

    f32 = {r["model"]: r for r in float32_vs_float64(a)}
    assert f32["linear"]["stops_at"] == pytest.approx(0.05)
    simp = {(r["simplification"][:5], r["dx"]): r for r in simplifications(a)}
    strip = simp[("y-per", 0.2)]
    assert strip["N"] == (25000, 5000) and strip["speedup"] == pytest.approx(0.512 / 0.053)
    assert strip["mse"] == pytest.approx((0.004, 0.064))
    assert simp[("float", 0.1)]["speedup"] == pytest.approx(0.053 / 0.0275)
    _, front = speed_front(a)
    for key in {(p["t_final"], p["model"]) for p in front}:  # slower points on a front are always more accurate
        assert all(np.diff([p["mse"] for p in front if (p["t_final"], p["model"]) == key]) < 0)


def test_every_figure_is_drawn_and_both_machines_are_reported(results, tmp_path):
    import matplotlib.image as mpimg

    out = tmp_path / "reports"
    write_reports(results, out)
    expected = [
        f"machine-a/{name}.png"
        for name in (
            "fig8_error_vs_dx",
            "fig9_allpair_vs_linkedlist",
            "fig10_runtime_vs_N",
            "fig11_step_shares",
            "fig13_task_shares",
            "fig14_speedup_vs_N",
            "speed_vs_accuracy",
            "stability_map",
        )
    ]
    expected += ["fig14_speedup_vs_N.png", "cards_step_vs_N.png"]
    # machine-b ran one size: no line against N to draw (figures.FIG10_SIZES), so no Fig. 10 of one dot
    assert not (out / "machine-b" / "fig10_runtime_vs_N.png").exists()
    for name in expected:
        image = mpimg.imread(out / name)
        assert image.shape[0] > 100 and image.shape[1] > 100 and image.std() > 0, name
    a = (out / "machine-a" / "report.md").read_text()
    for words in (
        "Table 4",
        "Table 5",
        "Table 6",
        "Fig. 9",
        "Fig. 8",
        "fitted order 2.00",
        "stops falling at dx = 0.2",
        "Time to a given accuracy",
        "paper / fastest",
        "cost of each simplification",
        "stable CFL (predicted, or long runs where lower)",
        "unstable by prediction",
        "skipped",
    ):
        assert words in a, words
    cards = (out / "cards.md").read_text()
    assert "machine-b" in cards and "Tesla K20c" in cards and "Quadro M4000" in cards
    assert "machine-b" in (out / "README.md").read_text()
    _figures_sit_in_their_sections_with_their_data(out / "machine-a")


def _figures_sit_in_their_sections_with_their_data(folder):
    """Issue 58: a contents list of the sections, each figure under the section that drew it (no pile at the
    end), and each figure's data beside it as a CSV whose points are the ones drawn."""
    import re

    import pandas as pd

    from pcabench.reports.build import anchor

    text = (folder / "report.md").read_text()
    headings = re.findall(r"^## (.+)$", text, flags=re.M)
    assert "Figures" not in headings and len(headings) > 3
    for title in headings:
        assert f"- [{title}](#{anchor(title)})" in text  # the contents list links every section
    sections = re.split(r"^## ", text, flags=re.M)
    for png in folder.glob("*.png"):
        (home,) = [s for s in sections if f"]({png.name})" in s]  # in exactly one section
        assert home.split("\n", 1)[0] in headings
        data = pd.read_csv(png.with_suffix(".csv"))
        assert f"[{png.stem}.csv]({png.stem}.csv)" in home and len(data) > 0, png.name
        assert data[["x", "y"]].notna().all(axis=1).any() and set(data.kind) <= {"line", "points", "bar", "image"}
    fig8 = pd.read_csv(folder / "fig8_error_vs_dx.csv")  # its measured points: the runs' dx and errors
    assert {0.2, 0.1}.issubset(set(fig8.x.round(6)))


def test_a_run_predicted_past_the_budget_is_skipped_not_run(tmp_path):
    from pcabench.execute.sweep import sweep
    from pcabench.machine.profiles import machine_id
    from pcabench.spec import RunSpec
    from pcabench.store.provenance import host_id

    path = tmp_path / "s.jsonl"
    for dx, ms in ((1.0, 10.0), (0.5, 160.0)):  # all-pair: 16x per 4x particles, on this host
        rec = row(profile=machine_id(), solver="allpair-cpu", step_ms=(ms, 0, 0), dx=dx, steps=10)
        rec.host = host_id()
        store.append(rec, path)
    spec = RunSpec("allpair-cpu", Scene(dx=0.125, steps=10))
    t0 = time.perf_counter()
    sweep([spec], path, run_budget=60.0, sweep_budget=600.0)
    assert time.perf_counter() - t0 < 10  # no child process ran the 64K all-pair
    last = store.read_rows(path)[-1]
    assert last["status"] == "skipped" and last["n_particles"] == 64000
    assert "predicted" in last["message"] and "N^2.00" in last["message"]


def test_a_run_cut_by_the_sweep_budget_is_not_stored(tmp_path):
    from pcabench.execute.sweep import sweep
    from pcabench.spec import RunSpec

    path = tmp_path / "s.jsonl"
    spec = RunSpec("linkedlist-cpu", Scene(dx=0.5, steps=20000, model="linear"))
    sweep([spec], path, run_budget=600.0, sweep_budget=0.5)  # 20,000 steps (seconds) do not fit in 0.5 s
    assert not path.exists() or store.read_rows(path) == []  # a rerun must run it, not find a false timeout
