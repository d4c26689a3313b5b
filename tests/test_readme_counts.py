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


def test_the_readme_is_a_front_door():
    """At most 300 lines (issue 58): the rest is in docs/, linked from its "More"."""
    assert len((ROOT / "README.md").read_text(encoding="utf-8").splitlines()) <= 300
