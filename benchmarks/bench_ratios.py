"""Same-run speed ratios of linkedlist-cpu: each configuration's step timed alternately, best of several.

On a shared, noisy machine an absolute time can double from one run to the
next; a ratio of two times taken turn about in the same run holds. These are
the ratios the CPU solver's targets are stated in: the pair list against the
paper's gather loop, two threads against one, float32 against float64, and
particles that never move (fixed, linear) against moving ones. Each returns
t_baseline / t_config (> 1: faster). 100K particles; PCABENCH_BENCH_LARGE=1
adds 400K.
"""

import time

from .common import Prepared, Unsupported, large

BASE = ("float64", "lagrangian", 1, "list")  # precision, model, threads, pair loop
CONFIGS = {
    "gather": ("float64", "lagrangian", 1, "gather"),
    "threads2": ("float64", "lagrangian", 2, "list"),
    "float32": ("float32", "lagrangian", 1, "list"),
    "fixed": ("float64", "fixed", 1, "list"),
    "linear": ("float64", "linear", 1, "list"),
}
REPEATS = 5


def best_alternating(prepared: dict, repeats: int = REPEATS) -> dict:
    """Each prepared solver's best step time, s, timing them in turn ``repeats`` times."""
    best = {key: float("inf") for key in prepared}
    for _ in range(repeats):
        for key, p in prepared.items():
            t0 = time.perf_counter()
            p.step()
            best[key] = min(best[key], time.perf_counter() - t0)
    return best


class TrackSpeedRatios:
    params = [[0.1] + ([0.05] if large() else []), list(CONFIGS)]
    param_names = ["dx", "against"]
    unit = "speed-up (same run)"
    timeout = 900

    def setup(self, dx, against):
        try:
            self.prepared = {
                key: Prepared("linkedlist-cpu", precision, dx, threads=threads, pair_loop=loop, model=model)
                for key, (precision, model, threads, loop) in (("base", BASE), (against, CONFIGS[against]))
            }
        except Unsupported as exc:
            raise NotImplementedError(str(exc)) from None

    def track_speedup(self, dx, against):
        best = best_alternating(self.prepared)
        if against == "gather":  # the list's gain over the paper's loop
            return best["gather"] / best["base"]
        return best["base"] / best[against]
