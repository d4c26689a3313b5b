"""The README's run counts come from the plans: each `pcabench study ... # ... N runs` line it shows is listed
(`--list`, nothing run) and has that many runs (issue 58: counts that drifted from the code)."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest

from .conftest import cli_main

ROOT = Path(__file__).resolve().parents[1]
LINE = re.compile(r"^pcabench study (?P<args>[^#]+?)\s+#.*?(?P<n>\d[\d,]*) runs", re.M)
CLAIMS = [(m["args"], int(m["n"].replace(",", ""))) for m in LINE.finditer((ROOT / "README.md").read_text())]


def test_the_readme_states_run_counts():
    assert len(CLAIMS) >= 5, CLAIMS


@pytest.mark.parametrize("args, runs", CLAIMS, ids=[a for a, _ in CLAIMS])
def test_each_run_count_the_readme_states_is_its_plans(args, runs, capsys):
    code, out, err = cli_main("study", *shlex.split(args), "--list", capsys=capsys)
    listed = re.findall(r"^\[(\d+)/(\d+)\]", out + err, re.M)
    assert code == 0 and listed, (out + err)[-500:]
    assert int(listed[-1][1]) == runs, f"`pcabench study {args}` lists {listed[-1][1]} runs; the README says {runs}"


# In the docs: "`pcabench study ARGS` (N runs" or "`--flag`, N runs": a count the code must still give, unless the
# text dates it ("`pcabench study --walls` at 584cdb9, 64 runs": what was run then, a measurement's record).
DOCS = ("docs/accuracy.md", "docs/performance.md", "docs/status.md", "docs/gpu.md", "docs/store.md", "CONTRIBUTING.md")
DOC_COUNT = re.compile(r"`(?:pcabench study )?(?P<args>--[^`]+)`(?P<mid>[^`]{0,40}?)(?P<n>\d[\d,]*) runs")
DATED = re.compile(r"\bat\s+(commit\s+)?[0-9a-f]{7}\b")
DOC_CLAIMS = [
    (f"{name}:{text[: m.start()].count(chr(10)) + 1}", m["args"], int(m["n"].replace(",", "")))
    for name in DOCS
    for text in [(ROOT / name).read_text(encoding="utf-8")]
    for m in DOC_COUNT.finditer(text)
    if not DATED.search(m["mid"])
]


def test_a_dated_count_is_left_as_measured_and_an_undated_one_is_checked():
    text = "`pcabench study --walls` at 584cdb9, 64 runs; `pcabench study --open` (113 runs"
    found = [(m["args"], bool(DATED.search(m["mid"]))) for m in DOC_COUNT.finditer(text)]
    assert found == [("--walls", True), ("--open", False)]
    assert len(DOC_CLAIMS) >= 3, DOC_CLAIMS


@pytest.mark.parametrize("where, args, runs", DOC_CLAIMS, ids=[w for w, _, _ in DOC_CLAIMS])
def test_each_undated_run_count_the_docs_state_is_its_plans(where, args, runs, capsys):
    code, out, err = cli_main("study", *shlex.split(args), "--list", capsys=capsys)
    listed = re.findall(r"^\[(\d+)/(\d+)\]", out + err, re.M)
    assert code == 0 and listed, (out + err)[-500:]
    assert int(listed[-1][1]) == runs, f"{where}: `pcabench study {args}` lists {listed[-1][1]} runs, not {runs}"


def test_the_readme_is_a_front_door():
    """At most 300 lines (issue 58): the rest is in docs/, linked from its "More"."""
    assert len((ROOT / "README.md").read_text(encoding="utf-8").splitlines()) <= 300
