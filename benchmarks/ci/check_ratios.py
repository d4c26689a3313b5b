"""Check same-run ratios in a pytest-benchmark JSON file; exit 1 naming any that fails.

    python benchmarks/ci/check_ratios.py reports/pytest-benchmark/run.json

The ratios hold on any machine, however fast or noisy, because both sides
were measured in the same run, each as its best round (a neighbour's job can
only slow a round down):
- the linked list takes less time per step than all-pair at every size tested;
- a step's best SNP + PI + SU add up to its best step (within 25 %), both measured alternating round by
  round in the step's own benchmark (``alternating`` in its extra info; separate benchmarks minutes apart
  where a JSON file predates it).
"""

from __future__ import annotations

import json
import sys

STEP_SUM_TOLERANCE = 0.25


def best_times(path) -> dict:
    """The best round of each stage benchmark, s, by (solver, precision, N, stage) (others, such as the
    pair-list build per kernel, have no stage and are not ratios of these)."""
    data = json.loads(open(path).read())
    out = {}
    for b in data["benchmarks"]:
        e = b["extra_info"]
        if "stage" in e:
            out[(e["solver"], e["precision"], e["n_particles"], e["stage"])] = b["stats"]["min"]
        if "alternating" in e:
            out[(e["solver"], e["precision"], e["n_particles"], "alternating")] = e["alternating"]
    return out


def check(med: dict) -> list[str]:
    failures, checked = [], 0
    for (solver, precision, n, stage), t in sorted(med.items()):
        if stage != "step":
            continue
        parts = [med.get((solver, precision, n, s)) for s in ("snp", "pi", "su")]
        step = t
        both = med.get((solver, precision, n, "alternating"))
        if both is not None:
            parts, step = [both["stages"]], both["step"]
        if None not in parts:
            checked += 1
            ratio = sum(parts) / step
            if abs(ratio - 1) > STEP_SUM_TOLERANCE:
                failures.append(
                    f"{solver} {precision} N={n}: SNP+PI+SU = {sum(parts):.3g} s is {ratio:.2f}x "
                    f"the measured step {step:.3g} s (allowed 1 +- {STEP_SUM_TOLERANCE})"
                )
        if solver == "allpair-cpu" and ("linkedlist-cpu", precision, n, "step") in med:
            checked += 1
            ll = med[("linkedlist-cpu", precision, n, "step")]
            if not ll < t:
                failures.append(
                    f"{precision} N={n}: linked list {ll:.3g} s per step is not faster than all-pair {t:.3g} s"
                )
    if checked == 0:
        failures.append("no benchmark pairs to compare: was the suite run with --benchmark-only?")
    return failures


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if len(argv) != 1:
        print(__doc__.strip().splitlines()[2], file=sys.stderr)
        return 2
    try:
        failures = check(best_times(argv[0]))
    except (OSError, ValueError, KeyError) as exc:
        print(f"cannot read the pytest-benchmark JSON {argv[0]!r}: {exc}", file=sys.stderr)
        return 2
    for f in failures:
        print(f"ratio check failed: {f}", file=sys.stderr)
    if not failures:
        print(f"ratio checks passed ({argv[0]})")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
