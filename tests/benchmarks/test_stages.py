"""The stages of a step on small scenes, for every solver and precision (pytest-benchmark).

    python -m pytest -o addopts="" tests/benchmarks --benchmark-only --benchmark-json=reports/pytest-benchmark/run.json
    python tests/benchmarks/check_ratios.py reports/pytest-benchmark/run.json

Each benchmark records the particle count, solver, precision, the errors
against the analytic pulse after the timed steps, and the hardware profile
id in its extra info. Compilation happens before the timed rounds.
check_ratios.py then checks ratios measured in the same run, which must hold
on any machine; absolute times are not asserted anywhere.
"""
from __future__ import annotations

import pytest

from benchmarks.common import Prepared, Unsupported
from pcabench.profiles import machine_id

SOLVERS = ("allpair-cpu", "linkedlist-cpu", "linkedlist-gpu")
SIZES = (1.0, 0.5)  # 1,000 and 4,000 particles
ROUNDS = 7


def prepared(solver, precision, dx) -> Prepared:
    """A fresh solver per benchmark (compilation is cached), so one stage's repeats never feed another's."""
    try:
        return Prepared(solver, precision, dx)
    except Unsupported as exc:
        pytest.skip(str(exc))


@pytest.mark.parametrize("dx", SIZES)
@pytest.mark.parametrize("precision", ("float64", "float32"))
@pytest.mark.parametrize("solver", SOLVERS)
@pytest.mark.parametrize("stage", ("step", "snp", "pi", "su"))
def test_stage(benchmark, solver, precision, dx, stage):
    p = prepared(solver, precision, dx)
    benchmark.group = f"{solver} {precision} N={p.n_particles}"
    if stage == "step":  # whole steps advance the pulse: score the state they reach
        benchmark.pedantic(p.step, rounds=ROUNDS, iterations=1, warmup_rounds=1)
        err = p.errors()
    else:  # one stage repeated alone is not a time step: score the state it was timed on
        err = p.errors()
        benchmark.pedantic(lambda: p.stage(stage), rounds=ROUNDS, iterations=1, warmup_rounds=1)
    benchmark.extra_info.update({"solver": solver, "precision": precision, "n_particles": p.n_particles,
                                 "stage": stage, "mse": err.mse, "me": err.me, "jit_seconds": p.jit_seconds,
                                 "profile_id": machine_id()})
    assert err.mse < 0.3  # the timed state is still the pulse (0.18 after 10 steps at N = 1,000)
