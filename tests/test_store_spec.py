"""Issue 39: one writer, one reader, one spec. Each test is a break found by a hostile probe of the store, the
children, the files and the printed commands, failing before the mechanism it names was mended."""

from __future__ import annotations

import json
import warnings

from pcabench import store
from pcabench.record import RunRecord
from pcabench.spec import RunSpec
from solvers import Scene

from .conftest import cli_main


def advisable(**kw) -> RunRecord:
    """A finished run of the 2D pulse advise can use (t_end 10 s, linear), on machine m, host h."""
    spec = RunSpec("linkedlist-cpu", Scene(dx=1.0, t_end=10.0, model="linear")).resolved()
    rec = RunRecord.from_spec(spec, "m", status="ok")
    rec.steps, rec.mse, rec.me, rec.host = spec.scene.n_steps, 0.1, 0.001, "h"
    rec.stages.update(snp=0.001, pi=0.01, su=0.0005)
    for k, v in kw.items():
        setattr(rec, k, v)
    return rec


# ---------------------------------------------------------------- 1. reading: one typed record
def test_an_unknown_key_beside_a_missing_stage_breaks_no_reader(tmp_path, capsys):
    results = tmp_path / "results"
    path = results / "m--h.jsonl"
    good = store.append(advisable(), path)
    odd = dict(good, run_id="odd1", t_init="soon", t_step="x", machine="forged", scene_key=3)
    torn_stage = dict(good, run_id="odd2", t_init="soon")
    torn_stage["stages"] = {k: v for k, v in good["stages"].items() if k != "init"}
    with open(path, "a") as f:
        for row in (odd, torn_stage):
            f.write(json.dumps(row) + "\n")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rows = store.read_rows(results)
    assert sorted(r["run_id"] for r in rows) == sorted([good["run_id"], "odd1"])  # the unknown keys, dropped
    assert all("t_init" not in r and "machine" not in r for r in rows)
    assert [str(w.message) for w in caught if "stages lack init" in str(w.message)] == [
        next(str(w.message) for w in caught if f"{path}:3:" in str(w.message))
    ]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", store.StoreWarning)
        code, out, err = cli_main("runs", "--results", str(results), capsys=capsys)
        assert code == 0 and len(out.splitlines()) == 3 and "Traceback" not in err, (out, err)
        code, out, err = cli_main("report", "--results", str(results), "--out", str(tmp_path / "out"), capsys=capsys)
        assert code == 0 and "Traceback" not in err, err
        code, out, err = cli_main(
            "advise", "--results", str(results), "--error", "0.5", "--machine", "m", capsys=capsys
        )
        assert code == 0 and "pcabench run --solver linkedlist-cpu" in out, (out, err)


def test_one_run_id_with_two_records_warns_naming_both_and_the_later_write_wins(tmp_path):
    results = tmp_path / "results"
    real = store.append(advisable(timestamp="2026-12-01T10:00:00+00:00"), results / "m--h.jsonl")
    forged = dict(real, mse=1e-12, timestamp="2026-11-01T10:00:00+00:00")  # read first, written earlier
    (results / "a--h.jsonl").write_text(json.dumps(forged) + "\n")
    copy = results / "z--h.jsonl"
    copy.write_text(json.dumps(real) + "\n")  # the same record copied into another store: one run, no warning
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rows = store.read_rows(results)
    assert [r["mse"] for r in rows] == [real["mse"]]
    (message,) = [str(w.message) for w in caught]
    assert f"{results / 'a--h.jsonl'}:1" in message and f"{results / 'm--h.jsonl'}:1" in message
    assert "later write" in message and str(copy) not in message
    # at equal timestamps the later line wins: the order of appends
    again = dict(real, mse=0.2)
    with open(results / "m--h.jsonl", "a") as f:
        f.write(json.dumps(again) + "\n")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", store.StoreWarning)
        assert [r["mse"] for r in store.read_rows(results / "m--h.jsonl")] == [0.2]
