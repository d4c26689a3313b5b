"""The paper's CPU matrix (Tables 4-6, Figs. 8-14), as far as the budgets allow."""

from __future__ import annotations

from pcabench.spec import ALL_CORES, RunSpec
from pcabench.studies.preset import Preset, spec_of


def paper() -> list[RunSpec]:
    """The paper's CPU matrix (Tables 4-6, Figs. 8-14), as far as the budgets allow."""
    runs = []
    for dx in (1.0, 0.5, 0.25, 0.2, 0.1, 0.05, 0.025):  # 1K .. 1.6M; Table 6 at 25K/100K/400K
        runs.append(spec_of(dx=dx, steps=100))
        runs.append(spec_of(dx=dx, steps=100, threads=ALL_CORES))
        runs.append(spec_of(dx=dx, steps=20, pair_loop="gather"))  # the paper's loop, for Table 4
    # Fig. 9 (the paper's 10th step, 1K .. 256K)
    for dx in (1.0, 0.5, 0.25, 0.125, 0.0625):
        runs.append(spec_of(dx=dx, steps=10))
        runs.append(spec_of("allpair-cpu", dx=dx, steps=10))
    for model in ("linear", "fixed", "lagrangian"):
        for precision in ("float64", "float32"):
            for dx in (0.4, 0.2, 0.1, 0.05, 0.025):
                runs.append(spec_of(threads=ALL_CORES, dx=dx, t_end=10.0, model=model, precision=precision, strip=True))
            for dx in (0.1, 0.05, 0.01, 0.004):
                runs.append(spec_of(threads=ALL_CORES, dx=dx, steps=100, model=model, precision=precision, strip=True))
        for dx in (0.2, 0.1):
            runs.append(spec_of(threads=ALL_CORES, dx=dx, t_end=10.0, model=model))
    return runs


PAPER = Preset(
    "paper", paper, 900.0, flag="paper", help="the paper's CPU matrix, within the budgets ({size})", order=20
)
