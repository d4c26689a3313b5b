"""The 3D study's runs (``pcabench study --three-d``), smallest first.

1. The 3D pulse in its 16 m periodic cube, linear, t = 5 s: standard SPH (Wendland C2 at h = 1.3 dx, 80
   neighbours, Verlet CFL 0.5) at dx 1, 0.5, 0.25; the paper's method (the Gaussian at h = 2.13 dx cut at 3 h,
   1,093 neighbours, CFL 0.2) at dx 0.5; the high-order method (Laguerre-Gauss at h = 1.5 dx cut at 4 h,
   gradient-corrected, 894 neighbours, Verlet CFL 0.5) at dx 0.5 and 0.25 (262,144 particles: the issue's
   target, at most 1e-3 and order 3.5).
2. The cost of a pair, serial, the gather loop, ten steps each, ns per particle-neighbour-step: the 3D pulse at
   dx 0.5 (32,768 particles) beside the 2D pulse on a square of the same particle count (dx 0.125 on 22.625 m:
   32,761 particles), with one kernel in both: Wendland C2 at about 80 neighbours in both (h = 1.3 dx in 3D,
   2.5 dx in 2D), and the fourth-order kernel (Laguerre-Gauss at h = 1.5 dx cut at 4 h, uncorrected: 894
   neighbours in 3D, 108 in 2D).
3. The rigid sphere (``--scene sphere``), the high-order method, linear, t = 4 s, the PML beyond its faces (the
   issue's scene): the probes A, B, C over 1.5 <= t <= 4 s against the exact series at dx 0.125 and 0.1, with the
   weak wall's staircase and with its cut cells (``--boundary-method cut``).

``pcabench study --three-d fine`` is the issue's target run on its own: the sphere at dx 0.05 with cut cells and
the PML (1,815,848 particles with the layer, 160 steps), on every core.

``pcabench study --three-d long`` is where methods fail in 3D: long runs at CFLs either side of each method's
stable step, not scored (``three_d_long``).
"""

from __future__ import annotations

from pcabench.spec import ALL_CORES
from pcabench.studies.preset import Preset, spec_of

THREE_D = "three-d"
THREE_D_FINE = "three-d-fine"
THREE_D_LONG = "three-d-long"
T_END = 5.0
PULSE = {"name": "acoustic-pulse-3d", "model": "linear", "t_end": T_END}
STANDARD = {"kernel": "wendland-c2", "h_factor": 1.3, "cfl": 0.5}
PAPER = {"cfl": 0.2}  # the paper's method: Scene's defaults (the Gaussian at h = 2.13 dx cut at 3 h) and its CFL
HIGH_ORDER = {"kernel": "laguerre-gauss", "h_factor": 1.5, "cutoff_factor": 4.0, "correction": "gradient", "cfl": 0.5}
STANDARD_DX = (1.0, 0.5, 0.25)
PAPER_DX = (0.5,)
HIGH_ORDER_DX = (0.5, 0.25)
# the pair's cost: the same kernel in 2D and 3D, the same particle count, ten steps; Wendland C2 at about 80
# neighbours in both, the fourth-order kernel at its own h
COST_STEPS = 10
COST_3D = {"name": "acoustic-pulse-3d", "dx": 0.5}
COST_2D = {"name": "acoustic-pulse", "dx": 0.125}
COST_KERNELS = (
    ({"kernel": "wendland-c2", "h_factor": 1.3}, {"kernel": "wendland-c2", "h_factor": 2.5}),
    ({"kernel": "laguerre-gauss", "h_factor": 1.5, "cutoff_factor": 4.0},) * 2,
)
COST_2D_SIDE = 22.625  # m: 181 x 181 = 32,761 particles at dx 0.125, beside the cube's 32,768
# the scene: the PML beyond the faces (the sponge's reflection from the +x and +y faces reaches A at t = 3.35 s,
# inside its window: measured at dx 0.1, A's error after t = 3.2 s against the run's prediction 0.130 with the
# sponge, 0.0116 with the PML)
SPHERE = {"name": "sphere", "model": "linear", "t_end": 4.0, "absorber": "pml"}
SPHERE_DX = (0.125, 0.1)
# the sphere's walls: the weak one's staircase and its cut cells (the corrected method's default since 2026-12-07)
SPHERE_WALLS = ({"boundary_method": "weak"}, {"boundary_method": "cut"})
SPHERE_FINE_DX = 0.05  # the target: at most 2 % at the probes
# Where methods fail in 3D (``three_d_long``). The 3D pulse in a periodic cube of 18 m at dx 1 (5,832 particles: the
# fourth-order kernel's three cutoffs), linear (the cubic lattice's prediction is exact for it) and, for the
# high-order method with Verlet, lagrangian; each method at a CFL below its predicted limit and one past it, run for
# 200 to 270 steps (round-off's 37 e-foldings take under 150 steps 1 % past Wendland C2's limit, 3 % past the
# fourth-order kernel's): (method, CFLs, t_end s).
LONG_CUBE = {"name": "acoustic-pulse-3d", "dx": 1.0, "x_min": -9.0, "x_max": 9.0, "y_min": -9.0, "y_max": 9.0,
             "z_min": -9.0, "z_max": 9.0}  # fmt: skip
