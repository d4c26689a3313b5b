"""One machine, one id: on a GPU machine the store's name, every record (CPU runs too), resume, the report
folder and Table 6's same-machine test all use :func:`pcabench.machine.profiles.machine_id`, GPU included.

The GPU is faked (``PCABENCH_FAKE_GPU``) in this process and, through the environment, in every child.
"""

from __future__ import annotations

import subprocess
import sys

import pytest

from benchmarks.common import gpu_available
from pcabench import cli, store
from pcabench.execute.sweep import run_child
from pcabench.machine import profiles
from pcabench.reports.build import write_reports
from pcabench.reports.frame import load as load_frame
from pcabench.spec import RunSpec
from pcabench.store.provenance import git_commit
from pcabench.studies.paper.rows import table6
from solvers import Scene

from .conftest import cli_main

FAKE = "Fake GPU X1"
STUDY = ("study", "--solver", "linkedlist-cpu", "--dx", "1", "--steps", "2")


@pytest.fixture(scope="module")
def machine(tmp_path_factory):
    """A study on a machine with a faked GPU: (its expected id, results folder, reports folder)."""
    tmp = tmp_path_factory.mktemp("machine")
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("PCABENCH_HOME", str(tmp / "home"))
        mp.delenv(profiles.MACHINE_ID_ENV, raising=False)
        mp.delenv(profiles.FAKE_GPU_ENV, raising=False)
        profiles.machine_id.cache_clear()
        cpu_only = profiles.machine_id()
        mp.setenv(profiles.FAKE_GPU_ENV, FAKE)
        profiles.machine_id.cache_clear()
        results, reports = tmp / "results", tmp / "reports"
        assert cli.main([*STUDY, "--results", str(results), "--reports", str(reports)]) == 0
        yield f"fake-gpu-x1__{cpu_only}", results, reports
    profiles.machine_id.cache_clear()


def test_the_fake_gpu_names_the_machine(machine):
    mid, _, _ = machine
    assert profiles.gpu_info()["name"] == FAKE
    assert profiles.machine_id() == profiles.capture()["id"] == mid


def test_without_the_hook_no_gpu_is_faked(monkeypatch):
    monkeypatch.delenv(profiles.FAKE_GPU_ENV, raising=False)
    assert (profiles.gpu_info() or {}).get("name") != FAKE


def test_a_faked_gpu_runs_no_gpu_solver(machine, capsys):
    if gpu_available():
        pytest.skip("a real GPU is here")
    code, _, err = cli_main("run", "--solver", "linkedlist-gpu", "--dx", "1", "--steps", "2", capsys=capsys)
    assert code == 3, err


def test_the_store_and_every_record_in_it_carry_the_gpu_machines_id(machine):
    mid, results, _ = machine
    assert [p.name for p in results.glob("*.jsonl")] == [store.store_name(mid)]
    rows = store.read_rows(results / store.store_name(mid))
    assert [(r["solver"], r["status"], r["profile_id"]) for r in rows] == [("linkedlist-cpu", "ok", mid)]


def test_a_child_records_its_parents_id_not_its_own(machine):
    spec = RunSpec("linkedlist-cpu", Scene(dx=1.0, steps=2)).resolved()
    row = run_child(spec, 300, git_commit(), "given-by-the-parent", stream=None)
    assert row["status"] == "ok" and row["profile_id"] == "given-by-the-parent"


def test_the_same_study_again_stores_nothing_new(machine):
    mid, results, _ = machine
    again = subprocess.run(
        [sys.executable, "-m", "pcabench.cli", *STUDY, "--results", str(results), "--no-report"],
        capture_output=True,
        text=True,
        timeout=300,
    )  # a new process: the id computed anew
    assert again.returncode == 0 and "already stored" in again.stderr, again.stderr
    assert len(store.read_rows(results / store.store_name(mid))) == 1


def test_the_report_folder_is_named_for_the_gpu_machine(machine):
    mid, _, reports = machine
    assert (reports / mid / "report.md").is_file()


def test_table6_finds_a_gpu_and_the_cpu_of_its_own_host(machine, tmp_path):
    mid, results, _ = machine
    path = results / store.store_name(mid)
    cpu = store.read_rows(path)[0]
    gpu = dict(
        cpu,
        solver="linkedlist-gpu",
        device="gpu",
        pair_loop="gather",
        stages={k: v / 10 for k, v in cpu["stages"].items()},
        run_id="a-gpu-run-on-this-machine",
    )  # as a GPU sweep here would store it
    merged = tmp_path / "results"
    store.append(cpu, merged / path.name)
    store.append(gpu, merged / path.name)
    [row] = table6(load_frame(merged))
    assert (row["gpu_profile"], row["cpu_profile"], row["same_machine"]) == (mid, mid, True)
    assert row["speedup"] == pytest.approx(10)
    write_reports(merged, tmp_path / "reports")
    cards = (tmp_path / "reports" / "cards.md").read_text()
    same = cards.split("Measured, each GPU against its own host's CPU")[1].split("Published")[0]
    assert f"| {mid} |" in same and "Across machines" not in same
    assert f"| {FAKE} |" in cards.split("## GPU cards")[1]  # the card named from the machine's stored profile
