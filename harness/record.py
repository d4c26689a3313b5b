"""The run record: one run's parameters, stage times, errors, status and provenance."""
from __future__ import annotations

import datetime as _dt
from dataclasses import asdict, dataclass, field

STATUSES = ("ok", "unstable", "out-of-memory", "timeout", "error", "skipped")


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
    mse: float  # relative RMS error of u (the paper's "MSE")
    me: float  # max |u - u_the|, m/s
    mean_neighbours: float
    status: str
    failed_step: int | None
    threads: int = 1
    steps_requested: int = 0
    scene: dict = field(default_factory=dict)
    message: str = ""
    profile_id: str = ""
    commit: str = ""
    versions: dict = field(default_factory=dict)
    preset: str = ""  # the study preset that asked for the run (quick, paper, stability, matrix), if any
    host: str = ""  # provenance.host_id(): which computer of this hardware profile made the run
    timestamp: str = field(default_factory=lambda: _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"))

    CONTRACT = ("solver", "precision", "model", "integrator", "dx", "n_particles", "steps", "t_end",
                "stages", "jit_seconds", "mse", "me", "mean_neighbours", "status", "failed_step")

    def as_dict(self) -> dict:
        return asdict(self)

    @property
    def step_seconds(self) -> float:
        """Mean wall time of one step (SNP + PI + SU), s."""
        s = self.stages
        return (s["snp"] + s["pi"] + s["su"]) / max(self.steps, 1)

    def stage_table(self) -> str:
        """The paper's stage table for this run: total s and ms per step."""
        lines = [f"{'stage':<8}{'total (s)':>12}{'per step (ms)':>16}{'share of step':>15}"]
        step_total = sum(self.stages[s] for s in ("snp", "pi", "su")) or float("nan")
        for s in ("input", "init", "snp", "pi", "su", "output"):
            per = 1e3 * self.stages[s] / max(self.steps, 1) if s in ("snp", "pi", "su") else float("nan")
            share = f"{100 * self.stages[s] / step_total:13.1f} %" if s in ("snp", "pi", "su") else ""
            per_txt = f"{per:16.3f}" if s in ("snp", "pi", "su") else f"{'':16}"
            lines.append(f"{s:<8}{self.stages[s]:12.4f}{per_txt}{share:>15}")
        lines.append(f"{'jit':<8}{self.jit_seconds:12.4f}   (compilation, outside the timed stages)")
        return "\n".join(lines)
