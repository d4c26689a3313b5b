"""The prediction's search for the cheapest method to an accuracy (advise's suggestion when no stored run reaches
it): a small grid of kernel x h/dx x dx x CFL share, and the high-order methods, each predicted from the dispersion
relation (its scene kind's :meth:`predict_headline`), the CFL at most the margin of the stable one
(:mod:`pcabench.predict.stability`), the cost particles x steps x neighbours x the step's sweeps. ``pcabench advise``
(pcabench/predict/advice.py) names what :func:`suggest` finds as a ``pcabench study`` command.
"""

from __future__ import annotations

import functools
import itertools
import shlex
import sys
import time

from pcabench.predict.methods import high_order_methods, step_weight
from pcabench.predict.stability import margin, stable_cfl
from solvers import DEFAULT_SCENE, DEFAULT_SOLVER, Scene, kernel_named, kernel_names, scene_kind
from solvers.kernels import truncated
from solvers.method import Method

# The configurations the prediction searches when no stored run reaches a target (a small, cheap grid), for
# every registered kernel.
SEARCH_H = (1.3, 1.6, 2.13)
SEARCH_DX = (1.0, 0.5, 0.4, 0.25, 0.2, 0.125, 0.1, 0.05, 0.025)
# The steps searched, as shares of the stable CFL: the longest the margin allows (stability.MARGIN, the one rule:
# 0.9 for linear), and on a strip and for the high-order methods also shorter ones (a fourth-order operator is
# most accurate at a short step: Verlet's phase lead no longer offsets a second-order lag). A 2D scene's
# prediction evolves every mode of its lattice (seconds at dx = 0.125): a coarser grid, and a standard method at
# the longest step only (the leapfrog's phase lead offsets the lattice's lag: the longest stable step is the
# most accurate and the cheapest).
SHORT_SHARES = (0.25, 0.5)
SEARCH_DX_2D = (0.5, 0.25, 0.2, 0.125)
# A scene with a body predicts its probes alone (about a second at any dx: solvers/reference/dispersive_cylinder.py):
# down to 80 particles per pulse width, and wider kernels (each kernel's long-wave phase-speed deficit at fixed
# h / dx, which no refinement removes, is smallest at h of 2.5 to 3 dx: docs/accuracy.md).
SEARCH_DX_BODY = (0.04, 0.02, 0.01, 0.005, 0.0025)
SEARCH_H_BODY = (1.0, 1.3, 1.6, 2.13, 2.5, 3.0)
# The high-order methods converge fast: a finer grid of dx about the workshop's 10 particles a pulse width.
HIGH_ORDER_DX_BODY = (0.04, 0.03, 0.025, 0.0225, 0.02, 0.01)
# Near a body the prediction has the wall exact: a lower bound. Measured (2026-12-06, the weak wall, Laguerre-Gauss
# h 1.5 dx cut at 4 h, corrected, Verlet CFL 0.5; docs/accuracy.md): the runs' probes are 1.03, 1.18, 1.8 and 1.65
# times the prediction at dx 0.04, 0.03, 0.0225, 0.02 (the lattice's staircase about the circle: first order). A
# body's suggestion asks the prediction for this share of the target.
BODY_MARGIN = 0.5
# A corrected method's suggestion near a body has cut cells (solvers/boundaries/bodies/cut.py: the sites the surface
# cuts carry their cells' fluid volume), whose wall is second order. Measured (2026-12-07, `pcabench study --cylinder
# wall`): the probes 1.00 to 1.02 times the prediction with the fourth-order kernel (Verlet CFL 0.5, dx 0.04 to 0.02),
# 1.04 and 1.43 with the sixth-order one (RK4 CFL 1, dx 0.04 and 0.02: where the bulk's is 0.1 %, the wall's shows).
CUT_WALL = {"boundary_method": "cut"}
CUT_MARGIN = 0.7


def search_grid(kind, model: str = "linear") -> tuple:
    """(dxs, h factors, CFL shares of the stable CFL) :func:`suggest` searches on a scene of ``kind`` for
    ``model``: the shares end at its margin (:func:`pcabench.predict.stability.margin`)."""
    longest = (margin(model),)
    if kind.body:
        return SEARCH_DX_BODY, SEARCH_H_BODY, longest
    if kind.strip:
        return SEARCH_DX, SEARCH_H, SHORT_SHARES + longest
    return SEARCH_DX_2D, SEARCH_H, longest


