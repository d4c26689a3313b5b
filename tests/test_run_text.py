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


def test_the_reference_rows_say_what_the_reader_says():
    """Every scored row of the committed reference names its headline measure, as the reader names it, and none
    keeps a relative error against a pulse that has gone (the 4.6e28 of rows older than the headline:
    tools/migrate_headline.py)."""
    import json
    from pathlib import Path

    from pcabench.reports.frame import headline_of

    rows = [
        json.loads(line)
        for path in sorted((Path(__file__).resolve().parents[1] / "reports" / "results").glob("*.jsonl"))
        for line in path.read_text().splitlines()
        if line.strip()
    ]
    scored = [r for r in rows if r["status"] == "ok"]
    assert scored and all("measure" in r for r in scored)
    assert all(r["measure"] == headline_of({k: v for k, v in r.items() if k != "measure"})[0] for r in scored[::50])
    assert max(r["mse"] for r in scored if r.get("mse") is not None) < 1e3


def test_advise_says_how_far_its_search_is(monkeypatch, capsys):
    """The prediction's search (19-81 s for a tight error) prints a line every 2 s (here every 0 s: each method)."""
    from pcabench.predict import search

    monkeypatch.setattr(search, "PROGRESS_S", 0.0)
    methods = search.candidates(
        search.scene_kind("acoustic-pulse"), *search.search_grid(search.scene_kind("acoustic-pulse"))
    )
    monkeypatch.setattr(search, "candidates", lambda *a: methods[:2])
    search.suggest(0.001, 10.0, scene="acoustic-pulse")
    err = capsys.readouterr().err
    assert err.startswith("advise: predicting acoustic-pulse with method 1/2"), err
