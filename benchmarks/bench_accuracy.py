"""Track accuracy and where the time goes: errors against the analytic pulse, stage shares of a step.

asv counts a rise as a regression, which is the right direction for an error
and for the share of a stage that should stay small.
"""

import time

import numpy as np

from .common import Prepared, Scene, large, thinnest_strip


def run(scene, solver):
    """pcabench.execute.run.run, imported when called: discovery imports every module, and at a commit without
    the harness's package (bf587a5) HEAD's pcabench does not import with that commit's solvers. Runs take
    a RunSpec from 2026-11-30 on, a scene and a solver name before."""
    import inspect

    from pcabench.execute.run import run

    if "spec" in inspect.signature(run).parameters:
        from pcabench.spec import RunSpec

        return run(RunSpec(solver, scene))
    return run(scene, solver)


class TrackError:
    """Relative RMS error of u at t = 10 s on a strip (Fig. 8's fixed-time protocol), Verlet, float64."""

    params = [["linear", "lagrangian"], [0.4, 0.2] + ([0.1] if large() else [])]
    param_names = ["model", "dx"]
    unit = "relative RMS"
    timeout = 300

    def track_error_t10(self, model, dx):
        scene = Scene(dx=dx, t_end=10.0, model=model, strip_height=thinnest_strip(dx))
        record = run(scene, "linkedlist-cpu")
        if record.status != "ok":
            raise RuntimeError(f"{record.status}: {record.message}")
        return record.mse


class TrackErrorPaperProtocol:
    """The paper's protocol: relative RMS after 100 steps, full domain, lagrangian."""

    params = [["float64", "float32"], [1.0, 0.5]]
    param_names = ["precision", "dx"]
    unit = "relative RMS"

    def track_error_100_steps(self, precision, dx):
        return run(Scene(dx=dx, precision=precision, steps=100), "linkedlist-cpu").mse


class TrackStageShare:
    """Each stage's share of a linked-list step at 16K particles (Table 5 / Fig. 11), %."""

    params = [["float64", "float32"], ["snp", "pi", "su"]]
    param_names = ["precision", "stage"]
    unit = "%"
    repeats = 7

    def setup(self, precision, stage):
        self.p = Prepared("linkedlist-cpu", precision, 0.25)

    def track_share(self, precision, stage):
        seconds = {s: [] for s in ("snp", "pi", "su")}
        for _ in range(self.repeats):
            for s in seconds:
                t0 = time.perf_counter()
                self.p.stage(s)
                seconds[s].append(time.perf_counter() - t0)
        median = {s: float(np.median(v)) for s, v in seconds.items()}
        return 100 * median[stage] / sum(median.values())


SPHERE_METHOD = {"kernel": "wendland-c2", "h_factor": 1.3, "correction": "gradient", "cfl": 0.5}  # its weak wall's


class TrackSceneError:
    """Each scene's primary error at t = 10 s, linear model, Verlet, the paper's method, on its default domain:
    the plane pulse on a strip at dx 0.4 (u), the 2D acoustic pulse on its 40 m periodic square at dx 0.5
    (drho); with a rigid wall (mirror particles), the plane pulse reflected at 6 m on a strip at dx 0.4 (u)
    and the 2D pulse in its 20 m walled duct at dx 0.5 (drho); the workshop's pulse scattered by the cylinder
    (its default boundary method) in its open square at dx 0.05, CFL 1 (drho); the 3D pulse in its 16 m periodic
    cube at dx 0.5 to t = 5 s, Wendland C2 at h 1.3 dx, CFL 0.5 (drho); the sphere at dx 0.125 to t = 4 s, Wendland
    C2 at h 1.3 dx corrected, CFL 0.5 (p at its probes). A change that breaks one scene's
    accuracy shows across commits; commits before the scene registry, or before a scene, skip it."""

    params = [["plane-pulse", "acoustic-pulse", "plane-wall", "pulse-wall", "cylinder", "acoustic-pulse-3d", "sphere"]]
    param_names = ["scene"]
    unit = "relative RMS"
    timeout = 300

    def setup(self, scene):
        try:
            self.scene = (
                Scene(dx=0.4, t_end=10.0, model="linear", strip_height=thinnest_strip(0.4))
                if scene == "plane-pulse"
                else Scene(dx=0.4, t_end=10.0, model="linear", name=scene, strip_height=thinnest_strip(0.4))
                if scene == "plane-wall"
                else Scene(dx=0.05, t_end=10.0, model="linear", name=scene, cfl=1.0)
                if scene == "cylinder"
                else Scene(dx=0.5, t_end=5.0, model="linear", name=scene, kernel="wendland-c2", h_factor=1.3, cfl=0.5)
                if scene == "acoustic-pulse-3d"
                else Scene(dx=0.125, t_end=4.0, model="linear", name=scene, **SPHERE_METHOD)
                if scene == "sphere"
                else Scene(dx=0.5, t_end=10.0, model="linear", name=scene)
            )
        except (TypeError, ValueError):  # a commit before the scene registry (TypeError), or without the scene
            raise NotImplementedError(f"no scene {scene} at this commit") from None

    def track_scene_error(self, scene):
        record = run(self.scene, "linkedlist-cpu")
        if record.status != "ok":
            raise RuntimeError(f"{record.status}: {record.message}")
        return record.mse
