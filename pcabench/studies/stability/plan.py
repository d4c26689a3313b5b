"""Where methods fail: the stability presets (``--stability short``, ``--stability long``)."""

from __future__ import annotations

from pcabench.spec import ALL_CORES, RunSpec
from pcabench.studies.preset import Preset, spec_of
from pcabench.studies.protocols import LONG_MODELS, LONG_SCENES, LONG_T_END, STABILITY_DX

STABILITY_CFL = (0.1, 0.2, 0.5, 1.0, 2.0, 2.5, 3.0, 4.0, 4.5, 5.0, 5.5, 6.0, 7.0)
STABILITY_H = (1.0, 1.3)  # h/dx beside Scene's default
# Above this relative RMS error a run that stayed bounded is classed inaccurate: twice the
# error of Verlet at CFL 0.2 on the stability scene (10 % at dx = 0.25, t = 10 s).
INACCURATE_ABOVE = 0.20
# The long-run stability preset (LONG_SCENES, LONG_T_END, LONG_MODELS: pcabench/studies/protocols.py) at these
# CFLs:
LONG_CFL = (4.4, 4.5, 4.6, 4.7, 4.75, 4.8, 4.9, 5.0)


def stability() -> list[RunSpec]:
    """Where methods fail: CFL x integrator, CFL x h/dx, run length, float32 at small dx."""
    runs = []
    base = dict(dx=STABILITY_DX, model="linear", strip=True)
    for integrator in ("verlet", "rk2", "kdk1", "euler"):
        for cfl in STABILITY_CFL:
            runs.append(spec_of(t_end=10.0, integrator=integrator, cfl=cfl, **base))
    for h_factor in STABILITY_H:
        for cfl in STABILITY_CFL:
            runs.append(spec_of(t_end=10.0, cfl=cfl, h_factor=h_factor, **base))
    for cfl in (0.2, 1.0, 4.0):
        runs.append(spec_of(t_end=10.0, cfl=cfl, precision="float32", **base))
    # run length: to t = 30 s (the pulse is then 10 m short of the free right edge)
    for integrator in ("verlet", "rk2", "kdk1", "euler"):
        runs.append(spec_of(t_end=30.0, integrator=integrator, cfl=0.2, **base))
    runs.append(spec_of(t_end=30.0, cfl=4.0, **base))
    # float32 against float64 at the paper's protocol down to its smallest dx
    for dx in (0.04, 0.01, 0.004):
        for precision in ("float64", "float32"):
            runs.append(
                spec_of(threads=ALL_CORES, dx=dx, steps=100, model="lagrangian", precision=precision, strip=True)
            )
    return runs


def stability_long() -> list[RunSpec]:
    """Each model of the paper's method at the CFLs around its predicted limit, to t = 300 s (dx = 0.25), on
    each scene of LONG_SCENES."""
    return [
        spec_of(name=scene, dx=STABILITY_DX, t_end=LONG_T_END, model=model, cfl=cfl, **setting)
        for scene, setting in LONG_SCENES.items()
        for model in LONG_MODELS
        for cfl in LONG_CFL
    ]


STABILITY = Preset(
    "stability",
    stability,
    120.0,
    flag="stability",
    choice="short",
    help="CFL x integrator x h/dx, run length and float32, the stability map ({size})",
    order=30,
)
STABILITY_LONG = Preset(
    "stability-long",
    stability_long,
    300.0,
    flag="stability",
    choice="long",
    help="each model at CFL 4.4-5 to t = 300 s, the moving models' own limit ({size})",
    order=31,
    scored=False,  # runs to t = 300 s to measure a stable step, not an error
)
