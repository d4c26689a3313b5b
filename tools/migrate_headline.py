"""Bring the committed reference rows older than the headline (``measure``, issue 50) up to what the reader says.

A row stored before a run named its headline measure carries none, and, where its open edges (or a free end) had
let the pulse go before its end, an ``mse`` against the pulse's 1e-60 tail (up to 4.6e28). The reader
(pcabench/reports/frame.py) names the headline such a row's scene kind gives it; the scorer now stores null for
a relative error against a reference that holds no pulse. This script writes both into the rows, so that the
JSONL a user reads with pandas says what `pcabench runs` and the report say:

* every scored row without ``measure``: ``measure`` and ``headline`` as :func:`pcabench.reports.frame.headline_of`
  derives them;
* ``mse`` null where the scene kind's own scorer, given the exact fields themselves, finds no pulse to be
  relative to (its NaN: solvers/reference/analytic.py, QUIET), the headline then read from the other measures.

Nothing else in a row changes; each file is rewritten whole (pcabench.store.safeio). Run from the checkout:

    python tools/migrate_headline.py reports/results

It prints what it changed per file; a second run changes nothing.
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

from pcabench.reports.frame import headline_of
from pcabench.spec import scene_from_row
from pcabench.store.safeio import write_file


def reference_is_quiet(row: dict) -> bool:
    """Whether the scene's scorer finds no pulse in the exact fields at the row's time (its mse of them is NaN)."""
    scene = scene_from_row(row)
    exact = scene.kind.exact_fields(scene, float(row["t_end"]))
    return not math.isfinite(dict(scene.kind.errors(scene, exact))["mse"])


def migrate(row: dict) -> tuple[dict, list[str]]:
    """The row as the reader reads it, and what changed."""
    if "measure" in row or row.get("status") != "ok":
        return row, []
    out, changed = dict(row), []
    mse = row.get("mse")
    if isinstance(mse, (int, float)) and mse > 1 and reference_is_quiet(row):  # the pulse gone by a free end
        out["mse"] = None
        changed.append("mse")
    out["measure"], out["headline"] = headline_of(out)
    changed += ["measure", "headline"]
    return out, changed


def main(folder: str) -> int:
    for path in sorted(Path(folder).glob("*.jsonl")):
        lines, counts = [], {}
        for line in path.read_text().splitlines():
            if not line.strip():
                continue
            row, changed = migrate(json.loads(line))
            for name in changed:
                counts[name] = counts.get(name, 0) + 1
            lines.append(json.dumps(row, sort_keys=True, allow_nan=False))
        if counts:
            write_file(path, ("\n".join(lines) + "\n").encode())
        print(f"{path}: {', '.join(f'{k} in {v} rows' for k, v in counts.items()) or 'nothing to change'}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1] if len(sys.argv) > 1 else "reports/results"))
