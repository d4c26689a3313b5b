"""High-order SPH (``--high-order``): the kernel gradient correction, the fourth-order Laguerre-Gauss kernel and
RK4 (design.md, 1c; solvers/corrections/) against standard SPH on the plane pulse and the 2D pulse: the orders at
fixed h / dx, the time to an accuracy, and the stable step over long runs. The cylinder's runs of the same method
are the cylinder study's part 7 (``--cylinder``)."""

from __future__ import annotations

from pcabench.studies.preset import Preset, spec_of
from solvers import Scene
from solvers.kernels import kernel_named, truncated

HIGH_ORDER = "high-order"
HIGH_ORDER_T_END = 10.0
# 1. The plane pulse (linear, t = 10 s, a 5 m strip, or the thinnest the support allows at coarse dx): each
# built-in kernel at a fixed h / dx with and without the correction, Verlet at the paper's CFL 0.2 (its step's
# error small beside the space's), at dx 0.4, 0.2, 0.1; and the high-order method, Laguerre-Gauss at
# h = 1.5 dx cut at 4 h, with RK4 at CFL 1, corrected and not.
PLANE_DX = (0.4, 0.2, 0.1)
PLANE_STRIP = 5.0  # m
KERNELS = (
    {"kernel": "gaussian", "h_factor": 2.13},
    {"kernel": "gaussian", "h_factor": 1.0},
    {"kernel": "wendland-c2", "h_factor": 2.0},
    {"kernel": "wendland-c4", "h_factor": 1.6},
    {"kernel": "laguerre-gauss", "h_factor": 1.5, "cutoff_factor": 4.0},
    {"kernel": "laguerre-gauss-6", "h_factor": 1.5, "cutoff_factor": 5.0},
)
METHOD = {"kernel": "laguerre-gauss", "h_factor": 1.5, "cutoff_factor": 4.0}  # the high-order method's kernel
RK4 = {"integrator": "rk4", "cfl": 1.0}
# The sixth-order Laguerre-Gauss kernel (issue 67), cut at 5 h where it keeps its order, corrected, with RK4 at
# CFL 0.5 (sixth order in space: at CFL 1 RK4's fourth-order phase error is its largest at dx 0.1) on the plane
# pulse, and at CFL 1 on the 2D pulse.
METHOD6 = {"kernel": "laguerre-gauss-6", "h_factor": 1.5, "cutoff_factor": 5.0, "correction": "gradient"}
RK4_SHORT = {"integrator": "rk4", "cfl": 0.5}
# 2. The 2D pulse (linear, t = 10 s, its 40 m periodic square) at dx 0.5 and 0.25: the paper's method, the
# high-order kernel corrected with Verlet at CFL 0.5 and with RK4 at CFL 1.
PULSE_DX = (0.5, 0.25)
# 3. The stable step over long runs (plane pulse, dx 0.25, t = 100 s, Mach 0.01), linear and lagrangian (whether
# the kernel's negative lobe or the correction breaks moving particles), of every corrected method advise's search
# names (pcabench/predict/methods.py high_order_methods: each kernel at h = 1.5 dx, Verlet and RK4). The free ends
# lower it below the periodic lattice's prediction: there a particle has half its neighbours, its L is about
# twice the interior's, and so is its highest frequency. Measured here first (2026-12-06, intel-xeon, one linear
# run at each CFL, `pcabench study --strip --dx 0.25 --t-end 100 --mach 0.01 --h-factor 1.5 --correction gradient
# --kernel K --integrator I --cfl ...`): Laguerre-Gauss Verlet bounded at 0.5 to 1.4 and blew up at 1.5 (step 20),
# RK4 bounded to 1.8, blew up at 2.1 (step 39) and 2.4 (prediction 2.04 and 2.88); Gaussian (cut at 4 h) Verlet
# bounded to 2.2, blew up at 2.4 (step 19; prediction 3.50), RK4 3.0 and 3.3 (step 41; 4.95); Wendland C2 Verlet
# 1.6 and 1.8 (step 22; 2.66), RK4 2.4 and 2.6 (step 26; 3.76); Wendland C4 Verlet 1.4 and 1.6 (step 19; 2.31),
# RK4 2.0 and 2.2 (step 44; 3.26): 0.6 to 0.7 of the prediction each. The study brackets those limits.
LONG_DX = 0.25
LONG_T_END = 100.0
LONG_MACH = 0.01  # the pulse must not break before LONG_T_END (at Mach 0.05 it does at 70 s)
LONG_CFLS = {  # (kernel, integrator): (the largest bounded CFL, the smallest that blew up)
    ("laguerre-gauss", "verlet"): (1.4, 1.5),
    ("laguerre-gauss", "rk4"): (1.8, 2.1),
    ("gaussian", "verlet"): (2.2, 2.4),
    ("gaussian", "rk4"): (3.0, 3.3),
    ("wendland-c2", "verlet"): (1.6, 1.8),
    ("wendland-c2", "rk4"): (2.4, 2.6),
    ("wendland-c4", "verlet"): (1.4, 1.6),
    ("wendland-c4", "rk4"): (2.0, 2.2),
    # measured 2026-12-07 (amd-epyc, the same command with --kernel laguerre-gauss-6 --cutoff 5): Verlet bounded to
    # 1.0, blew up at 1.1 (step 146; lagrangian 301), RK4 1.5 and 1.6 (step 61; 175), against the prediction's
    # 1.51 and 2.14
    ("laguerre-gauss-6", "verlet"): (1.0, 1.1),
    ("laguerre-gauss-6", "rk4"): (1.5, 1.6),
}
LONG_H = 1.5
LONG_CUTOFF = 4.0  # a truncated kernel's that states no order_cutoff (the Gaussian's), as the search has it


