"""float32 against float64 at the paper's protocol."""

from __future__ import annotations

from pcabench.reports.section import Section
from pcabench.studies.paper.rows import float32_vs_float64


def text(rows, ctx) -> list[str]:
    if not rows:
        return []
    lines = ["## float32 against float64", ""]
    for r in rows:
        pairs = "; ".join(f"dx {d:g}: {e64:.3g} / {e32:.3g}" for d, e64, e32 in r["pairs"])
        verdict = (
            f"float32 departs from float64 by more than {100 * r['tolerance']:g} % at dx = {r['stops_at']:g}"
            if r["stops_at"]
            else f"float32 tracks float64 within {100 * r['tolerance']:g} % down to dx = {r['pairs'][-1][0]:g}, "
            "the smallest measured: it has not stopped converging"
        )
        lines.append(f"- {r['model']}, {r['protocol']}, {r['domain']} (MSE float64 / float32: {pairs}): {verdict}.")
    return lines + [""]


SECTION = Section("float32", lambda ctx: float32_vs_float64(ctx.df), text, order=120)
