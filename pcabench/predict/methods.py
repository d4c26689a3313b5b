"""The methods the prediction says reach an accuracy soonest: one search, for the front's runs and advise.

For the `linear` model the dispersion prediction (solvers/reference/dispersion.py) is
exact, so a method's error at t is known before it runs; its cost is about
particles x steps x neighbours. :func:`fastest` searches kernel x h/dx x dx x
CFL (a share of the predicted stable CFL, at most ``MARGIN`` of it: the
linear prediction is exact, the moving models' limit is measured lower) for
the cheapest methods predicted to reach an error, one per kernel. The front
preset runs them beside the paper's configuration, so the method advise
names comes from the front and the prediction, not from a hand-made list.
"""

from __future__ import annotations

import itertools
import math
from functools import lru_cache

from pcabench.predict.stability import MARGIN
from solvers import DEFAULT_SCENE, Scene, kernel_names
from solvers.kernels import kernel_named, truncated
from solvers.physics.integrators import sweeps_per_step
from solvers.reference.dispersion import lattice_stable_cfl, predict

H_FACTORS = (1.0, 1.1, 1.2, 1.3, 1.4, 1.6, 2.0, 2.13)
# High-order SPH (solvers/corrections/gradient.py, design.md 1c): each kernel with the gradient correction at
# h = 1.5 dx, a truncated kernel cut where it keeps its order (its ``order_cutoff``: the fourth-order Laguerre-Gauss
# kernel at 4 h, the sixth-order one at 5 h; 4 h for one that states none), with
# Verlet and with RK4. A fourth-order operator is most accurate at a short step (Verlet's phase lead no longer
# offsets a second-order lag): shares of the stable CFL down to a quarter.
HIGH_ORDER_H = (1.5,)
HIGH_ORDER_CUTOFF = 4.0
HIGH_ORDER_INTEGRATORS = ("verlet", "rk4")
DXS = (0.4, 0.3, 0.25, 0.2, 0.15, 0.125, 0.1, 0.075, 0.05)
CFL_SHARES = (0.5, 0.7, 0.9)  # of the predicted stable CFL


def cost(scene: Scene) -> float:
    """Work of a run, particle-neighbour visits: particles x steps x neighbours within the cutoff x the step's
    sweeps over Verlet's (RK4: 4)."""
    return scene.n_particles * scene.n_steps * math.pi * (scene.cutoff / scene.dx) ** 2 * step_weight(scene)


def step_weight(scene: Scene) -> float:
    """A step's sweeps over a Verlet step's (the integrator's program counted: rk4 4, rk2 2)."""
    return sweeps_per_step(scene.integrator) / sweeps_per_step("verlet")


def high_order_methods() -> tuple[dict, ...]:
    """The corrected methods a search adds to the standard kernels x h/dx (Scene fields: kernel, h_factor,
    cutoff_factor where the kernel is truncated, correction, integrator)."""
    return tuple(
        {
            "kernel": kernel,
            "h_factor": h,
            **({"cutoff_factor": kernel_named(kernel).order_cutoff or HIGH_ORDER_CUTOFF} if truncated(kernel) else {}),
            "correction": "gradient",
            "integrator": integrator,
        }
        for kernel in kernel_names()
        for h in HIGH_ORDER_H
        for integrator in HIGH_ORDER_INTEGRATORS
    )


def fastest(
    error: float, t_end: float, model: str = "linear", name: str = DEFAULT_SCENE, per_kernel: int = 1
) -> tuple[dict, ...]:
    """The cheapest methods (kernel, h_factor, cfl, dx; the paper's domain of scene ``name``) predicted to reach
    a relative RMS ``error`` at ``t_end``, ``per_kernel`` for each registered kernel, cheapest first, each with
    its predicted error, its stable CFL and its cost."""
    return _fastest(error, t_end, model, name, per_kernel, kernel_names())


@lru_cache(maxsize=64)
def _fastest(error: float, t_end: float, model: str, name: str, per_kernel: int, kernels: tuple) -> tuple[dict, ...]:
    found = []
    for kernel, h, share in itertools.product(kernels, H_FACTORS, CFL_SHARES):
        # the periodic lattice's (the search is over the paper's scene, which long runs never measured lower)
        limit = lattice_stable_cfl(kernel, h, Scene.default("cutoff_factor"), Scene.default("integrator"))
        if share > MARGIN[model] or limit <= 0:
            continue
        for dx in sorted(DXS, reverse=True):  # coarse first: the first dx that reaches it is the cheapest
            try:
                scene = Scene(
                    dx=dx,
                    name=name,
                    kernel=kernel,
                    h_factor=h,
                    cfl=round(share * limit, 2),
                    t_end=t_end,
                    model="linear",
                )
            except ValueError:  # a combination Scene refuses is not a candidate
                continue
            p = predict(scene)
            if p.predicted_error <= error:
                found.append(
                    {
                        "kernel": kernel,
                        "h_factor": h,
                        "cfl": scene.cfl,
                        "dx": dx,
                        "stable_cfl": limit,
                        "predicted_error": p.predicted_error,
                        "cost": cost(scene),
                    }
                )
                break
    found.sort(key=lambda m: m["cost"])
    out, per = [], {}
    for m in found:
        if per.get(m["kernel"], 0) < per_kernel:
            per[m["kernel"]] = per.get(m["kernel"], 0) + 1
            out.append(m)
    return tuple(out)
