"""What a command prints is what the user asked about (issue 66): a probe's readings on a scene that does not score
them, a study's closing table of its own runs (not another study's), the failure table with the method's
columns."""

from __future__ import annotations

from pcabench import store
from pcabench.execute.sweep import failed_record
from pcabench.reports import frame
from pcabench.spec import RunSpec
from pcabench.studies.paper import failed
from solvers import Scene

from .conftest import cli_main


def test_a_probe_the_scene_does_not_score_is_printed(capsys):
    args = ["run", "--solver", "linkedlist-cpu", "--dx", "1", "--steps", "5", "--probe", "5,0", "--quiet"]
    rc, out, err = cli_main(*args, capsys=capsys)
    assert rc == 0, err
    (line,) = [x for x in out.splitlines() if x.startswith("probe P1")]
    assert "drho at (5, 0) m, 5 samples" in line and "max |drho|" in line, line


def test_a_study_ends_with_a_table_of_its_own_runs(tmp_path, monkeypatch, capsys):
    """Two studies into one store: the second's closing table lists its run, not the first's."""
    monkeypatch.setenv("PCABENCH_HOME", str(tmp_path))
    base = ["study", "--solver", "linkedlist-cpu", "--dx", "1", "--steps", "3", "--results", str(tmp_path / "r")]
    rc, out, err = cli_main(*base, "--scene", "acoustic-pulse", capsys=capsys)
    assert rc == 0, err
    assert "This study's runs" in out and "| acoustic-pulse | 1 | 1,600 |" in out, out
    rc, out, err = cli_main(*base, "--scene", "plane-pulse", capsys=capsys)
    assert rc == 0, err
    assert "acoustic-pulse" not in out and "| linkedlist-cpu float64 | 3 steps" in out, out


def test_the_failure_table_names_each_runs_scene_wall_kernel_h_and_correction(tmp_path):
    scene = Scene(dx=0.04, name="cylinder", kernel="laguerre-gauss", h_factor=1.5, cutoff_factor=4.0, steps=5)
    scene = scene.replace(correction="gradient", boundary_method="rings")
    row = store.to_row(failed_record(RunSpec("linkedlist-cpu", scene).resolved(), "unstable", "blew up", "m"))
    store.append(row, tmp_path / "m.jsonl")
    ctx = type("Ctx", (), {"df": frame.load(tmp_path)})()
    text = "\n".join(failed.text(failed.rows(ctx), ctx))
    header = next(line for line in text.splitlines() if line.startswith("| solver"))
    assert all(f"| {c} |" in header for c in ("scene", "kernel", "h/dx", "correction")), header
    assert "| cylinder (rings wall) |" in text and "| laguerre-gauss | 1.5 | gradient |" in text, text
