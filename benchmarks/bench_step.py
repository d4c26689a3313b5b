"""Time one step and each stage (SNP, PI, SU) of every CPU solver, by precision and particle count.

Compilation and the first step happen in ``setup``, outside the timed region
(``bench_jit.py`` times compilation on its own). All-pair stops at 16K
particles; ``PCABENCH_BENCH_LARGE=1`` adds 100K and 400K for the linked list.
"""

from .common import Prepared, StageBenchmarks, Unsupported, cpu_dx, solver_names, thinnest_strip


class TimeStep(StageBenchmarks):
    params = [solver_names("cpu"), ["float64", "float32"], list(cpu_dx())]
    param_names = ["solver", "precision", "dx"]
    timeout = 300
    min_run_count = 3

    def setup(self, solver, precision, dx):
        try:
            self.p = Prepared(solver, precision, dx)
        except Unsupported as exc:
            raise NotImplementedError(str(exc)) from None


class TimeStepThreads:
    """The multi-threaded linked list on every core numba may use (the honest CPU peer)."""

    params = [["float64", "float32"], list(cpu_dx())]
    param_names = ["precision", "dx"]
    timeout = 300

    def setup(self, precision, dx):
        import numba

        self.p = Prepared("linkedlist-cpu", precision, dx, threads=numba.config.NUMBA_NUM_THREADS)

    def time_step(self, *_):
        self.p.step()


# A walled scene and its free twin on the same lattice (same N, same box): what a step pays for the wall's
# mirror particles (extra pairs in the wall's column of cells only). The 2D pulse in the 20 x 20 m box of
# pulse-wall (walls at both x ends) against the x-periodic acoustic-pulse in that box; the plane pulse on
# plane-wall's x range and strip (a wall at the right end) against plane-pulse's free ends there.
WALL_DX = 0.25  # 6,400 particles in the box, 1,280 on the strip
WALL_PAIRS = {
    "pulse-wall": {"x_min": -14.0, "x_max": 6.0, "y_min": -10.0, "y_max": 10.0},
    "acoustic-pulse": {"x_min": -14.0, "x_max": 6.0, "y_min": -10.0, "y_max": 10.0},
    "plane-wall": {"x_min": -10.0, "x_max": 6.0, "strip": True},  # strip: the thinnest strip at WALL_DX
    "plane-pulse": {"x_min": -10.0, "x_max": 6.0, "strip": True},
}


class TimeWallStep:
    """One step of linkedlist-cpu (float64, lagrangian, serial) with and without a rigid wall at the same N
    (:data:`WALL_PAIRS`), by pair loop; commits before the walls skip the walled scenes."""

    params = [list(WALL_PAIRS), ["list", "gather"]]
    param_names = ["scene", "pair_loop"]
    timeout = 300
    min_run_count = 3

    def setup(self, scene, pair_loop):
        box = dict(WALL_PAIRS[scene])
        if box.pop("strip", False):
            box["strip_height"] = thinnest_strip(WALL_DX)
        try:
            self.p = Prepared("linkedlist-cpu", "float64", WALL_DX, pair_loop=pair_loop, name=scene, **box)
        except Unsupported as exc:
            raise NotImplementedError(str(exc)) from None
        except (TypeError, ValueError) as exc:  # a commit without the scene (or without scenes)
            raise NotImplementedError(f"no scene {scene} at this commit: {exc}") from None

    def time_step(self, *_):
        self.p.step()


# The paper's scene with and without open x edges (the sponge's default layer, 1.5 pulse widths each side: 18 %
# more particles on the paper's 50 m domain; two pulse widths, 24 %, at commits before 2026-12-05's e7ce86e):
# what a step pays for the layer, its particles and the sponge's damping (issue 41's target: at most 25 % of
# the closed scene's step).
OPEN_DX = 0.1  # 100,000 particles closed, 118,000 open


class TimeOpenEdgeStep:
    """One step of linkedlist-cpu (float64, lagrangian, serial) on the paper's scene, closed or with open x
    edges; commits before the open edges skip the open case."""

    params = [["closed", "open x"]]
    param_names = ["edges"]
    timeout = 300
    min_run_count = 3

    def setup(self, edges):
        extra = {} if edges == "closed" else {"open": "x"}
        try:
            self.p = Prepared("linkedlist-cpu", "float64", OPEN_DX, **extra)
        except (TypeError, ValueError) as exc:  # a commit without open edges
            raise NotImplementedError(f"no open edges at this commit: {exc}") from None

    def time_step(self, *_):
        self.p.step()


# The cylinder (the workshop's pulse scattered by a rigid body, its ghosts filled before every sweep) beside the
# 2D pulse's open square of the same size and dx: what a step pays for the body, linear (its ghosts' sampling
# weights built once) and lagrangian (rebuilt before every sweep, on the host).
CYLINDER_DX = 0.05  # 65,536 particles with the open square's layers


class TimeCylinderStep:
    """One step of linkedlist-cpu (float64, serial) on the cylinder and on the 2D pulse's open square of the same
    box and dx, linear and lagrangian; commits before the cylinder skip it."""

    params = [["acoustic-pulse open", "cylinder"], ["linear", "lagrangian"]]
    param_names = ["scene", "model"]
    timeout = 300
    min_run_count = 3

    def setup(self, scene, model):
        box = dict(x_min=-6.0, x_max=6.0, y_min=-6.0, y_max=6.0, pulse_width=0.2)  # the layer: 2 pulse widths
        extra = (
            {"name": "cylinder", "pulse_center": 4.0}
            if scene == "cylinder"
            else {"name": "acoustic-pulse", "open": "xy", "pulse_center": 4.0}
        )
        try:
            self.p = Prepared("linkedlist-cpu", "float64", CYLINDER_DX, model=model, **box, **extra)
        except (TypeError, ValueError) as exc:  # a commit without the scene
            raise NotImplementedError(f"no {scene} at this commit: {exc}") from None

    def time_step(self, *_):
        self.p.step()
