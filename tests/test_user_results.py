"""What a new user meets in the first hour: their own store, honest comparisons, progress, output paths,
a CLI that agrees with the README, and a table of stored runs."""

from __future__ import annotations

import io
import json
import subprocess
from pathlib import Path

import pytest

from pcabench import __version__, cli, paths, store
from pcabench.execute.sweep import sweep
from pcabench.reports.frame import load as load_frame
from pcabench.spec import RunSpec
from pcabench.store import runs
from solvers import Scene

from .conftest import cli_main
from .test_study import fixture_rows, row


# ---------------------------------------------------------------- a user's runs are their own
def test_a_users_runs_go_to_an_ignored_folder_never_to_tracked_files(monkeypatch):
    monkeypatch.delenv("PCABENCH_HOME", raising=False)
    root = paths.checkout()
    assert root is not None and paths.user_results().is_relative_to(root)
    assert paths.user_results() != paths.reference_results()
    target = paths.user_results().relative_to(root) / "machine--host.jsonl"
    ignored = subprocess.run(["git", "check-ignore", "-q", str(target)], cwd=root)
    assert ignored.returncode == 0, f"{target} is not ignored by git"
    monkeypatch.setenv("PCABENCH_HOME", "/tmp/elsewhere")
    assert str(paths.user_results()).startswith("/tmp/elsewhere")


def test_two_hosts_of_one_profile_get_two_stores_and_two_reports(tmp_path):
    assert store.store_name("amd-epyc", "h1") != store.store_name("amd-epyc", "h2")
    results = tmp_path / "results"
    for host in ("h1", "h2"):
        for r in fixture_rows()[:4]:
            r.host = host
            r.run_id = f"{host}-{r.run_id}"
            store.append(r, results / store.store_name(r.profile_id, host))
    from pcabench.reports.build import write_reports

    write_reports(results, tmp_path / "out")
    assert (tmp_path / "out" / "machine-a--h1" / "report.md").exists()
    assert (tmp_path / "out" / "machine-a--h2" / "report.md").exists()
    assert "host h2" in (tmp_path / "out" / "machine-a--h2" / "report.md").read_text()


# ---------------------------------------------------------------- honest comparisons
@pytest.fixture
def reports(tmp_path):
    results = tmp_path / "results"
    for r in fixture_rows():
        store.append(r, results / f"{r.profile_id}.jsonl")
    from pcabench.reports.build import write_reports

    write_reports(results, tmp_path / "out")
    return tmp_path / "out"


def test_table4_sets_cpu_beside_the_papers_cpu_and_gpu_beside_its_gpu(reports):
    text = (reports / "machine-a" / "report.md").read_text()
    table4 = text.split("## Table 4")[1].split("## Table 5")[0]
    for line in table4.splitlines():
        if line.startswith("| linkedlist-cpu") or line.startswith("| allpair-cpu"):
            assert "K20c" not in line, line
        if line.startswith("| linkedlist-gpu") and "1,000" not in line:
            assert "CPU step" not in line, line


def test_cross_machine_speedups_stand_apart_from_same_machine_ones(reports):
    b = (reports / "machine-b" / "report.md").read_text()
    table6 = b.split("## Table 6")[1].split("\n## ")[0]
    same, _, across = table6.partition("### Across machines")
    assert "machine-a" not in same  # no same-machine row borrows another CPU
    assert "machine-a" in across
    cards = (reports / "cards.md").read_text()
    measured, _, rest = cards.partition("Across machines")
    assert "| machine-b |" not in measured.split("Published")[0]


# ---------------------------------------------------------------- progress and output paths
def test_a_sweep_shows_the_run_in_progress_its_size_and_a_qualified_eta(tmp_path):
    stream = io.StringIO()
    specs = [RunSpec("linkedlist-cpu", Scene(dx=dx, steps=3)) for dx in (1.0, 0.5)]
    sweep(specs, tmp_path / "s.jsonl", run_budget=300, sweep_budget=600, stream=stream)
    text = stream.getvalue()
    assert "[1/2] linkedlist-cpu [list] dx=1 N=1,000 steps=3: running" in text
    assert "N=4,000" in text and "sweep: 2/2 done" in text
    assert "eta" in text and "predicted from this host's timings" in text


