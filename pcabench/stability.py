"""A run's predicted stability: the largest stable CFL of its method, and how far past it the run went.

The limit comes from the dispersion relation (solvers/dispersion.py
``stable_cfl``): exact for the `linear` model; for `fixed` and `lagrangian`
it is their linear part's, the limit used for them too (design section 4)
unless long runs measured a lower one (:data:`MEASURED_LIMITS`).
A run at or past its predicted limit is unstable, whatever its error: if it
ended bounded, its run was too short for round-off to grow, and
:func:`e_foldings` says how far the most unstable mode had grown (round-off,
1e-16 of the pulse, needs about :data:`ROUND_OFF_E_FOLDINGS` of them to reach
the pulse's size). advise, the speed-accuracy front, the time-to-accuracy
table and the stability map all read :func:`assess`.
"""
from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

ROUND_OFF_E_FOLDINGS = math.log(1e16)  # ~37: from float64 round-off to the pulse's size
UNSTABLE_BY_PREDICTION = "unstable by prediction"

# The moving models over long runs, where their nonlinear terms can grow what the linear part keeps bounded:
# (model, kernel, h/dx, cutoff/h, integrator) -> (the smallest CFL that blew up, the largest that stayed
# bounded). Measured 2026-12-01 at t = 300 s, dx = 0.25 on a 5 m strip (about 250 steps), serial, with
# `pcabench run --solver linkedlist-cpu --dx 0.25 --t-end 300 --model MODEL --cfl CFL --strip-height 5`:
# lagrangian bounded at 4.7, blew up at 4.75 (step 236), 4.8 (142), 4.9 (47); fixed bounded at 4.5 and 4.6,
# blew up at 4.7 (step 149), 4.8 (47), 4.9 (23). The linear prediction for this method is 4.97.
MEASURED_LIMITS = {("lagrangian", "gaussian", 2.13, 3.0, "verlet"): (4.75, 4.7),
                   ("fixed", "gaussian", 2.13, 3.0, "verlet"): (4.7, 4.6)}


def _value(r, key, default=None):
    v = r.get(key, default) if hasattr(r, "get") else getattr(r, key, default)
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return default
    return v


def _scene(kernel: str, h_factor: float, cutoff_factor: float, integrator: str, dx: float = 1.0):
    from solvers import Scene
    from solvers.kernels import truncated

    method = {"kernel": kernel, "h_factor": h_factor, "integrator": integrator}
    if truncated(kernel):  # a kernel of compact support (the Wendland kernels) is cut there
        method["cutoff_factor"] = cutoff_factor
    return Scene(dx=dx, t_end=1.0, model="linear", memory_limit_bytes=2**62, **method)


@lru_cache(maxsize=1024)
def _limits(kernel: str, h_factor: float, cutoff_factor: float, integrator: str) -> tuple[float, float]:
    """(stable CFL, largest c0 |D| dt per unit CFL) of one method. Both are the same at every dx (the
    lattice's offsets are in units of dx, and dx |D| depends on h/dx only), so dx = 1 stands for all."""
    from solvers.dispersion import largest_symbol, stable_cfl

    scene = _scene(kernel, h_factor, cutoff_factor, integrator)
    return stable_cfl(scene), scene.dx * largest_symbol(scene)


def method_of(r) -> tuple[str, float, float, str]:
    """(kernel, h/dx, cutoff/h, integrator) of a stored run or a front point (Scene's defaults where missing)."""
    from solvers import Scene

    return (str(_value(r, "kernel", Scene.default("kernel"))), float(_value(r, "h_factor", Scene.default("h_factor"))),
            float(_value(r, "cutoff_factor", Scene.default("cutoff_factor"))),
            str(_value(r, "integrator", Scene.default("integrator"))))


def measured_limit(r) -> float | None:
    """The smallest CFL at which long runs of ``r``'s model and method blew up (:data:`MEASURED_LIMITS`), or None."""
    from solvers.kernels import truncated

    kernel, h, cut, integrator = method_of(r)
    for (model, k, hh, cc, integ), (limit, _bounded) in MEASURED_LIMITS.items():
        if (model, k, integ) == (_value(r, "model", ""), kernel, integrator) and math.isclose(h, hh) \
                and (not truncated(k) or math.isclose(cut, cc)):
            return limit
    return None


def stable_limit(r) -> float:
    """The largest stable CFL of run ``r``'s method: predicted (0: its integrator grows at any step), or for a
    moving model the limit measured over long runs where that is lower (:data:`MEASURED_LIMITS`)."""
    linear, measured = _limits(*method_of(r))[0], measured_limit(r)
    return linear if measured is None else min(linear, measured)


def past_limit(cfl: float, limit: float) -> bool:
    """Whether ``cfl`` is at or past the stable ``limit``: the scan's limit is the first unstable step."""
    return float(cfl) >= float(limit)


def e_foldings(r, steps: int) -> float:
    """How many times e the most unstable mode of run ``r``'s method grows in ``steps`` steps: the log of the
    step matrix's spectral radius, largest over the modes up to the lattice's largest |D|, times the steps."""
    from solvers.dispersion import amplification_radius

    _, z_per_cfl = _limits(*method_of(r))
    z = np.linspace(0.0, float(r["cfl"]) * z_per_cfl, 200)[1:]
    radius = float(amplification_radius(method_of(r)[3], z).max())
    return max(0.0, math.log(radius)) * int(steps)


def assess(r) -> dict:
    """``stable_cfl``, ``fraction`` (the run's CFL over it, inf for a limit of 0), ``past_limit`` and
    ``limit_from`` ("prediction", or "long runs" where a moving model's measured limit is the lower)."""
    limit, cfl = stable_limit(r), float(r["cfl"])
    return {"stable_cfl": limit, "fraction": cfl / limit if limit > 0 else math.inf,
            "past_limit": past_limit(cfl, limit),
            "limit_from": "prediction" if limit == _limits(*method_of(r))[0] else "long runs"}
