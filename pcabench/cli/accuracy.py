"""``pcabench accuracy``: the error and largest stable step the dispersion relation predicts, no simulation."""

from __future__ import annotations

from pcabench import jsonout
from pcabench.cli.options import ACCURACY_OPTIONS, check_wall_option, domain_of
from pcabench.machine import memory
from pcabench.spec import OptionError
from solvers import (
    DEFAULT_SCENE,
    Scene,
    scene_kind,
)


def cmd_accuracy(args) -> int:
    from solvers.reference.dispersion import predict

    given = {key: getattr(args, opt) for opt, key in ACCURACY_OPTIONS.items() if getattr(args, opt) is not None}
    check_wall_option([given.get("name", DEFAULT_SCENE)], "x_max" in given)
    scene = Scene(  # the prediction builds the scene's lattice: bounded by this process's memory, as a run is
        dx=args.dx,
        t_end=args.t_end if args.t_end is not None else scene_kind(given.get("name", DEFAULT_SCENE)).t_end,
        model="linear",
        memory_limit_bytes=memory.available_memory_bytes(),
        probes=tuple(getattr(args, "probe", None) or ()),  # checked as a run checks them (in the body: refused)
        **given,
        **domain_of(args),
    )
    from pcabench.execute.progress import Heartbeat
    from solvers.scenes.base import NoPrediction

    try:
        with Heartbeat(f"pcabench accuracy: predicting {scene.n_particles:,} particles"):  # a 3D lattice: a minute
            p = predict(scene)
    except NoPrediction as exc:
        raise OptionError(str(exc)) from None
    past = p.stable_cfl <= scene.cfl  # at or past the largest stable step (pcabench/predict/stability.py)
    if args.json:
        known = {"known_failure": scene.known_failure, "cautions": list(scene.cautions)}  # ("" / [] where none)
        jsonout.emit(
            jsonout.dumps({"scene": scene.as_dict(), **p.as_dict(), "past_stable_cfl": past, **known}, sort_keys=True)
        )
        return 0
    for caution in scene.cautions:  # the prediction is of the interior's operators: it cannot see a wall blow up
        print(
            f"warning: {caution}"
            + (". The prediction below assumes the run holds." if caution == scene.known_failure else "")
        )
    if past:
        print(
            f"CFL {scene.cfl:g} is past the largest stable CFL {p.stable_cfl:.3g} of {scene.integrator}: a run "
            "grows without bound (the predicted error is that growth)"
            if p.stable_cfl > 0
            else f"{scene.integrator} grows at every CFL: a long enough run grows without bound"
        )
    print(
        f"{scene.describe()}\n"
        f"predicted {scene.kind.headline(p.t_end)}: {p.predicted_error:.4g} "
        f"(max error {p.predicted_me:.3g} {'m/s' if scene.kind.primary == 'u' else 'kg/m^3'})\n"
        f"largest stable CFL (dt c0 / dx) for {scene.integrator}: {p.stable_cfl:.4g}"
        f"{' (grows at any step)' if p.stable_cfl == 0 else ''}\n"
        f"phase speed error at k = 1/w: lattice {100 * p.lattice_phase_error:+.3f} %, with the step "
        f"{100 * p.step_phase_error:+.3f} %"
        + (
            ""
            if p.lattice_phase_error_diagonal is None
            else f" along the lattice's axis; along its diagonal {100 * p.lattice_phase_error_diagonal:+.3f} % and "
            f"{100 * p.step_phase_error_diagonal:+.3f} %"
        )
    )
    for name, value in (p.measures or {}).items():
        print(f"predicted {name.replace('_', ' ')}: {value:.4g}")
    return 0


# advise's numbers printed to 3 significant digits (the scene's own parameters stay exact)
ROUNDED_AS_PRINTED = (
    "error",
    "seconds",
    "stable_cfl",
    "paper_seconds",
    "paper_error",
    "speedup_over_paper",
    "not_advised",
)
