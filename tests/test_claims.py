"""The README's and docs' figures come out of their own commands (issue 59).

A figure the text states beside the command that makes it carries a marker right after it:

    <!-- claim: pcabench COMMAND :: LABEL = FIGURE -->

The test runs COMMAND (each takes under a minute), reads the first number printed after LABEL and checks that
it rounds to FIGURE at FIGURE's own significant digits, and that FIGURE is what the text around the marker
states. A claim whose command changed its answer, or whose text drifted from the marker, fails here.
"""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest

from .conftest import cli_main

ROOT = Path(__file__).resolve().parents[1]
DOCUMENTS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]
MARKER = re.compile(r"<!-- claim: (?P<command>pcabench .+?) :: (?P<label>.+?) = (?P<figure>\S+) -->")
NUMBER = re.compile(r"-?\d[\d,]*(?:\.\d+)?(?:e[-+]?\d+)?", re.IGNORECASE)


# the machine ids a claim that reads stored runs is checked under, besides this host's own: a new host with no
# rows, a reference machine whose rows do not answer every question (issue 66: the claims held only on the
# host whose machine id the answering rows carried), and one whose rows answer differently (intel-xeon: on such
# a host three claims of amd-epyc's runs failed until they named their machine, 2026-12-08)
OTHER_HOSTS = ("fresh-host-1", "amd-epyc", "intel-xeon")


def reads_stored_runs(command: str) -> bool:
    """Whether the claim's command answers from stored runs, by this host's machine unless it names one."""
    words = shlex.split(command)
    return words[1] == "advise" and "--machine" not in words


def claims() -> list:
    out = []
    for doc in DOCUMENTS:
        for m in MARKER.finditer(doc.read_text(encoding="utf-8")):
            name = f"{doc.name}:{m['label'].strip()}={m['figure']}"
            out.append(pytest.param(doc, m, None, id=name))
            if reads_stored_runs(m["command"]):
                out += [pytest.param(doc, m, host, id=f"{name}@{host}") for host in OTHER_HOSTS]
    return out


def significant_digits(figure: str) -> int:
    """How many significant digits ``figure`` states ("3.3e-3": 2; "25,600": 3, its trailing zeros not counted;
    "0.134": 3)."""
    mantissa = re.split("[eE]", figure.replace(",", ""))[0].lstrip("-")
    digits = mantissa.replace(".", "").lstrip("0")
    return len(digits.rstrip("0")) if "." not in mantissa else len(digits)


def test_the_documents_state_claims():
    assert len(claims()) >= 7  # README's and docs' markers: a marker lost in an edit fails here


@pytest.fixture
def host(request, monkeypatch):
    """The machine id the claim runs under (None: this host's own)."""
    from pcabench.machine import profiles

    if request.param is not None:
        monkeypatch.setenv(profiles.MACHINE_ID_ENV, request.param)
    profiles.machine_id.cache_clear()
    yield request.param
    profiles.machine_id.cache_clear()


@pytest.mark.parametrize("doc, marker, host", claims(), indirect=["host"])
def test_each_claim_is_what_its_command_prints(doc, marker, host, capsys):
    text = MARKER.sub("", doc.read_text(encoding="utf-8"))  # the prose without the markers
    prose = MARKER.sub("", doc.read_text(encoding="utf-8")[: marker.start()]).rstrip()
    paragraph = prose[prose.rfind("\n\n") :]  # the paragraph (or table) the marker follows
    figure = marker["figure"]
    assert figure in paragraph, f"{doc.name}: the text before the marker does not state {figure}"
    assert figure in text
    words = shlex.split(marker["command"])[1:]
    rc, out, err = cli_main(*words, capsys=capsys)
    assert rc == 0, err
    label = marker["label"].strip()
    at = out.find(label)
    assert at >= 0, f"{label!r} not printed by {marker['command']}:\n{out}"
    printed = NUMBER.search(out, at + len(label))
    assert printed, out[at : at + 200]
    value, stated = float(printed.group().replace(",", "")), float(figure.replace(",", ""))
    digits = significant_digits(figure)
    assert float(f"{value:.{digits}g}") == pytest.approx(stated, rel=1e-12), (printed.group(), figure, out[at:][:200])
