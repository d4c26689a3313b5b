"""The benchmark suites themselves: the ratio checker can fail, and no suite touches CUDA at import."""

from __future__ import annotations

import subprocess
import sys

from tests.benchmarks.check_ratios import check


def medians(ll_step=1.0, ap_step=3.0, parts=(0.1, 0.8, 0.1)):
    out = {}
    for solver, step in (("linkedlist-cpu", ll_step), ("allpair-cpu", ap_step)):
        out[(solver, "float64", 1000, "step")] = step
        for stage, share in zip(("snp", "pi", "su"), parts):
            out[(solver, "float64", 1000, stage)] = step * share
    return out


def test_ratio_checks_pass_and_fail():
    assert check(medians()) == []
    slow = check(medians(ll_step=4.0))
    assert len(slow) == 1 and "not faster than all-pair" in slow[0]
    off = check(medians(parts=(0.1, 0.5, 0.1)))
    assert len(off) == 2 and all("SNP+PI+SU" in f for f in off)
    assert "no benchmark pairs" in check({})[0]


def test_benchmark_modules_import_without_cuda():
    code = (
        "import sys; sys.path.insert(0, '.')\n"
        "import benchmarks.bench_step, benchmarks.bench_gpu, benchmarks.bench_accuracy, "
        "benchmarks.bench_memory, benchmarks.bench_jit, benchmarks.common\n"
        "bad = [m for m in sys.modules if m.startswith(('cupy', 'numba.cuda'))]\n"
        "assert not bad, bad"
    )
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
