"""The results store: append-only, readable after a torn write, mergeable across machines."""

from __future__ import annotations

import pytest

from pcabench import store
from pcabench.execute.run import run
from pcabench.reports.frame import load as load_frame
from pcabench.spec import RunSpec
from solvers import Scene


def test_append_read_merge_and_torn_line(tmp_path):
    rec = run(RunSpec("linkedlist-cpu", Scene(dx=1.0, steps=3)), "machine-a")
    a, b = tmp_path / "a.jsonl", tmp_path / "b.jsonl"
    row = store.append(rec, a)
    store.append(rec, a)  # the same run twice: deduplicated on load
    rec_b = run(RunSpec("linkedlist-cpu", Scene(dx=1.0, steps=3, precision="float32")), "machine-b")
    store.append(rec_b, b)
    with open(a, "a") as f:
        f.write('{"solver": "linkedlist-cpu", "trunc')  # a run killed mid-write
    with pytest.warns(store.StoreWarning, match="a.jsonl:3: not JSON"):  # the torn line is named, then skipped
        df = load_frame([a, b])
    assert len(df) == 2
    assert set(df["profile_id"]) == {"machine-a", "machine-b"}
    assert row["status"] == "ok" and df["t_step"].gt(0).all()
    assert (df["t_snp"] + df["t_pi"] + df["t_su"] > 0).all()
