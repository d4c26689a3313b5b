"""What several studies share (the preset layer, below every study's plan): the stability scene's dx, the long
runs' scenes, end time and models (the stability study's, repeated at walls and open edges so that each compares
one to one), and the fronts' end time (the walls' accuracy runs end there too)."""

from __future__ import annotations

# The stability preset's scene: the design's dx = 0.25 on a strip, the linear model
# (exactly the linear wave equation, so growth is the integrator's, not the physics').
STABILITY_DX = 0.25
# The long runs: the moving models' own limit, where their nonlinear terms (and, with free ends, the particles at the
# edges) can grow what the linear part keeps bounded, measured over runs long enough for round-off to grow. Two
# scenes: the paper's pulse on the stability strip, free ends in x (at Mach 0.01, so that it does not break before
# t = 300 s: 350 s; the pulse leaves by the free end long before, so that the run then tests the edges); and the
# 2D acoustic pulse in a 20 m periodic square, where the sound never leaves and never breaks. The linear model runs
# beside the moving ones on each: the control whose limit the prediction knows exactly.
LONG_SCENES = {
    "plane-pulse": dict(strip=True, mach=0.01),
    "acoustic-pulse": dict(x_min=-10.0, x_max=10.0, y_min=-10.0, y_max=10.0),
}
LONG_T_END = 300.0  # s: about 250 steps at CFL 4.7, dx 0.25
LONG_MODELS = ("linear", "fixed", "lagrangian")
FRONT_T_END = 10.0  # s: the fronts' runs (and the walls' accuracy runs) end here
