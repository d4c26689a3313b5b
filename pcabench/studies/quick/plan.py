"""The default preset: every table and figure at small N, a few minutes on a laptop CPU."""

from __future__ import annotations

from pcabench.spec import RunSpec
from pcabench.studies.preset import Preset, spec_of
from pcabench.studies.protocols import STABILITY_DX
from solvers import Scene

QUICK_CFL = (0.2, 2.0, 5.0, 7.0)  # the quick map: stable, stable, just past the predicted 4.97, far past it


def quick() -> list[RunSpec]:
    """A few minutes on a laptop CPU: every table and figure at small N."""
    runs = []
    # Table 4/5, Figs. 10, 11, 13: the paper's scene (lagrangian, full domain)
    runs += [spec_of(dx=dx, steps=20) for dx in (1.0, 0.5, 0.25)]
    # Fig. 9: all-pair against linked list (0.125 is predicted past the budget and skipped)
    runs += [spec_of("allpair-cpu", dx=dx, steps=20) for dx in (1.0, 0.5, 0.25, 0.125)]
    # Fig. 8 at a fixed physical time and at the paper's 100 steps, on the strip
    for model in ("linear", "lagrangian"):
        for dx in (0.4, 0.2, 0.1) + ((0.05,) if model == "linear" else ()):
            runs.append(spec_of(dx=dx, t_end=10.0, model=model, strip=True))
        for dx in (0.4, 0.2, 0.1):
            runs.append(spec_of(dx=dx, steps=100, model=model, strip=True))
    # The cost of each simplification: fixed particles, float32, and the full domain
    for dx in (0.2, 0.1):
        runs.append(spec_of(dx=dx, t_end=10.0, model="fixed", strip=True))
        runs.append(spec_of(dx=dx, t_end=10.0, model="linear", precision="float32", strip=True))
    runs.append(spec_of(dx=0.2, t_end=10.0, model="linear"))
    runs.append(spec_of(dx=0.2, t_end=10.0, model="lagrangian"))
    # The stability map: Verlet on the stability scene at a few CFLs, up to past its limit
    runs += [spec_of(dx=STABILITY_DX, t_end=10.0, model="linear", strip=True, cfl=cfl) for cfl in QUICK_CFL]
    # Another scene: the 2D acoustic pulse, linear and lagrangian, at the default amplitude and a small one
    runs += [
        spec_of(name="acoustic-pulse", dx=0.5, t_end=10.0, model=model, mach=mach)
        for mach in (Scene.default("mach"), 0.005)
        for model in ("linear", "lagrangian")
    ]
    return runs


QUICK = Preset(
    "quick",
    quick,
    120.0,
    flag="quick",
    help="every table and figure at small N ({size}; 2 minutes here; default)",
    order=10,
)
