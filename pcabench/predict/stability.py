"""A run's predicted stability: the largest stable CFL of its method, and how far past it the run went.

The limit comes from the dispersion relation (solvers/reference/dispersion.py
``stable_cfl``): exact for the `linear` model on a periodic lattice; for
`fixed` and `lagrangian` it is their linear part's (design section 4). Where
long runs of a scene measured a lower one (free ends, or a moving model's
nonlinear terms: :data:`MEASURED_LIMITS`), that one is used.
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

# Long runs (``pcabench study --stability long``: t = 300 s, dx = 0.25, the paper's method, serial), where the
# prediction's periodic lattice is not the whole story: free ends (the paper's scene) and the moving models'
# nonlinear terms can grow what the periodic linear lattice keeps bounded.
# (scene, model, kernel, h/dx, cutoff/h, integrator) -> (the smallest CFL that blew up, the largest that stayed
# bounded below it), where that is below the prediction (4.97 for this method). Measured 2026-12-01 (AMD EPYC):
# on the plane pulse's strip (free ends, Mach 0.01) every model bounded at 4.75 and blew up from 4.8, the linear
# one too, so that it is the free ends' limit; on the 2D pulse in a periodic 20 m square linear and lagrangian
# bounded at 4.9 and blew up at 5 (the prediction), fixed blew up from 4.75 (bounded at 4.7).
_PAPER_METHOD = ("gaussian", 2.13, 3.0, "verlet")
MEASURED_LIMITS = {
    ("plane-pulse", "linear", *_PAPER_METHOD): (4.8, 4.75),
    ("plane-pulse", "fixed", *_PAPER_METHOD): (4.8, 4.75),
    ("plane-pulse", "lagrangian", *_PAPER_METHOD): (4.8, 4.75),
    ("acoustic-pulse", "fixed", *_PAPER_METHOD): (4.75, 4.7),
    # At a rigid wall (``pcabench study --walls``, commit 15cd1e3, measured 2026-12-02, AMD EPYC), CFL 4.75, 4.9, 5:
    # on plane-wall's strip (Mach 0.01, a free left end) every model bounded at 4.75 and blew up from 4.9, as the
    # plane pulse's free ends; on pulse-wall (walls at both x ends) linear and lagrangian bounded at 4.9 and blew up
    # at 5 (the prediction), fixed blew up from 4.9 (bounded at 4.75, where the periodic square's fixed run blew up):
    # no wall lowered a limit below its free counterpart's.
    ("plane-wall", "linear", *_PAPER_METHOD): (4.9, 4.75),
    ("plane-wall", "fixed", *_PAPER_METHOD): (4.9, 4.75),
    ("plane-wall", "lagrangian", *_PAPER_METHOD): (4.9, 4.75),
    ("pulse-wall", "fixed", *_PAPER_METHOD): (4.9, 4.75),
}


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
    return Scene(dx=dx, t_end=1.0, model="linear", **method)


@lru_cache(maxsize=1024)
def _limits(kernel: str, h_factor: float, cutoff_factor: float, integrator: str) -> tuple[float, float]:
    """(stable CFL, largest c0 |D| dt per unit CFL) of one method. Both are the same at every dx (the
    lattice's offsets are in units of dx, and dx |D| depends on h/dx only), so dx = 1 stands for all."""
    from solvers.reference.dispersion import largest_symbol, stable_cfl

    scene = _scene(kernel, h_factor, cutoff_factor, integrator)
    return stable_cfl(scene), scene.dx * largest_symbol(scene)


def method_of(r) -> tuple[str, float, float, str]:
    """(kernel, h/dx, cutoff/h, integrator) of a stored run or a front point (:meth:`solvers.method.Method.of`:
    Scene's defaults where missing; a compact kernel's truncation is its support, written as the default)."""
    from solvers import Scene
    from solvers.method import Method

    m = Method.of(r)
    cut = Scene.default("cutoff_factor") if m.cutoff_factor is None else m.cutoff_factor
    return m.kernel, m.h_factor, cut, m.integrator


def measured_limit(r) -> float | None:
    """The smallest CFL at which long runs of ``r``'s scene, model and method blew up (:data:`MEASURED_LIMITS`),
    or None (a run without a scene is of the paper's)."""
    from solvers import DEFAULT_SCENE
    from solvers.kernels import truncated

    kernel, h, cut, integrator = method_of(r)
    mine = (str(_value(r, "scene", DEFAULT_SCENE)), _value(r, "model", ""), kernel, integrator)
    for (scene, model, k, hh, cc, integ), (limit, _bounded) in MEASURED_LIMITS.items():
        if (scene, model, k, integ) == mine and math.isclose(h, hh) and (not truncated(k) or math.isclose(cut, cc)):
            return limit
    return None


def stable_limit(r) -> float:
    """The largest stable CFL of run ``r``'s method: predicted (0: its integrator grows at any step), or the
    limit long runs of its scene and model measured where that is lower (:data:`MEASURED_LIMITS`)."""
    linear, measured = _limits(*method_of(r))[0], measured_limit(r)
    return linear if measured is None else min(linear, measured)


def past_limit(cfl: float, limit: float) -> bool:
    """Whether ``cfl`` is at or past the stable ``limit``: the scan's limit is the first unstable step."""
    return float(cfl) >= float(limit)


def e_foldings(r, steps: int) -> float:
    """How many times e the most unstable mode of run ``r``'s method grows in ``steps`` steps: the log of the
    step matrix's spectral radius, largest over the modes up to the lattice's largest |D|, times the steps."""
    from solvers.reference.dispersion import amplification_radius

    _, z_per_cfl = _limits(*method_of(r))
    z = np.linspace(0.0, float(r["cfl"]) * z_per_cfl, 200)[1:]
    radius = float(amplification_radius(method_of(r)[3], z).max())
    return max(0.0, math.log(radius)) * int(steps)


def assess(r) -> dict:
    """``stable_cfl``, ``fraction`` (the run's CFL over it, inf for a limit of 0), ``past_limit``,
    ``limit_from`` ("prediction", or "long runs" where the limit long runs of its scene measured is the lower)
    and ``predicted`` (the periodic lattice's predicted limit)."""
    limit, cfl, predicted = stable_limit(r), float(r["cfl"]), _limits(*method_of(r))[0]
    return {
        "stable_cfl": limit,
        "fraction": cfl / limit if limit > 0 else math.inf,
        "past_limit": past_limit(cfl, limit),
        "predicted": predicted,
        "limit_from": "prediction" if limit == predicted else "long runs",
    }