LONG_PULSE = (
    # standard SPH: the cubic lattice's limit 2.28 lies below the square's 2.35, so 2.3 is stable in 2D only
    (STANDARD, ("linear",), (2.25, 2.3), 600.0),
    (HIGH_ORDER, ("linear", "lagrangian"), (2.0, 2.1), 500.0),  # Verlet: the limit 2.04
    ({**HIGH_ORDER, "integrator": "rk4"}, ("linear",), (2.8, 3.0), 500.0),  # RK4: the limit 2.88
)
# The sphere's wall (cut cells, a free end: pcabench/predict/stability.py ``free_ended``) with the high-order method:
# the sphere, pulse and layer at dx 0.125 (four particles a radius, the coarsest the scene allows) in a
# cube of 3.2 m (the pulse's centre at 1 m, 1.5 widths from the faces; 54,872 particles with the PML), to t = 30 s
# (171 Verlet steps at CFL 1.4, 109 RK4 steps at 2.2); Verlet and RK4 either side of the free end's limits (1.5 and
# 2.1, measured_limits.csv) and Verlet up to 1.9, where the cut wall blew up by hand: (integrator, CFLs).
LONG_SPHERE = {**SPHERE, "dx": 0.125, "t_end": 30.0, "pulse_center": 1.0, "boundary_method": "cut",
               "x_min": -1.6, "x_max": 1.6, "y_min": -1.6, "y_max": 1.6, "z_min": -1.6, "z_max": 1.6}  # fmt: skip
LONG_SPHERE_CFLS = (("verlet", (1.4, 1.5, 1.7, 1.9)), ("rk4", (2.2, 2.5)))


def three_d() -> list:
    """The 3D study (module docstring), smallest first within each part."""
    runs = [spec_of(dx=dx, **PULSE, **STANDARD) for dx in STANDARD_DX]
    runs += [spec_of(dx=dx, **PULSE, **PAPER) for dx in PAPER_DX]
    runs += [spec_of(dx=dx, **PULSE, **HIGH_ORDER) for dx in HIGH_ORDER_DX]
    half = 0.5 * COST_2D_SIDE
    square = {"x_min": -half, "x_max": half, "y_min": -half, "y_max": half}
    cost = {"model": "linear", "cfl": 0.5, "steps": COST_STEPS, "pair_loop": "gather"}
    for three, two in COST_KERNELS:
        runs += [spec_of(**COST_3D, **three, **cost), spec_of(**COST_2D, **two, **square, **cost)]
    runs += [spec_of(dx=dx, **SPHERE, **HIGH_ORDER, **wall) for wall in SPHERE_WALLS for dx in SPHERE_DX]
    return runs


def three_d_fine() -> list:
    """The sphere at the issue's dx with cut cells, on every core (module docstring)."""
    return [spec_of(dx=SPHERE_FINE_DX, threads=ALL_CORES, **SPHERE, **HIGH_ORDER, **SPHERE_WALLS[-1])]


def three_d_long() -> list:
    """Where methods fail in 3D: long runs either side of each method's stable CFL on the periodic cube and at the
    sphere's wall (module docstring)."""
    runs = [
        spec_of(**{**PULSE, **LONG_CUBE, **method, "model": model, "cfl": cfl, "t_end": t_end})
        for method, models, cfls, t_end in LONG_PULSE
        for model in models
        for cfl in cfls
    ]
    base = {**LONG_SPHERE, **{k: v for k, v in HIGH_ORDER.items() if k != "cfl"}}
    runs += [spec_of(**base, integrator=integrator, cfl=cfl) for integrator, cfls in LONG_SPHERE_CFLS for cfl in cfls]
    return runs


THREE_D_PRESET = Preset(
    THREE_D,
    three_d,
    3600.0,
    flag="three-d",
    choice="coarse",
    help="sound in 3D: the 3D pulse's error against dx with standard SPH, the paper's method and the high-order "
    "method, a pair's cost in 3D against 2D for two kernels, the rigid sphere with the high-order method ({size}; "
    "about 20 min here, serial)",
    order=59,
)

THREE_D_FINE_PRESET = Preset(
    THREE_D_FINE,
    three_d_fine,
    4 * 3600.0,
    flag="three-d",
    choice="fine",
    help="the rigid sphere at dx 0.05 (the issue's target: 1.5 million particles), the high-order method, cut "
    "cells, every core (about 1 h on two cores here)",
    order=59.5,
)

THREE_D_LONG_PRESET = Preset(
    THREE_D_LONG,
    three_d_long,
    1200.0,
    flag="three-d",
    choice="long",
    help="where methods fail in 3D: long runs either side of each method's stable CFL on the periodic cube (the "
    "cubic lattice's limits) and at the sphere's wall ({size}; about 20 min here, serial)",
    order=59.7,
    scored=False,  # runs long to measure a stable step, not an error
)
