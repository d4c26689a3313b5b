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


def claims() -> list:
    out = []
    for doc in DOCUMENTS:
        for m in MARKER.finditer(doc.read_text(encoding="utf-8")):
            out.append(pytest.param(doc, m, id=f"{doc.name}:{m['label'].strip()}={m['figure']}"))
    return out


def significant_digits(figure: str) -> int:
    """How many significant digits ``figure`` states ("3.3e-3": 2; "25,600": 3, its trailing zeros not counted;
    "0.134": 3)."""
    mantissa = re.split("[eE]", figure.replace(",", ""))[0].lstrip("-")
    digits = mantissa.replace(".", "").lstrip("0")
    return len(digits.rstrip("0")) if "." not in mantissa else len(digits)


def test_the_documents_state_claims():
    assert len(claims()) >= 7  # README's and docs' markers: a marker lost in an edit fails here


@pytest.mark.parametrize("doc, marker", claims())
def test_each_claim_is_what_its_command_prints(doc, marker, capsys):
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
