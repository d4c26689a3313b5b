"""The run specification: what one run is (solver, threads, scene, preset), and when two runs are the same.

A :class:`RunSpec` is a typed value. It travels to a sweep's child process as
JSON (:meth:`RunSpec.to_json` / :meth:`RunSpec.from_json`), and
:func:`identity` is the one definition of "the same run" used by the store,
the resume logic and the reports.

The thread policy lives here and nowhere else: ``threads`` is an integer >= 1
(1 is serial, the paper's CPU code) or ``"all"`` (every core this process may
use, for a solver whose class says it is ``threaded``), resolved to an integer by :func:`resolve_threads`.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass

from solvers import Scene, SceneError, check_pair_loop, resolve_pair_loop, solver_class
from solvers.boundaries.bodies import CORRECTED_BOUNDARY_METHOD
from solvers.corrections import DEFAULT_CORRECTION
from solvers.edges import default_absorber
from solvers.scene import PAPER_PULSE, PER_KIND
from solvers.scenes import scene_kind

SERIAL = 1
# Every absorber's default layer, in pulse widths, for the rows stored before a row kept its layer's width (the
# derived key ``layer``, m) and the sponge's default became 1.5 pulse widths (2026-12-05): :func:`stored_parameters`.
LAYER_WIDTHS_BEFORE = 2.0
# The absorber a 3D scene's open faces took by default before a row kept the one it ran (the derived key
# ``absorber_used``) and the 3D default became the PML (2026-12-07): :func:`stored_parameters`.
ABSORBER_3D_BEFORE = "sponge"
# The wall a corrected method's body took by default before a row kept the one it ran (``boundary_method_used``)
# and the default became cut cells (2026-12-07).
CORRECTED_WALL_BEFORE = "weak"
ALL_CORES = "all"


class OptionError(ValueError):
    """A harness option (not a scene parameter) is outside its allowed range."""


def usable_cores() -> int:
    """Threads ``"all"`` means: the cores this process may run on, within numba's thread limit."""
    import numba

    usable = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1
    return max(1, min(usable, numba.config.NUMBA_NUM_THREADS))


def parse_threads(text) -> int | str:
    """``--threads`` as given: an integer >= 1 or ``all``. OptionError names the option."""
    if isinstance(text, str) and text.strip().lower() == ALL_CORES:
        return ALL_CORES
    try:
        if isinstance(text, bool) or isinstance(text, str) and not text.isascii():
            raise ValueError  # True is not a count, nor are digits of other scripts
        value = int(text)
    except (TypeError, ValueError):
        raise OptionError(f"--threads must be an integer >= 1 or 'all' (got {text!r})") from None
    if value < 1:
        raise OptionError(f"--threads must be an integer >= 1 or 'all' (got {value})")
    return value


def resolve_threads(threads, solver: str) -> int:
    """The thread count for ``solver``: ``"all"`` becomes every usable core (1 for serial solvers).

    An explicit count above 1 for a serial solver, or above the cores numba may
    use, is an OptionError naming ``--threads``.
    """
    threads, cls = parse_threads(threads), solver_class(solver)
    if threads == ALL_CORES:
        return usable_cores() if cls.threaded else SERIAL
    if threads > 1 and not cls.threaded:
        raise OptionError(f"--threads: {solver} is serial, {cls.serial_why} (got {threads})")
    import numba

    if threads > numba.config.NUMBA_NUM_THREADS:
        raise OptionError(
            f"--threads must be between 1 and {numba.config.NUMBA_NUM_THREADS} on this machine (got {threads})"
        )
    return threads


