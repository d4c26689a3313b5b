"""The command line contract: the stage table, --json, --fields, and clear errors on bad input."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from solvers import Scene, SceneError

from .conftest import cli_main


def pcabench(*args, timeout=600):
    return subprocess.run(
        [sys.executable, "-m", "pcabench.cli", *args], capture_output=True, text=True, timeout=timeout
    )


def test_run_prints_stage_table_and_errors():
    proc = pcabench("run", "--solver", "linkedlist-cpu", "--dx", "1", "--steps", "10")
    assert proc.returncode == 0, proc.stderr
    for word in (
        "input",
        "init",
        "snp",
        "pi",
        "su",
        "output",
        "jit",
        "particles",
        "mean neighbours",
        "MSE",
        "ME",
        "1,000",
    ):
        assert word in proc.stdout


def test_json_is_one_object_with_the_contract(tmp_path):
    fields = tmp_path / "f.npz"
    proc = pcabench(
        "run",
        "--solver",
        "allpair-cpu",
        "--dx",
        "1",
        "--t-end",
        "2",
        "--model",
        "linear",
        "--json",
        "--fields",
        str(fields),
    )
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout)
    for key in (
        "solver",
        "precision",
        "model",
        "integrator",
        "dx",
        "n_particles",
        "steps",
        "t_end",
        "stages",
        "jit_seconds",
        "mse",
        "me",
        "mean_neighbours",
        "status",
        "failed_step",
    ):
        assert key in out
    assert set(out["stages"]) == {"input", "init", "snp", "pi", "su", "output"}
    assert out["n_particles"] == 1000 and out["steps"] == 10 and out["t_end"] == pytest.approx(2.0)
    assert 0 < out["mse"] < 1 and out["status"] == "ok" and out["failed_step"] is None
    f = np.load(fields)
    assert set(f.files) == {"x", "y", "u", "v", "drho", "t"} and f["u"].shape == (1000,)
    assert float(f["t"]) == pytest.approx(2.0)


def test_unstable_run_reports_status_and_step_with_exit_1():
    proc = pcabench(
        "run", "--solver", "linkedlist-cpu", "--dx", "1", "--steps", "300", "--cfl", "12", "--model", "linear", "--json"
    )
    assert proc.returncode == 1
    out = json.loads(proc.stdout)
    assert out["status"] == "unstable" and out["failed_step"] >= 1


@pytest.mark.parametrize(
    "args,words",
    [
        (["--dx", "0"], ["dx", "> 0"]),
        (["--dx", "-1"], ["dx", "> 0"]),
        (["--dx", "nan"], ["--dx", "finite"]),
        (["--dx", "0.00001"], ["dx", "smallest dx that fits"]),
        (["--dx", "1", "--cutoff", "0.5"], ["--cutoff", ">= 1"]),
        (["--dx", "1", "--cfl", "0"], ["--cfl", "[0.001, 50]"]),
        (["--dx", "1", "--steps", "0"], ["--steps", ">= 1"]),
        (["--dx", "1", "--t-end", "-5"], ["--t-end", "> 0"]),
        (["--dx", "0.1", "--strip-height", "0.5"], ["--strip-height", "3 cutoffs"]),
        (["--dx", "1", "--threads", "0"], ["--threads", ">= 1"]),
        (["--dx", "1", "--threads", "100000"], ["--threads", "between 1 and"]),
        (["--dx", "1", "--precision", "float16"], ["precision", "float64"]),
        (["--dx", "1", "--integrator", "leapfrog"], ["integrator", "verlet"]),
        (["--dx", "1", "--model", "eulerian"], ["model", "lagrangian"]),
    ],
)
def test_bad_input_exits_2_with_a_clear_message(args, words, capsys):
    code, out, err = cli_main("run", "--solver", "linkedlist-cpu", *args, capsys=capsys)
    assert code == 2, (out, err)
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    # one prefix, the option as typed (never Scene's parameter name), and the subcommand's help
    assert err.startswith("pcabench run: error: ") and err.rstrip().endswith("(see pcabench run --help)"), err
    assert not any(name in err for name in ("cutoff_factor", "t_end", "strip_height", "h_factor")), err
    for word in words:
        assert word in err, err


def test_unknown_solver_is_refused(capsys):
    code, _, err = cli_main("run", "--solver", "quantum-cpu", "--dx", "1", capsys=capsys)
    assert code == 2 and "solver" in err and "Traceback" not in err


def test_scene_states_particles_and_memory_before_allocating():
    scene = Scene(dx=0.004)
    assert scene.n_particles == 62_500_000
    assert 0 < scene.memory_bytes() < 62_500_000 * 300
    with pytest.raises(SceneError, match="smallest dx that fits"):
        Scene(dx=0.004, memory_limit_bytes=2**30)


def test_paper_particle_counts():
    assert [Scene(dx=d).n_particles for d in (1, 0.1, 0.05, 0.01)] == [1000, 100_000, 400_000, 10_000_000]


def test_exit_codes_are_distinct_and_listed_in_the_help(tmp_path, capsys):
    from pcabench import cli

    empty = tmp_path / "empty"
    empty.mkdir()
    codes = {}
    code, _, err = cli_main("report", "--results", str(empty), "--out", str(tmp_path / "out"), capsys=capsys)
    assert len(err.strip().splitlines()) == 1 and "no results" in err and "Traceback" not in err, err
    codes["no results"] = code
    code, _, err = cli_main("advise", "--error", "0.1", "--results", str(empty), capsys=capsys)
    said = [line for line in err.strip().splitlines() if not line.startswith("advise: predicting")]  # progress
    assert code == codes["no results"] and "no stored runs" in err and len(said) == 1, err
    codes["bad input"] = cli_main("run", "--solver", "linkedlist-cpu", "--dx", "0", capsys=capsys)[0]
    codes["ok"] = cli_main("run", "--solver", "linkedlist-cpu", "--dx", "1", "--steps", "2", "--quiet", capsys=capsys)[
        0
    ]
    codes["run failed"] = cli_main(
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
        "--quiet",
        capsys=capsys,
    )[0]
    assert codes == {"no results": cli.EXIT_NO_RESULTS, "bad input": 2, "ok": 0, "run failed": 1}
    assert len(set(codes.values()) | {cli.EXIT_UNAVAILABLE}) == 5  # one meaning per code
    assert not (tmp_path / "out").exists()  # refused before writing anything
    help_text = cli.build_parser().format_help()
    for code in codes.values():
        assert f"\n  {code} " in help_text, help_text
    assert "no results" in help_text and "the run failed" in help_text


def test_library_code_never_raises_system_exit():
    import pathlib
    import re

    root = pathlib.Path(__file__).resolve().parents[1]
    for package in ("pcabench", "solvers"):
        for path in (root / package).rglob("*.py"):
            if path.name in ("cli.py", "__main__.py"):
                continue
            text = path.read_text()
            assert not re.search(r"raise SystemExit|except[^\n]*SystemExit", text), path


def test_help_describes_the_tool(capsys):
    code, out, _ = cli_main("--help", capsys=capsys)
    assert code == 0 and "Benchmark SPH" in out and "argparse" not in out


def test_accuracy_says_when_the_cfl_is_past_the_stable_one(capsys):
    code, out, _ = cli_main("accuracy", "--dx", "0.1", "--cfl", "10", capsys=capsys)
    assert code == 0 and out.splitlines()[0].startswith("CFL 10 is past the largest stable CFL 4.97"), out
    code, out, _ = cli_main("accuracy", "--dx", "0.1", "--cfl", "10", "--json", capsys=capsys)
    data = json.loads(out, parse_constant=_refuse)
    assert data["past_stable_cfl"] is True and data["stable_cfl"] < 10
    code, out, _ = cli_main("accuracy", "--dx", "0.1", "--cfl", "2", "--json", capsys=capsys)
    assert json.loads(out, parse_constant=_refuse)["past_stable_cfl"] is False
    code, out, _ = cli_main("accuracy", "--dx", "0.1", "--cfl", "2", capsys=capsys)
    assert "past" not in out


def _refuse(name):
    raise ValueError(f"not strict JSON: {name}")


def test_json_is_strict_everywhere(capsys):
    from pcabench import jsonout

    text = jsonout.dumps(
        {
            "a": float("nan"),
            "b": [float("inf"), -float("inf")],
            "c": np.float32(1.5),
            "d": np.int64(3),
            "e": np.bool_(True),
        }
    )
    assert json.loads(text, parse_constant=_refuse) == {"a": None, "b": [None, None], "c": 1.5, "d": 3, "e": True}
    code, out, _ = cli_main("accuracy", "--dx", "0.25", "--integrator", "euler", "--json", capsys=capsys)
    assert json.loads(out, parse_constant=_refuse)["stable_cfl"] == 0
    code, out, _ = cli_main("profile", "--no-gpu", capsys=capsys)
    assert code == 0 and json.loads(out, parse_constant=_refuse)