def plane(dx: float, **method) -> object:
    """A plane-pulse run of ``method`` at ``dx`` on the PLANE_STRIP strip (or the thinnest the support allows)."""
    strip = max(
        PLANE_STRIP, Scene.thinnest_strip(dx, method.get("cutoff_factor"), method["h_factor"], method["kernel"])
    )
    return spec_of(dx=dx, strip_height=strip, model="linear", t_end=HIGH_ORDER_T_END, **method)


def high_order() -> list:
    """The high-order study (module docstring), smallest runs first within each part."""
    runs = [
        plane(dx, **kernel, correction=correction)
        for dx in PLANE_DX
        for kernel in KERNELS
        for correction in ("none", "gradient")
    ]
    runs += [plane(dx, **METHOD, **RK4, correction=c) for dx in PLANE_DX for c in ("none", "gradient")]
    runs += [plane(dx, **METHOD6, **RK4_SHORT) for dx in PLANE_DX]
    pulse = {"name": "acoustic-pulse", "model": "linear", "t_end": HIGH_ORDER_T_END}
    for dx in PULSE_DX:
        runs.append(spec_of(dx=dx, **pulse))
        runs.append(spec_of(dx=dx, **pulse, **METHOD, correction="gradient", cfl=0.5))
        runs.append(spec_of(dx=dx, **pulse, **METHOD, correction="gradient", **RK4))
        runs.append(spec_of(dx=dx, **pulse, **METHOD6, **RK4))
    for (kernel, integrator), cfls in LONG_CFLS.items():
        cut = {"cutoff_factor": kernel_named(kernel).order_cutoff or LONG_CUTOFF} if truncated(kernel) else {}
        base = {"kernel": kernel, "h_factor": LONG_H, **cut, "correction": "gradient", "integrator": integrator}
        for model in ("linear", "lagrangian"):
            runs += [
                spec_of(dx=LONG_DX, model=model, mach=LONG_MACH, t_end=LONG_T_END, cfl=cfl, strip=True, **base)
                for cfl in cfls
            ]
    return runs


HIGH_ORDER_PRESET = Preset(
    HIGH_ORDER,
    high_order,
    600.0,
    flag="high-order",
    help="high-order SPH: the kernel gradient correction, the Laguerre-Gauss kernel and RK4 against standard SPH "
    "on the plane pulse and the 2D pulse (orders at fixed h/dx, time to an accuracy, the stable step over long "
    "runs) ({size})",
    order=58,
)