def test_a_bad_fields_path_is_refused_before_the_run(tmp_path, capsys):
    code, out, err = cli_main(
        "run",
        "--solver",
        "linkedlist-cpu",
        "--dx",
        "1",
        "--fields",
        str(tmp_path / "no" / "such" / "f.npz"),
        capsys=capsys,
    )
    assert code == 2 and "--fields" in err and "Traceback" not in err and "stage" not in out


def test_json_is_standard_json_null_never_nan(capsys):
    code, out, _ = cli_main(
        "run",
        "--solver",
        "linkedlist-cpu",
        "--dx",
        "1",
        "--steps",
        "300",
        "--cfl",
        "12",
        "--model",
        "linear",
        "--json",
        "--quiet",
        capsys=capsys,
    )

    def refuse(name):
        raise ValueError(f"non-standard JSON constant {name}")

    row = json.loads(out, parse_constant=refuse)
    assert code == 1 and row["status"] == "unstable" and row["mse"] is None


# ---------------------------------------------------------------- the CLI agrees with the README
def test_study_lists_take_several_values_as_documented():
    parser = cli.build_parser()
    args = parser.parse_args(["study", "--dx", "1", "0.5", "--steps", "5", "10", "--threads", "1", "all"])
    name, specs = cli.study_specs(args)
    assert name == "matrix" and len(specs) == 2 * 2 * 2
    assert {s.scene.steps for s in specs} == {5, 10} and {s.threads for s in specs} == {1, "all"}


def test_usage_errors_are_one_line_and_version_is_there(capsys):
    code, _, err = cli_main("run", "--solver", "linkedlist-cpu", "--dx", capsys=capsys)
    assert code == 2 and len(err.strip().splitlines()) == 1 and "--dx" in err
    code, out, _ = cli_main("--version", capsys=capsys)
    assert code == 0 and __version__ in out
    code, out, _ = cli_main("run", "--help", capsys=capsys)
    for word in ("allpair-cpu", "lagrangian", "fixed", "linear", "verlet", "kdk1", "euler", "rk2", "gather"):
        assert word in out, word


# ---------------------------------------------------------------- stored runs as a table
def test_runs_lists_filters_and_compares(tmp_path):
    results = tmp_path / "results"
    for r in fixture_rows():
        store.append(r, results / f"{r.profile_id}.jsonl")
    df = load_frame(results)
    gpu = runs.table(df, solver="linkedlist-gpu", machine="machine-a")
    assert set(gpu.solver) == {"linkedlist-gpu"} and set(gpu.machine) == {"machine-a"} and len(gpu) == 2
    both = runs.compare(df, "machine-a", "machine-b")
    row = both[(both.solver == "linkedlist-gpu") & (both.N == 1000)]
    assert len(row) == 0  # machine-a's GPU ran float32, machine-b's float64: not the same configuration
    with pytest.raises(KeyError, match="neither a machine nor a commit"):
        runs.compare(df, "machine-a", "nowhere")
    with pytest.raises(KeyError, match="a machine and 'abc' a commit"):  # not like with like: refused
        runs.compare(df, "machine-a", "abc")


def test_runs_shows_a_skipped_run_as_skipped_with_its_reason_and_no_numbers(tmp_path, capsys):
    results = tmp_path / "results"
    for r in fixture_rows():  # holds one skipped run: "predicted 999 s > run budget"
        store.append(r, results / f"{r.profile_id}.jsonl")
    code, out, err = cli_main("runs", "--results", str(results), "--status", "skipped", capsys=capsys)
    header, *lines = out.strip().splitlines()
    assert code == 0 and len(lines) == 1, out + err
    cells = dict(zip(header.split(), lines[0].split(maxsplit=len(header.split()) - 1)))
    assert cells["status"] == "skipped" and cells["note"] == "predicted 999 s > run budget", cells
    assert cells["steps"] == cells["step_ms"] == cells["error"] == cells["measure"] == "-", cells  # not 0 steps
    code, out, _ = cli_main("runs", "--results", str(results), "--status", "ok", capsys=capsys)
    assert code == 0 and "-  ok" not in out and "<NA>" not in out