@dataclass(frozen=True)
class RunSpec:
    """One run of a sweep: a solver on a scene, with ``threads`` CPU threads.

    ``threads`` may be ``"all"`` and ``pair_loop`` ``"auto"`` until
    :meth:`resolved` decides them for this machine. ``preset`` names the study
    that asked for the run (quick, paper, stability, matrix, gpu).
    """

    solver: str
    scene: Scene
    threads: int | str = SERIAL
    preset: str = ""
    pair_loop: str = "auto"

    def __post_init__(self):
        try:
            solver_class(self.solver)
        except SceneError as exc:
            raise OptionError(f"--{exc}") from None
        parse_threads(self.threads)
        check_pair_loop(self.solver, self.pair_loop)

    @property
    def is_resolved(self) -> bool:
        """Whether ``threads`` is a count and ``pair_loop`` a loop (what a run, a record and a store key need)."""
        return isinstance(self.threads, int) and self.pair_loop != "auto"

    def resolved(self) -> "RunSpec":
        """This spec with ``threads`` as a count and ``pair_loop`` as the loop the solver will use here
        (itself if it is resolved already: a spec is resolved once, where the sweep or command starts)."""
        if self.is_resolved:
            return self
        return RunSpec(
            self.solver,
            self.scene,
            resolve_threads(self.threads, self.solver),
            self.preset,
            resolve_pair_loop(self.solver, self.scene, self.pair_loop),
        )

    def key(self, machine: str, code: str, host: str) -> str:
        """:func:`identity` of this (resolved) spec run on ``machine``/``host`` by ``code``."""
        return identity(self.solver, self.threads, self.scene, self.preset, machine, code, host, self.pair_loop)

    @property
    def label(self) -> str:
        """A short human label: solver, threads, N and the scene's non-default parameters."""
        s = self.scene
        threads = f" x{self.threads}" if self.threads not in (SERIAL, str(SERIAL)) else ""
        loop = f" [{self.pair_loop}]" if self.pair_loop not in ("auto", "all-pairs") else ""
        changed = {k: v for k, v in scene_parameters(s).items() if v != s.default_of(k) and k not in ("dx", "name")}
        scene = "" if s.name == Scene.default("name") else f" {s.name}"
        extra = " ".join(f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}" for k, v in changed.items())
        return f"{self.solver}{threads}{loop}{scene} dx={s.dx:g} N={s.n_particles:,}" + (f" {extra}" if extra else "")

    def to_json(self) -> str:
        return json.dumps(
            {
                "solver": self.solver,
                "threads": self.threads,
                "scene": scene_parameters(self.scene),
                "preset": self.preset,
                "pair_loop": self.pair_loop,
            },
            sort_keys=True,
        )

    @classmethod
    def from_json(cls, text: str) -> "RunSpec":
        d = json.loads(text)
        return cls(
            d["solver"], Scene(**d["scene"]), d.get("threads", SERIAL), d.get("preset", ""), d.get("pair_loop", "auto")
        )


def scene_parameters(scene: Scene) -> dict:
    """The scene's own parameters (no derived quantities, no machine limit), as stored."""
    return scene.parameters()


def stored_parameters(scene: dict) -> dict:
    """A stored scene dict's own parameters (derived keys dropped), each one a row predates (absent or null) at
    its default: the value runs had before the parameter existed (rows without ``kernel`` are Gaussian), and an
    open row's default layer the one it ran with (LAYER_WIDTHS_BEFORE, where the row does not state its layer).
    The one place old rows are brought up to the current fields (the frame, the resume key, scene_from_row)."""
    out = {k: Scene.keyword_default(k) if scene.get(k) is None else scene[k] for k in Scene.PARAMETERS}
    ran = _layer_ran(scene, out)
    try:
        kind = scene_kind(out["name"])
    except ValueError:  # a plug-in's scene not installed here: its row keeps what it stored (and its layer)
        if ran is not None:
            out["layer_width"] = ran
        return out
    for k in PER_KIND:  # parameters whose default is the scene kind's: the value a Scene resolves
        if out[k] is None:
            out[k] = kind.defaults.get(k, PAPER_PULSE.get(k))
    absorber = _absorber_ran(scene, out, kind)
    if absorber is not None and absorber != default_absorber(kind):  # a default since changed: named
        out["absorber"] = absorber
    wall = _wall_ran(scene, out, kind)
    if wall is not None and wall != CORRECTED_BOUNDARY_METHOD:
        out["boundary_method"] = wall
    if ran is not None:
        out["layer_width"] = _default_unless_changed(out, ran)
    return out