def candidates(kind, dxs, hs, shares) -> list[tuple[dict, tuple, tuple]]:
    """(method, CFL shares, dxs) :func:`suggest` tries on a scene of ``kind``: every kernel at each h of ``hs``
    (standard SPH, Verlet) with ``shares``, then the high-order methods (pcabench/predict/methods.py) with their
    own shares (and near a body their own dxs). Near a body a kernel with a negative lobe is tried corrected only:
    uncorrected, the Laguerre-Gauss kernel's ghosts grow (h 1.5 dx, 4h: blew up near t = 2 s at every CFL tried)
    or add three times the bulk's error (h = dx, CFL 1.14, rings, dx 0.04: 0.223 against 0.077 predicted)."""
    standard = [
        ({"kernel": kern, "h_factor": h}, shares, dxs)
        for kern, h in itertools.product(kernel_names(), hs)
        if not (kind.body and kernel_named(kern).negative_lobe)
    ]
    fine = HIGH_ORDER_DX_BODY if kind.body else dxs
    return standard + [(m, SHORT_SHARES + shares[-1:], fine) for m in high_order_methods()]


PROGRESS_S = 2.0  # s between the search's progress lines on stderr


def suggest(
    error: float,
    t_end: float,
    model: str = "linear",
    scene: str = DEFAULT_SCENE,
    problem: tuple[str, ...] = (),
    domain: str | None = None,
) -> dict:
    """From the prediction: the cheapest configuration of a small grid (:func:`search_grid`, and the high-order
    methods: :func:`candidates`) predicted to reach ``error`` at ``t_end`` on ``scene`` (cost ~ particles x steps
    x neighbours x the step's sweeps: on the thinnest strip where a strip serves the scene, else on its own
    domain), the one predicted closest to it, and the paper configuration's dx. A scene with a body is predicted
    with its wall exact (the bulk's dispersion alone: a lower bound of a run's error), a corrected method with
    cut cells (solvers/boundaries/bodies/cut.py: the ghosts' walls grow with a corrected negative-lobe kernel); the
    search says how far it is on stderr, every 2 s. The study command it names makes runs that advise, asked
    again, reads: ``problem`` (the study options of the problem asked about: ``--open x``, ``--mach 0.1``) goes into
    it, and a strip only where ``domain`` is not ``full``."""
    kind = scene_kind(scene)
    dxs, hs, shares = search_grid(kind, model)
    best, paper, closest = None, None, None
    methods = candidates(kind, dxs, hs, shares)
    said = [time.monotonic()]  # when progress was last printed: every PROGRESS_S (a quick search prints none)
    for i, (method, method_shares, method_dxs) in enumerate(methods, 1):
        corrected = method.get("correction", "none") != "none"
        wall = CUT_WALL if kind.body and corrected else {}
        # the prediction's target (a body's: with its wall's margin)
        asked = error * ((CUT_MARGIN if corrected else BODY_MARGIN) if kind.body else 1.0)
        if time.monotonic() - said[0] >= PROGRESS_S:
            said[0] = time.monotonic()
            label = Method.of(method).numerics
            print(
                f"advise: predicting {scene} with method {i}/{len(methods)} ({label}) ...", file=sys.stderr, flush=True
            )
        for share in method_shares:
            tried: dict = {}
            trial_at = functools.partial(_trial, kind, scene, t_end, {**method, **wall}, share, tried)
            order = sorted(method_dxs, reverse=True)  # coarse to fine: the first that reaches is the cheapest
            finest = next((found for found in map(trial_at, order[::-1]) if found is not None), None)
            if finest is None or finest[1].predicted_error > asked:  # not even at the finest dx: none coarser
                if finest is not None and (closest is None or finest[1].predicted_error < closest[1].predicted_error):
                    closest = finest
                continue
            for dx in order:
                found = trial_at(dx)
                if found is None:
                    continue
                trial, p = found
                if closest is None or p.predicted_error < closest[1].predicted_error:
                    closest = (trial, p)
                if p.predicted_error > asked:
                    continue
                # particles x steps x neighbours: a strip's particles go as 1 / dx, a plane's as its square, a
                # cube's as its cube, and the neighbours as the cutoff's disc or ball
                cost = (1 / dx) ** (1 if kind.strip else kind.dims) * trial.n_steps * (trial.cutoff / dx) ** kind.dims
                cost *= step_weight(trial)
                if best is None or cost < best[0]:
                    best = (cost, trial, p)
                break
    for dx in sorted(dxs, reverse=True):  # the coarsest dx at which the paper's configuration reaches the error
        try:
            candidate = Scene(dx=dx, name=scene, t_end=t_end, model="linear")
        except Exception:  # noqa: BLE001 - a dx the scene refuses (its wall inside the support) is not searched
            continue
        if kind.predict_headline(candidate).predicted_error <= error:
            paper = candidate
            break
    out = {
        "paper_dx": None if paper is None else paper.dx,
        "smallest_dx_searched": min(dxs),
        "note": "predicted from the dispersion relation of the linear part"
        + (
            f", the wall exact, asked for {BODY_MARGIN:g} of the target with ghosts and {CUT_MARGIN:g} with cut cells "
            "(the wall's own error)"
            if kind.body
            else ""
        ),
    }
    if closest is not None:
        c, p = closest
        out["closest"] = dict(**method_fields(c), dx=c.dx, predicted_error=p.predicted_error)
    if best is not None:
        _, s, p = best
        out.update(
            **method_fields(s),
            dx=s.dx,
            predicted_error=p.predicted_error,
            stable_cfl=stable_cfl(s),
            **({} if kind.strip else {"n_particles": s.n_particles, "steps": s.n_steps}),
            study=shlex.join(
                [
                    "pcabench",
                    "study",
                    "--solver",
                    DEFAULT_SOLVER,
                    "--model",
                    model if scene_kind(scene).has_isothermal else "linear",  # else no lagrangian run is scored
                    "--t-end",
                    f"{t_end:g}",
                    *([] if scene == DEFAULT_SCENE else ["--scene", scene]),
                    *problem,
                    *(["--strip"] if kind.strip and domain != "full" else []),
                    *method_words(s),
                    "--dx",
                    f"{s.dx:g}",
                    # a body's dx is fine already, and half a 3D dx is eight times its particles: its own run only
                    *([] if kind.body or kind.dims == 3 else [f"{s.dx / 2:g}"]),
                ]
            ),
        )
    return out


