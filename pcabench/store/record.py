"""The run record: one run's parameters, stage times, errors, status and provenance."""

from __future__ import annotations

import datetime as _dt
import math
import uuid
from dataclasses import MISSING, asdict, dataclass, field, fields

from pcabench.store.schema import STATUSES, STEP_STAGES  # noqa: F401 - declared with the record's schema, re-exported here
from solvers import STAGES


def step_seconds(stages: dict, steps: int) -> float:
    """Mean wall time of one step (SNP + PI + SU) from total stage times, s."""
    return sum(stages[s] for s in STEP_STAGES) / max(steps or 0, 1)


@dataclass
class RunRecord:
    """Everything a table or figure needs about one run. Times in s, errors of u."""

    solver: str
    precision: str
    model: str
    integrator: str
    dx: float
    n_particles: int
    steps: int  # steps taken (fewer than asked if the run failed)
    t_end: float  # physical time reached, s
    stages: dict  # input, init, snp, pi, su, output -> total seconds
    jit_seconds: float
    mse: float  # relative RMS error of the scene's primary field (u for the paper's scene: the paper's "MSE")
    me: float  # its max error, in its unit (m/s for u)
    mean_neighbours: float
    status: str
    failed_step: int | None
    threads: int = 1
    pair_loop: str = ""  # how the solver visited pairs: list, gather (the paper's) or all-pairs
    device: str = ""  # where the solver's pair loops ran (its class's ``device``: cpu or gpu); "" in older rows
    steps_requested: int = 0
    mse_isothermal: float | None = None  # relative RMS error of the primary field against the isothermal solution
    # (every model since the scene registry; lagrangian only before)
    measure: str = ""  # the headline measure's name (SceneKind.measure: rms_u, probes_p, left_energy); "" unscored
    headline: float | None = None  # its value (mse, or the error measure of that name): the run's one error
    errors: dict = field(default_factory=dict)  # the scene's other error measures (solvers/scenes/), by name
    probes: dict = field(default_factory=dict)  # {"t": [s], name: [drho, kg/m^3]} at the scene's probe points
    plane: dict = field(default_factory=dict)  # a 3D run's final drho on the lattice plane nearest z = 0 (plane_z)
    scene: dict = field(default_factory=dict)
    message: str = ""
    profile_id: str = ""
    commit: str = ""
    code: str = ""  # provenance.code_key(): the code that made the run, by content ("" in older rows)
    versions: dict = field(default_factory=dict)
    preset: str = ""  # the study preset that asked for the run (quick, paper, stability, matrix), if any
    host: str = ""  # provenance.host_id(): which computer of this hardware profile made the run
    # True: no loop was compiled for this run (each loaded from the on-disk JIT cache, solvers/jitcache.py, or
    # already in the process); False: at least one was compiled; None in rows older than the cache
    jit_cached: bool | None = None
    timestamp: str = field(default_factory=lambda: _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"))
    run_id: str = field(default_factory=lambda: uuid.uuid4().hex[:16])  # this record, wherever it is copied

    CONTRACT = (
        "solver",
        "precision",
        "model",
        "integrator",
        "dx",
        "n_particles",
        "steps",
        "t_end",
        "stages",
        "jit_seconds",
        "mse",
        "me",
        "mean_neighbours",
        "status",
        "failed_step",
    )

    @classmethod
    def from_spec(cls, spec, machine: str = "", status: str = "error", message: str = "") -> "RunRecord":
        """The record of the resolved RunSpec ``spec`` on machine ``machine`` before any step: no times, no
        errors, provenance filled."""
        from pcabench.store.provenance import code_key, git_commit, host_id, package_versions
        from solvers import solver_class

        nan, scene = float("nan"), spec.scene
        return cls(
            solver=spec.solver,
            device=solver_class(spec.solver).device,
            precision=scene.precision,
            model=scene.model,
            integrator=scene.integrator,
            dx=scene.dx,
            n_particles=scene.n_particles,
            steps=0,
            t_end=0.0,
            stages={s: 0.0 for s in STAGES},
            jit_seconds=0.0,
            mse=nan,
            me=nan,
            mean_neighbours=nan,
            status=status,
            failed_step=None,
            threads=int(spec.threads),
            pair_loop=spec.pair_loop,
            steps_requested=scene.n_steps,
            scene=scene.as_dict(),
            message=message,
            profile_id=machine,
            commit=git_commit(),
            code=code_key(),
            versions=package_versions(),
            preset=spec.preset,
            host=host_id(),
        )

    @classmethod
    def from_row(cls, row: dict) -> "RunRecord":
        """The record of a stored row that passed the schema (:func:`pcabench.store.validate`): its known fields
        only (a key the schema does not know stays out of every table and report), each one the row predates at
        its default, the stages as the clock's six (s), the scene's other error measures as numbers."""
        values = {}
        for f in fields(cls):
            value = row.get(f.name)
            if value is None and f.name in ("timestamp", "run_id"):
                value = ""  # never this moment's, nor a new id
            elif value is None and f.default is not MISSING:
                value = f.default
            elif value is None and f.default_factory is not MISSING:
                value = f.default_factory()
            values[f.name] = value  # a contract field stored as null (an error never measured) stays None
        values["stages"] = {s: float(row["stages"][s]) for s in STAGES}
        values["errors"] = {k: v for k, v in (row.get("errors") or {}).items() if isinstance(v, (int, float))}
        values["probes"] = {  # a reading that is not a list of numbers is dropped, not trusted
            k: [float(x) for x in v]
            for k, v in (row.get("probes") or {}).items()
            if isinstance(v, list) and all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in v)
        }
        values["plane"] = _plane(row.get("plane"))
        values["scene"] = dict(row["scene"])
        values["versions"] = dict(row.get("versions") or {})
        return cls(**values)

    def as_dict(self) -> dict:
        return asdict(self)

    @property
    def step_seconds(self) -> float:
        """Mean wall time of one step (SNP + PI + SU), s."""
        return step_seconds(self.stages, self.steps)

    def stage_table(self) -> str:
        """The paper's stage table for this run: total s and ms per step."""
        lines = [f"{'stage':<8}{'total (s)':>12}{'per step (ms)':>16}{'share of step':>15}"]
        step_total = sum(self.stages[s] for s in STEP_STAGES) or float("nan")
        for s in STAGES:
            per = 1e3 * self.stages[s] / max(self.steps, 1) if s in STEP_STAGES else float("nan")
            share = f"{100 * self.stages[s] / step_total:13.1f} %" if s in STEP_STAGES else ""
            per_txt = f"{per:16.3f}" if s in STEP_STAGES else f"{'':16}"
            lines.append(f"{s:<8}{self.stages[s]:12.4f}{per_txt}{share:>15}")
        how = {True: "loaded from the JIT cache", False: "compiled"}.get(self.jit_cached, "compilation")
        lines.append(f"{'jit':<8}{self.jit_seconds:12.4f}   ({how}, outside the timed stages)")
        return "\n".join(lines)

    def failure_text(self, scene) -> str:
        """``pcabench run``'s report of a run that did not finish scored: the stage table, its size, how far it
        got, and its status in words (a blow-up: the step, the time and the field past its bound)."""
        at = f" at step {self.failed_step}" if self.failed_step else ""
        when = f" (t = {self.failed_step * scene.dt:.6g} s)" if self.failed_step else ""
        words = {
            "unstable": f"blew up{at}{when}",
            "error": f"failed{at}{when}",
            "out-of-memory": f"ran out of memory{at}",
            "timeout": "stopped past its run budget",
        }.get(self.status, self.status + at)
        lines = [
            self.stage_table(),
            f"particles        {self.n_particles:,}",
            f"steps            {self.steps} of {scene.n_steps}",
            f"kernel           {scene.kernel} (cutoff {scene.cutoff:.4g} m)",
            f"status           {self.status}: {words}; no errors measured",
        ]
        if self.message:
            lines.append(f"message          {self.message.splitlines()[0]}")
        if scene.known_failure:
            lines.append(f"note             {scene.known_failure}")
        return "\n".join(lines)

    def text(self, scene) -> str:
        """``pcabench run``'s report of this run of ``scene``: the stage table, the run's size, its errors
        (in the scene's primary field: u in m/s, drho in kg/m^3) and its status."""
        if self.status != "ok":  # a failed run took no measures: what it is, and where and why it stopped
            return self.failure_text(scene)
        primary = scene.kind.primary
        unit = {"u": "m/s", "drho": "kg/m^3"}.get(primary, "")

        def number(value, form: str) -> str:  # a measure a failed run never took: "-"
            return "-" if value is None else format(value, form)

        at_probes = self.measure.startswith("probes_")  # mse is the probes' measure: the headline names it
        mse = (
            (
                f"MSE (rel. RMS)   {number(self.mse, '.6g')}"
                + ("" if primary == "u" else f" of {primary}")
                + (" (against the pulse; once it has left, read the left measures below)" if scene.open else "")
            )
            if self.mse is None or math.isfinite(self.mse)
            else f"MSE (rel. RMS)   - (undefined: the exact {primary} holds no pulse in the scored domain"
            + ("; the pulse has left: read the left measures below)" if scene.open else ")")
        )
        lines = [
            self.stage_table(),
            f"particles        {self.n_particles:,}",
            f"steps            {self.steps} (t = {number(self.t_end, '.6g')} s)",
            f"kernel           {scene.kernel} (cutoff {scene.cutoff:.4g} m)",
            f"mean neighbours  {number(self.mean_neighbours, '.2f')}",
            *(  # the one error that means something at the run's end, by its name
                [
                    f"headline         {self.measure} {number(self.headline, '.6g')}: "
                    f"{scene.kind.measure_words(self.measure, self.t_end)}"
                ]
                if self.measure
                else []
            ),
            *([] if at_probes else [mse]),
            f"ME (max)         {number(self.me, '.6g')} {unit}"
            + (f" (of {primary} at the probes)" if at_probes else ""),
        ]
        lines += [  # a measure whose reference holds no pulse is undefined (NaN): "-"
            f"{name.replace('_', ' '):<16} {value:.6g}" if math.isfinite(value) else f"{name.replace('_', ' '):<16} -"
            for name, value in self.errors.items()
        ]
        points = scene.probe_points()
        for name, series in (self.probes or {}).items():  # a probe no measure scores: what it recorded
            if name == "t" or f"probe_{name}" in self.errors or name not in points:
                continue
            t = (self.probes or {}).get("t") or []
            values = [abs(v) for v in series if v is not None and math.isfinite(v)]
            at = ", ".join(f"{c:g}" for c in points[name])
            lines.append(
                f"probe {name:<10} drho at ({at}) m, {len(series)} samples"
                + (f" over {t[0]:.4g}-{t[-1]:.4g} s" if t else "")
                + (f": max |drho| {max(values):.4g} kg/m^3" if values else "")
                + " (the series: --json)"
            )
        if self.mse_isothermal is not None:
            lines.append(
                f"MSE against the isothermal solution (the equations lagrangian solves) {self.mse_isothermal:.6g}"
            )
        lines.append(f"status           {self.status}" + (f" at step {self.failed_step}" if self.failed_step else ""))
        if self.message:
            lines.append(f"message          {self.message.splitlines()[0]}")
        return "\n".join(lines)


def _plane(value) -> dict:
    """A stored plane (solvers.scenes.base.plane_z) as it was written, or {} where it is not one: numbers where
    numbers belong, rows of numbers (or null) of one length."""
    if not isinstance(value, dict):
        return {}
    number = lambda v: isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)  # noqa: E731
    rows = value.get("drho")
    if not all(number(value.get(k)) for k in ("z", "t", "x0", "y0", "step")) or not isinstance(rows, list) or not rows:
        return {}
    if not all(isinstance(r, list) and len(r) == len(rows[0]) and all(v is None or number(v) for v in r) for r in rows):
        return {}
    return {**{k: float(value[k]) for k in ("z", "t", "x0", "y0", "step")}, "drho": rows}