def _layer_ran(scene: dict, parameters: dict) -> float | None:
    """The width (m) of the default layer a stored open row ran (one that names none): its derived key ``layer``,
    or for a row stored before rows kept it, LAYER_WIDTHS_BEFORE pulse widths; None for any other row (closed,
    a width of its own, or a scene dict that is not a stored row: no derived keys)."""
    if not parameters.get("open") or parameters.get("layer_width") is not None or "n_particles" not in scene:
        return None
    if isinstance(scene.get("layer"), (int, float)):
        return float(scene["layer"])
    pulse = parameters.get("pulse_width")
    return LAYER_WIDTHS_BEFORE * pulse if isinstance(pulse, (int, float)) else None


def _absorber_ran(scene: dict, parameters: dict, kind) -> str | None:
    """The absorber a stored open row that names none ran by default: its derived key ``absorber_used``, or for a
    3D row stored before rows kept it, ABSORBER_3D_BEFORE; None for any other row (closed, an absorber of its own,
    a 2D row before the key, or a scene dict that is not a stored row)."""
    if not parameters.get("open") or parameters.get("absorber") or "n_particles" not in scene:
        return None
    if isinstance(scene.get("absorber_used"), str) and scene["absorber_used"]:
        return scene["absorber_used"]
    return ABSORBER_3D_BEFORE if kind.dims == 3 else None


def _wall_ran(scene: dict, parameters: dict, kind) -> str | None:
    """The wall a stored corrected row on a body that names none ran by default: its derived key
    ``boundary_method_used``, or for a row stored before rows kept it, CORRECTED_WALL_BEFORE; None for any other
    row (no body, a wall of its own, uncorrected, or a scene dict that is not a stored row)."""
    corrected = parameters.get("correction") not in (None, "", DEFAULT_CORRECTION)
    if not kind.body or parameters.get("boundary_method") or not corrected or "n_particles" not in scene:
        return None
    if isinstance(scene.get("boundary_method_used"), str) and scene["boundary_method_used"]:
        return scene["boundary_method_used"]
    return CORRECTED_WALL_BEFORE


def _default_unless_changed(parameters: dict, ran: float) -> float | None:
    """None (the default) where today's default layer is the one the row ran, to the lattice's columns; else the
    width it ran, stated, so that the row reads as what ran and is not one configuration with today's runs."""
    try:
        now = Scene(**parameters)
        same = now.n_layer == now.replace(layer_width=ran).n_layer
    except (SceneError, ValueError, TypeError):  # a row this checkout cannot build: as it was
        return ran
    return None if same else ran


def scene_from_row(row) -> Scene:
    """The Scene of a run: a stored row (its ``scene`` dict) or a row of the reports' frame (its ``scene_key``);
    derived keys dropped, each parameter the row predates at its default. The one way from a record to a
    Scene."""
    if "scene_key" in row and isinstance(row["scene_key"], str):
        return Scene(**stored_parameters(json.loads(row["scene_key"])))
    return Scene(**stored_parameters(row.get("scene") or {}))


def identity(
    solver: str,
    threads: int,
    scene: Scene | dict,
    preset: str,
    profile: str,
    code: str,
    host: str,
    pair_loop: str = "",
) -> str:
    """The key of a run for resuming and de-duplication: the same key is the same run.

    ``code`` is the code that made it (:func:`pcabench.store.provenance.code_key`, a content hash; a stored
    row older than it: its commit), so a run of other code, committed or not, is another run.

    ``scene`` may be a Scene or a stored row's scene dict (its derived keys are ignored, the parameters
    it predates take their defaults: :func:`stored_parameters`).
    ``pair_loop`` is the loop the run used (rows from before pair loops had none).
    """
    scene = stored_parameters(scene) if isinstance(scene, dict) else scene_parameters(scene)
    return json.dumps(
        [solver, int(threads), scene, preset or "", profile, code, host, pair_loop or ""], sort_keys=True, default=str
    )


def row_code(row: dict) -> str:
    """The code a stored row was made by, as :func:`identity` takes it: its ``code``, or in a row older than
    the content key its commit (which then never equals a content key: such a row is not resumed)."""
    return row.get("code") or row.get("commit", "") or ""


def row_identity(row: dict) -> str:
    """:func:`identity` of a stored row."""
    return identity(
        row["solver"],
        int(row.get("threads") or 1),
        row.get("scene") or {},
        row.get("preset", ""),
        row.get("profile_id", ""),
        row_code(row),
        row.get("host", ""),
        row.get("pair_loop", ""),
    )
