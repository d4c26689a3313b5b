"""What high-order SPH costs a step (solvers/corrections/, the Laguerre-Gauss kernel, RK4): same-run ratios.

Each configuration's step is timed in turn with its baseline, best of 40 (on a shared, noisy machine a ratio
taken turn about holds where an absolute time does not). On the paper's scene at dx 0.1 (100K particles),
linkedlist-cpu, the pair list, serial; the kernel is the high-order method's, Laguerre-Gauss at h = 1.5 dx cut at
4 h. Each returns t_config / t_baseline (> 1: dearer):

- ``correction-linear``, ``correction-fixed``, ``correction-lagrangian``: the gradient correction against none, for
  each model (particles that stay build L once; moving ones at every search, their moments summed from the
  pair list);
- ``kernel``: the Laguerre-Gauss kernel against the Gaussian at the same h and cutoff (the same pairs): its cost
  per neighbour pair;
- ``rk4``: RK4 against Verlet, both corrected (four sweeps of both rates against one of each);
- ``kernel-6``: the sixth-order Laguerre-Gauss kernel against the Gaussian, both cut at its 5 h (the same pairs):
  its cost per neighbour pair;
- ``sixth-order``: the corrected step with the sixth-order kernel cut at 5 h against the fourth-order one's at 4 h
  (1.56 times the pairs in 2D).
"""

from .bench_ratios import best_alternating
from .common import Prepared, Unsupported

METHOD = {"kernel": "laguerre-gauss", "h_factor": 1.5, "cutoff_factor": 4.0}
REPEATS = 40  # turns each: a few per cent apart, so more than the speed ratios' 5 (bench_ratios.py)
CONFIGS = {  # (baseline, configuration): Scene overrides
    "correction-linear": ({"model": "linear"}, {"model": "linear", "correction": "gradient"}),
    "correction-fixed": ({"model": "fixed"}, {"model": "fixed", "correction": "gradient"}),
    "correction-lagrangian": ({"model": "lagrangian"}, {"model": "lagrangian", "correction": "gradient"}),
    "kernel": ({"model": "linear", "kernel": "gaussian"}, {"model": "linear"}),
    "rk4": (
        {"model": "linear", "correction": "gradient"},
        {"model": "linear", "correction": "gradient", "integrator": "rk4"},
    ),
    "kernel-6": (
        {"model": "linear", "kernel": "gaussian", "cutoff_factor": 5.0},
        {"model": "linear", "kernel": "laguerre-gauss-6", "cutoff_factor": 5.0},
    ),
    "sixth-order": (
        {"model": "linear", "correction": "gradient"},
        {"model": "linear", "correction": "gradient", "kernel": "laguerre-gauss-6", "cutoff_factor": 5.0},
    ),
}


class TrackHighOrderCost:
    params = [[0.1], list(CONFIGS)]
    param_names = ["dx", "what"]
    unit = "cost (same run)"
    timeout = 900

    def setup(self, dx, what):
        base, config = CONFIGS[what]
        try:
            self.prepared = {
                key: Prepared("linkedlist-cpu", "float64", dx, pair_loop="list", **{**METHOD, **scene})
                for key, scene in (("base", base), ("config", config))
            }
        except (Unsupported, TypeError, ValueError) as exc:  # a commit before the correction
            raise NotImplementedError(str(exc)) from None

    def track_cost(self, dx, what):
        best = best_alternating(self.prepared, REPEATS)
        return best["config"] / best["base"]