def test_runs_compare_takes_a_machine_prefix_and_prints_no_index(tmp_path, capsys):
    results = tmp_path / "results"
    for profile, ms in (("amd-epyc", 1.0), ("h100-80gb", 0.5), ("h200-141gb", 0.25)):
        for dx in (1.0, 0.5):
            r = row(profile=profile, step_ms=(ms, ms, ms), dx=dx)
            store.append(r, results / f"{profile}.jsonl")
    code, out, err = cli_main("runs", "--results", str(results), "--compare", "amd", "h", capsys=capsys)
    assert code == 2 and "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    assert "--compare" in err and "h100-80gb" in err and "h200-141gb" in err, err  # "h": which one?
    code, out, err = cli_main("runs", "--results", str(results), "--compare", "amd", "h1", capsys=capsys)
    header, *lines = out.strip().splitlines()
    assert code == 0 and len(lines) == 2, out + err
    assert header.split()[0] == "solver" and all(line.split()[0] == "linkedlist-cpu" for line in lines), out
    assert "step_ms amd-epyc" in header and "step_ms h100-80gb" in header, header
    assert [float(line.split()[-4]) for line in lines] == [0.5, 0.5], out  # b / a
    code, out, err = cli_main("runs", "--results", str(results), "--machine", "h", capsys=capsys)
    assert code == 0 and {line.split()[0] for line in out.strip().splitlines()[1:]} == {"h100-80gb", "h200-141gb"}
    code, _, err = cli_main("runs", "--results", str(results), "--compare", "amd", "nowhere", capsys=capsys)
    assert code == 2 and len(err.strip().splitlines()) == 1 and "'nowhere'" in err, err


# ---------------------------------------------------------------- asv's smoke run
def test_asv_smoke_config_writes_only_to_ignored_scratch_and_selects_few_benchmarks(tmp_path):
    asv_util = pytest.importorskip("asv.util")
    import importlib.util

    from pcabench.machine import asv

    root = Path(__file__).resolve().parents[1]
    if not (root / ".git").exists():
        pytest.skip("not a git checkout")
    spec = importlib.util.spec_from_file_location("asv_smoke", root / "benchmarks" / "ci" / "asv_smoke.py")
    asv_smoke = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(asv_smoke)  # a script in benchmarks/ci/, not a module of the asv suite
    assert asv_smoke.ROOT == root
    config = asv.scratch_config(asv.SCRATCH, root, name="pytest")
    try:
        conf = asv_util.load_json(str(config), js_comments=True)
        git = ["git", "-C", str(root)]
        ignored = subprocess.run(
            [*git, "check-ignore", "--no-index", str(config), conf["results_dir"]], capture_output=True, text=True
        ).stdout.split()
        assert ignored == [str(config), conf["results_dir"]], ignored  # both git-ignored
        tracked = subprocess.run([*git, "ls-files", "--", conf["results_dir"]], capture_output=True, text=True)
        assert tracked.stdout == "" and not conf["results_dir"].startswith(str(root / "reports"))
        assert {k: v for k, v in conf.items() if k != "results_dir"} == {
            k: v
            for k, v in asv_util.load_json(str(root / "asv.conf.json"), js_comments=True).items()
            if k != "results_dir"
        }
    finally:
        config.unlink()
    # each pattern picks a few parameter sets of the committed suite's benchmarks, as asv matches them
    import itertools
    import re

    suite = json.loads((root / "reports/asv/results/benchmarks.json").read_text())
    names = [
        f"{name}({', '.join(p)})"
        for name, b in suite.items()
        if isinstance(b, dict)
        for p in itertools.product(*b["params"])
    ]
    picked = [[n for n in names if re.search(pattern, n)] for pattern in asv_smoke.SELECTION]
    assert all(picked) and sum(map(len, picked)) <= 6, picked
    assert asv_smoke.main(["--results", str(root / "reports/asv/results")]) == 2


def test_asv_imports_its_suite_and_never_the_ci_folder(monkeypatch):
    """asv imports every module of the benchmarks package (asv_runner's discovery, an import error fatal): the
    asv suite's modules, and not benchmarks/ci/ (pytest-benchmark's suite and CI's scripts, no package)."""
    discovery = pytest.importorskip("asv_runner.discovery")
    root = Path(__file__).resolve().parents[1]
    monkeypatch.syspath_prepend(str(root))
    names = [m.__name__ for m in discovery.disc_modules("benchmarks")]
    assert "benchmarks.bench_step" in names and "benchmarks.common" in names
    assert not [n for n in names if n.startswith("benchmarks.ci")], names
    assert (root / "benchmarks" / "ci" / "test_stages.py").exists()  # there, and not imported
