"""A run's predicted stability: the largest stable CFL of its method, and how far past it the run went.

The limit (:func:`stable_cfl`, the suite's one) comes from the dispersion relation
(solvers/reference/dispersion.py ``predicted_stable_cfl``): exact for the `linear` model on a periodic lattice; for
`fixed` and `lagrangian` it is their linear part's (design section 4). Where
long runs of a scene measured a lower one (free ends, or a moving model's
nonlinear terms: :func:`measured_limits`), that one is used.
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
from pathlib import Path

import numpy as np

ROUND_OFF_E_FOLDINGS = math.log(1e16)  # ~37: from float64 round-off to the pulse's size
# The one margin rule: the largest share of a method's stable CFL (:func:`stable_cfl`) at which advise names a
# stored run or suggests one, and the front picks its methods. The prediction is exact for `linear`; for the
# moving models it is their linear part's, and their measured limits lie lower.
MARGIN = {"linear": 0.9, "fixed": 0.7, "lagrangian": 0.7}
UNSTABLE_BY_PREDICTION = "unstable by prediction"

MEASURED_LIMITS_FILE = Path(__file__).with_name("measured_limits.csv")  # data, with where each was measured


@lru_cache(maxsize=1)
def measured_limits() -> dict[tuple, tuple[float, float]]:
    """(scene, model, kernel, h/dx, cutoff/h, integrator, correction) -> (the smallest CFL that blew up, the largest
    that stayed bounded below it), where long runs measured a limit below the prediction
    (:data:`MEASURED_LIMITS_FILE`, each row with its date, machine and command)."""
    import csv

    with MEASURED_LIMITS_FILE.open(newline="", encoding="utf-8") as f:
        rows = csv.DictReader(line for line in f if not line.startswith("#"))
        return {
            (
                r["scene"],
                r["model"],
                r["kernel"],
                float(r["h_factor"]),
                float(r["cutoff_factor"]),
                r["integrator"],
                r.get("correction") or "none",
            ): (
                float(r["blew_up_from"]),
                float(r["bounded_to"]),
            )
            for r in rows
        }


def _value(r, key, default=None):
    v = r.get(key, default) if hasattr(r, "get") else getattr(r, key, default)
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return default
    return v


@lru_cache(maxsize=1024)
def _limits(
    kernel: str, h_factor: float, cutoff_factor: float, integrator: str, correction: str = "none", dims: int = 2
) -> tuple[float, float]:
    """(stable CFL, largest c0 |D| dt per unit CFL) of one method (:class:`solvers.method.Method`) on the periodic
    square (``dims`` 2) or cubic (3) lattice. Both are the same at every dx (the lattice's offsets are in units of
    dx, and dx |D| depends on h/dx only), so dx = 1 stands for all."""
    from solvers.kernels import truncated
    from solvers.method import Method
    from solvers.reference.dispersion import largest_symbol, unit_scene
    from solvers.reference.dispersion import predicted_stable_cfl as lattice_limit

    if dims == 3:
        from solvers.reference.dispersion3d import largest_unit_symbol, lattice_stable_cfl

        method = (kernel, h_factor, cutoff_factor, integrator, correction)
        return lattice_stable_cfl(*method), largest_unit_symbol(*method)
    method = Method(kernel, h_factor, cutoff_factor if truncated(kernel) else None, 1.0, integrator, correction)
    scene = unit_scene(**method.scene_fields())
    return lattice_limit(method), scene.dx * largest_symbol(scene)


def dims_of(r) -> int:
    """The dimension of ``r``'s scene (its kind's; 2 for a run without a scene, the paper's, or a scene whose
    plug-in is not installed here)."""
    from solvers import DEFAULT_SCENE, scene_kind

    try:
        return int(scene_kind(str(_value(r, "scene", DEFAULT_SCENE))).dims)
    except (KeyError, ValueError):
        return 2


def lattice_limits(r) -> tuple[float, float]:
    """:func:`_limits` of ``r``'s method on its scene's lattice (square or cubic)."""
    return _limits(*method_of(r), dims_of(r))


def method_of(r) -> tuple[str, float, float, str, str]:
    """(kernel, h/dx, cutoff/h, integrator, correction) of a stored run or a front point
    (:meth:`solvers.method.Method.of`: Scene's defaults where missing; a compact kernel's truncation is its support,
    written as the default)."""
    from solvers import Scene
    from solvers.method import Method

    m = Method.of(r)
    cut = Scene.default("cutoff_factor") if m.cutoff_factor is None else m.cutoff_factor
    return m.kernel, m.h_factor, cut, m.integrator, m.correction


FREE_END_SCENE = "plane-pulse"  # where the free end's limits are measured (the high-order study's long runs)


def free_ended(name: str, edges: str, wall: str = "") -> bool:
    """Whether a run of scene ``name`` has a free end: closed (no ``edges`` opened) with a lattice edge with no
    wall, seam or layer beyond it, where a particle has half its neighbours (solvers.scenes.base.SceneKind.boundaries),
    or a body whose wall (``wall``: its boundary method) leaves the fluid beside it part of its neighbours as such an
    edge does (``BoundaryMethod.free_end``: the weak wall and its cut cells; the sphere's long runs blow up where the
    free end's do, docs/accuracy.md "The sphere's stable step")."""
    from solvers import scene_kind
    from solvers.boundaries.bodies import boundary_method_named

    try:
        kind = scene_kind(name)
    except (KeyError, ValueError):  # a scene whose plug-in is not installed: no claim about its edges
        return False
    if kind.body and wall:
        try:
            if getattr(boundary_method_named(wall), "free_end", False):
                return True
        except (KeyError, ValueError):  # a wall whose plug-in is not installed: no claim about it
            pass
    closed = not edges and not kind.defaults.get("open")
    return closed and bool({"free-x", "free-y"} & kind.boundaries())


def body_wall(r, name: str) -> str:
    """The boundary method of the wall of ``r``'s body: the one it names or ran, else the default for its
    correction (solvers.body.BodyOptions); "" for a scene without a body (or one whose plug-in is not installed)."""
    from solvers import scene_kind
    from solvers.body import BodyOptions

    try:
        if not scene_kind(name).body:
            return ""
    except (KeyError, ValueError):
        return ""
    named = _value(r, "boundary_method") or _value(r, "boundary_method_used")
    return str(named) if named else BodyOptions().boundary_method_used(method_of(r)[4])


def measured_limit(r) -> float | None:
    """The smallest CFL at which long runs of ``r``'s scene, model and method blew up (:func:`measured_limits`),
    or None (a run without a scene is of the paper's). A scene with a free end (:func:`free_ended`: a closed
    scene's free edge, or a body's wall without ghosts) and no row of its own takes the free end's limit measured
    on :data:`FREE_END_SCENE`."""
    from solvers import DEFAULT_SCENE
    from solvers.kernels import truncated

    kernel, h, cut, integrator, correction = method_of(r)
    name, model_r = str(_value(r, "scene", DEFAULT_SCENE)), _value(r, "model", "")
    edges = str(_value(r, "open", "") or "")
    names = [name] + ([FREE_END_SCENE] if free_ended(name, edges, body_wall(r, name)) else [])
    for want in names:
        for (scene, model, k, hh, cc, integ, corr), (limit, _bounded) in measured_limits().items():
            if (
                (scene, model, k, integ, corr) == (want, model_r, kernel, integrator, correction)
                and math.isclose(h, hh)
                and (not truncated(k) or math.isclose(cut, cc))
            ):
                return limit
    return None


def stable_cfl(r) -> float:
    """The largest stable CFL of ``r``'s method on its scene and model, ``r`` a stored run, a front point or a
    :class:`~solvers.Scene`: the periodic lattice's prediction (0: its integrator grows at any step), or the limit
    long runs of its scene and model measured where that is lower (:func:`measured_limits`). Every stable CFL the
    suite states or steps by is this one (advise, the fronts, the reports, the cylinder's advised CFL), but for
    a plan that brackets the periodic lattice's own limit on purpose (the walls study's long runs:
    solvers.reference.dispersion.predicted_stable_cfl). Open edges keep
    it: their damping is a term of each update (solvers/boundaries/absorbers/base.py; measured with `pcabench study
    --open` and the cylinder's long runs, docs/accuracy.md "Open edges")."""
    from solvers import Scene
    from solvers.method import Method

    if isinstance(r, Scene):
        wall = r.boundary_method_used if r.body is not None else ""
        r = {"scene": r.name, "model": r.model, "open": r.open, "boundary_method": wall, **Method.of(r).scene_fields()}
    linear, measured = lattice_limits(r)[0], measured_limit(r)
    return linear if measured is None else min(linear, measured)


def past_limit(cfl: float, limit: float) -> bool:
    """Whether ``cfl`` is at or past the stable ``limit``: the scan's limit is the first unstable step."""
    return float(cfl) >= float(limit)


def margin(model: str) -> float:
    """The largest share of the stable CFL a run of ``model`` is advised at (:data:`MARGIN`)."""
    return MARGIN[model]


def margin_rule(model: str) -> str:
    """:data:`MARGIN` for ``model`` in words, as advise states it."""
    why = "whose prediction is exact" if model == "linear" else "whose prediction is of its linear part"
    return f"advised at most {margin(model):g} of the stable CFL for {model}, {why}"


def e_foldings(r, steps: int) -> float:
    """How many times e the most unstable mode of run ``r``'s method grows in ``steps`` steps: the log of the
    step matrix's spectral radius, largest over the modes up to the lattice's largest |D|, times the steps."""
    from solvers.reference.dispersion import amplification_radius

    _, z_per_cfl = lattice_limits(r)
    z = np.linspace(0.0, float(r["cfl"]) * z_per_cfl, 200)[1:]
    radius = float(amplification_radius(method_of(r)[3], z).max())
    return max(0.0, math.log(radius)) * int(steps)


def assess(r) -> dict:
    """``stable_cfl``, ``fraction`` (the run's CFL over it, inf for a limit of 0), ``past_limit``,
    ``past_margin`` (past :func:`margin` of the limit for its model, to the CFL's two decimals: never advised),
    ``limit_from``
    ("prediction", or "long runs" where the limit long runs of its scene measured is the lower) and
    ``predicted`` (the periodic lattice's predicted limit)."""
    limit, cfl, predicted = stable_cfl(r), float(r["cfl"]), lattice_limits(r)[0]
    fraction = cfl / limit if limit > 0 else math.inf
    return {
        "stable_cfl": limit,
        "fraction": fraction,
        "past_limit": past_limit(cfl, limit),
        # a CFL is written to two decimals (round(share x limit, 2)): half of the last one is within the margin
        "past_margin": cfl > margin(str(_value(r, "model", "linear"))) * limit + 0.005,
        "predicted": predicted,
        "limit_from": "prediction" if limit == predicted else "long runs",
    }