def _trial(kind, scene: str, t_end: float, method: dict, share: float, tried: dict, dx: float):
    """(scene, prediction) of ``method`` at ``dx`` and ``share`` of its stable CFL, kept in ``tried``; None where
    Scene refuses the combination or the method grows at any step."""
    if dx not in tried:
        try:
            base = Scene(dx=dx, name=scene, t_end=t_end, model="linear", **method)
        except Exception:  # noqa: BLE001 - a combination Scene refuses is not a candidate
            tried[dx] = None
            return None
        limit = stable_cfl(base)  # predicted, or lower where long runs of the scene measured it
        if not limit > 0:
            tried[dx] = None
            return None
        trial = base.replace(cfl=round(share * limit, 2))
        tried[dx] = (trial, kind.predict_headline(trial))
    return tried[dx]


def method_fields(scene: Scene) -> dict:
    """A suggested scene's method as advise reports it: kernel, h/dx, CFL, its label, and the cutoff, integrator,
    correction and boundary method where they are not the defaults."""
    out = {"kernel": scene.kernel, "h_factor": scene.h_factor, "cfl": scene.cfl, "method": Method.of(scene).label}
    for name in ("cutoff_factor", "integrator", "correction", "boundary_method"):
        if getattr(scene, name) != Scene.default(name) and (name != "cutoff_factor" or truncated(scene.kernel)):
            out[name] = getattr(scene, name)
    return out


def method_words(scene: Scene) -> list[str]:
    """The study options of a suggested scene's method (each one away from its default)."""
    words = ["--kernel", scene.kernel, "--h-factor", f"{scene.h_factor:g}", "--cfl", f"{scene.cfl:g}"]
    fields = method_fields(scene)
    for name, option in (
        ("cutoff_factor", "--cutoff"),
        ("integrator", "--integrator"),
        ("correction", "--correction"),
        ("boundary_method", "--boundary-method"),
    ):
        if name in fields:
            value = fields[name]
            words += [option, f"{value:g}" if isinstance(value, float) else str(value)]
    return words
