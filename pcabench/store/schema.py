"""The run record's schema, declared once: every field's type, range, allowed characters and length.

The store checks a row against it on write (a record that would not read
back is never written) and on read (a row that fails is skipped with one
warning naming the line and the field), so nothing downstream of the store
sees an unchecked value. Keys it does not know are kept if they are plain
values (a later pcabench's extra fields: strings, numbers, booleans, null, or
a flat object of those);
the ``scene`` dict's known keys are checked, its other keys (a named scene's
parameters) may hold strings or numbers.

Names that become paths (``profile_id``, ``host``: the store's file name and
the report's folder; ``solver``, ``commit``) are letters, digits and
``. _ - +`` of bounded length, and never one of :data:`RESERVED` (a file
pcabench writes beside them).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from solvers.edges import OPEN_EDGES
from solvers.interface import STAGES
from solvers.kernels.registry import KERNEL_NAME
from solvers.method import INTEGRATORS
from solvers.registry import SOLVER_NAME
from solvers.scene import MAX_STEPS, MODELS, PRECISIONS

STATUSES = ("ok", "unstable", "out-of-memory", "timeout", "error", "skipped")
STEP_STAGES = ("snp", "pi", "su")  # the stages of a time step; input, init and output happen once per run
# a record's ``stages``: the clock's six, each in s (STAGES, solvers/interface.py)

SCHEMA = 2  # version of the row format; rows from before versioning are schema 1
MAX_SECONDS = 1e9  # a time above this (31 years) is not a measurement
MAX_NAME = 100  # the longest name that becomes part of a file name (profile--host.jsonl.reserve < 255 bytes)
MAX_TEXT = 200  # the longest short text (a version string, a named scene's string parameter)
MAX_MESSAGE = 20_000  # a record's message (an error's traceback, a solver's output), cut to this
NAME = re.compile(r"[A-Za-z0-9][A-Za-z0-9._-]*", re.ASCII)  # safe as a file name
CODE_KEY = re.compile(r"[0-9a-f]{16}", re.ASCII)  # provenance.code_key
COMMIT = re.compile(r"[A-Za-z0-9][A-Za-z0-9._+-]*", re.ASCII)  # a sha, with +dirty; or a tag
TIMESTAMP = re.compile(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d(\.\d+)?([+-]\d\d:\d\d|Z)?", re.ASCII)
CONTROL = re.compile(r"[\x00-\x1f\x7f-\x9f]")
MESSAGE_CONTROL = re.compile(r"[\x00-\x08\x0b-\x1f\x7f-\x9f]")  # a message may hold newlines and tabs
# files and folders pcabench writes beside a machine's store or report folder: never a machine's name
RESERVED = frozenset(
    n.lower()
    for n in ("README.md", "cards.md", "gpu", "results", "store", "reports", "hardware_profiles", "index.md", ".", "..")
)
RESERVED_SUFFIXES = (".md", ".png", ".json", ".jsonl", ".lock", ".torn", ".reserve", ".npz", ".gz", ".tmp")


@dataclass(frozen=True)
class Field:
    """One key of a record: its JSON types, range, allowed characters and length."""

    types: tuple  # of "str", "int", "number", "bool", "dict", "null"
    required: bool = False
    low: float | None = None
    high: float | None = None
    choices: tuple | None = None
    pattern: re.Pattern | None = None  # the characters a string may hold (whole match); "" always allowed
    max_len: int = MAX_TEXT
    empty: bool = True  # whether "" is allowed
    path: bool = False  # the value becomes part of a path: not a reserved name
    above: bool = False  # the range excludes ``low`` (a length: > 0)
    form: str = "a name of letters, digits, '.', '_', '-'"  # what ``pattern`` allows, in words


def _name(required=False, empty=True, path=False, max_len=MAX_NAME, pattern=NAME):
    return Field(("str",), required, pattern=pattern, max_len=max_len, empty=empty, path=path)


def _time(required=False, null=False):
    return Field(("number", "null") if null else ("number",), required, low=0, high=MAX_SECONDS)


STAGE_TIME = _time()  # one stage's total time in a record, s
PATH_NAME = _name(empty=False, path=True, max_len=2 * MAX_NAME + 2)  # a file or folder name (profile--host)
_STEPS = Field(("int",), True, low=0, high=MAX_STEPS)
_ERROR = Field(("number", "null"), low=0, high=1e300)
_MEASURE = Field(("number", "null"), low=-1e300, high=1e300)  # a scene's own measure (a plug-in's may be signed)

FIELDS: dict[str, Field] = {
    "schema": Field(("int",), low=1),
    "solver": _name(required=True, empty=False, max_len=32, pattern=SOLVER_NAME),  # the one name rule (plugins.NAME)
    "precision": Field(("str",), choices=PRECISIONS),
    "model": Field(("str",), choices=MODELS),
    "integrator": Field(("str",), choices=INTEGRATORS),
    "dx": Field(("number",), True, low=0, high=1e3, above=True),
    "n_particles": Field(("int",), True, low=0, high=2**31 - 1),
    "steps": _STEPS,
    "t_end": Field(("number", "null"), low=0, high=1e12),
    "stages": Field(("dict",), True),
    "jit_seconds": _time(null=True),
    "jit_cached": Field(("bool", "null")),
    "mse": _ERROR,
    "me": _ERROR,
    "mean_neighbours": Field(("number", "null"), low=0, high=2**31),
    "status": Field(("str",), True, choices=STATUSES),
    "failed_step": Field(("int", "null"), low=0, high=MAX_STEPS),
    "threads": Field(("int",), low=1, high=1 << 16),
    "pair_loop": _name(max_len=32),
    "device": _name(max_len=32),
    "steps_requested": Field(("int",), low=0, high=MAX_STEPS),
    "mse_isothermal": _ERROR,
    "measure": _name(max_len=32),  # the headline measure's name (SceneKind.measure): rms_u, probes_p, left_energy
    "headline": _MEASURE,  # its value: the one error that means something at the run's end
    "errors": Field(("dict",)),  # the scene's other error measures, by name: numbers or null
    "probes": Field(("dict",)),  # readings at the scene's probe points, by name: lists of numbers
    "plane": Field(("dict",)),  # a 3D run's final drho on the plane nearest z = 0 (solvers.scenes.base.plane_z)
    "scene": Field(("dict",), True),
    "message": Field(("str",), max_len=MAX_MESSAGE),
    "profile_id": _name(required=True, empty=False, path=True),
    "host": _name(max_len=64, path=True),
    "commit": Field(("str",), pattern=COMMIT, max_len=64, form="letters, digits, '.', '_', '+', '-'"),
    "code": Field(("str",), pattern=CODE_KEY, max_len=16, form="16 hexadecimal digits (provenance.code_key)"),
    "versions": Field(("dict",)),
    "preset": _name(max_len=32),
    "timestamp": Field(("str",), pattern=TIMESTAMP, max_len=40, form="of the form YYYY-MM-DDTHH:MM:SS+00:00"),
    "run_id": Field(("str",), max_len=64, empty=False),
}

_SCENE_NUMBER = Field(("number",), True, low=-1e12, high=1e12)
SCENE_FIELDS: dict[str, Field] = {
    "dx": Field(("number",), True, low=0, high=1e3, above=True),
    "steps": Field(("int", "null"), True, low=1, high=MAX_STEPS),
    "t_end": Field(("number", "null"), True, low=0, high=1e12),
    "strip_height": Field(("number", "null"), low=0, high=1e12),
    "z_min": Field(("number", "null"), low=-1e12, high=1e12),  # a 3D scene's depth (a 2D one's: null, or absent)
    "z_max": Field(("number", "null"), low=-1e12, high=1e12),
    "n_particles": Field(("int",), low=0, high=2**31 - 1),
    "n_steps": Field(("int",), True, low=0, high=MAX_STEPS),
    "cutoff": _SCENE_NUMBER,
    "h": _SCENE_NUMBER,
    "dt": _SCENE_NUMBER,
    "t_final": _SCENE_NUMBER,
    "layer": Field(("number",), low=0, high=1e12),  # the open edges' layer, m (0 closed; rows before 2026-12-05: none)
    "absorber_used": _name(max_len=32),  # the absorber the layer ran ("" closed; rows before 2026-12-07: none)
    "boundary_method_used": _name(max_len=32),  # the body's wall it ran ("" no body; rows before 2026-12-07: none)
    **{
        k: Field(("number",), low=-1e12, high=1e12)
        for k in (
            "x_min",
            "x_max",
            "y_min",
            "y_max",
            "rho0",
            "c0",
            "mach",
            "pulse_width",
            "pulse_center",
            "h_factor",
            "cutoff_factor",
            "cfl",
            "blowup_factor",
            "height",
        )
    },
    "kernel": _name(max_len=32, pattern=KERNEL_NAME),  # as the kernel registry checks
    "correction": _name(max_len=32, pattern=SOLVER_NAME),  # a kernel correction (solvers/corrections/)
    "model": Field(("str",), choices=MODELS),
    "integrator": Field(("str",), choices=INTEGRATORS),
    "precision": Field(("str",), choices=PRECISIONS),
    "name": _name(max_len=32, pattern=SOLVER_NAME),  # a named scene: the one name rule (plugins.NAME)
    "open": Field(("str",), choices=OPEN_EDGES),
    "layer_width": Field(("number", "null"), low=0, high=1e12, above=True),
    "absorber": _name(max_len=32, pattern=SOLVER_NAME),
    "absorber_strength": Field(("number", "null"), low=0, high=1e12, above=True),
    "cylinder_radius": Field(("number", "null"), low=0, high=1e12, above=True),
    "sphere_radius": Field(("number", "null"), low=0, high=1e12, above=True),
    "boundary_method": _name(max_len=32, pattern=SOLVER_NAME),
    "probes": Field(("list",)),
}


def _kind(value) -> str:
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "bool"
    if isinstance(value, int):
        return "int"
    if isinstance(value, float):
        return "number"
    return {str: "str", dict: "dict", list: "list"}.get(type(value), type(value).__name__)


def text_problem(value: str, control=CONTROL) -> str:
    """Why the string ``value`` cannot be stored and shown ('' if it can): not UTF-8 (a lone surrogate),
    or control characters."""
    try:
        value.encode("utf-8")
    except UnicodeEncodeError:
        return "holds a character that is not UTF-8 (a lone surrogate)"
    if control.search(value):
        return "holds control characters"
    return ""


def reserved_name(name: str) -> bool:
    """Whether ``name`` would clash with a file or folder pcabench writes beside it."""
    low = name.lower()
    return low in RESERVED or low.endswith(RESERVED_SUFFIXES)


def check_value(key: str, spec: Field, value) -> str:
    """Why ``value`` does not fit field ``key`` ('' if it does)."""
    kind = _kind(value)
    if kind not in spec.types and not (kind == "int" and "number" in spec.types):
        return f"{key!r} is {'a JSON ' + kind if kind != 'null' else 'null'}, not {' or '.join(spec.types)}"
    if kind in ("int", "number"):
        if kind == "int" and abs(value) > 1 << 62:
            return f"{key!r} is out of range (got an integer of {value.bit_length()} bits)"
        if not math.isfinite(value):
            return f"{key!r} must be finite (got {value!r})"
        if (spec.low is not None and (value <= spec.low if spec.above else value < spec.low)) or (
            spec.high is not None and value > spec.high
        ):
            low = f"{'(' if spec.above else '['}{spec.low:g}"
            return (
                f"{key!r} must be in {low}, {spec.high:g}] (got {value!r:.40})"
                if spec.high is not None
                else f"{key!r} must be >= {spec.low:g} (got {value!r:.40})"
            )
    if kind == "str":
        why = text_problem(value, MESSAGE_CONTROL if key == "message" else CONTROL)
        if why:
            return f"{key!r} {why}"
        if len(value) > spec.max_len:
            return f"{key!r} is {len(value)} characters long, more than {spec.max_len}"
        if value == "" and not spec.empty:
            return f"{key!r} is empty"
        if spec.choices is not None and value not in spec.choices:
            return f"{key!r} must be one of {', '.join(spec.choices)} (got {value!r})"
        if value and spec.pattern is not None and not spec.pattern.fullmatch(value):
            return f"{key!r} must be {spec.form} (got {value!r:.80})"
        if spec.path and reserved_name(value):
            return f"{key!r} {value!r} is a name pcabench keeps for its own files"
    return ""


def _plain(key: str, value) -> str:
    """Why a value of a key the schema does not know is not plain ('' if it is)."""
    kind = _kind(value)
    if kind == "str":
        return check_value(key, Field(("str",), max_len=MAX_MESSAGE), value)
    if kind == "int":
        return "" if abs(value) <= 1 << 62 else f"{key!r} is out of range"
    if kind == "number":
        return "" if math.isfinite(value) and abs(value) <= 1e300 else f"{key!r} must be a finite number"
    return "" if kind in ("null", "bool") else f"{key!r} is a JSON {kind}; an extra key holds a plain value"


def _extra(key: str, value) -> str:
    """Why the value of a top-level key the schema does not know cannot be kept ('' if it can): a plain
    value, or a flat object of plain values (a later pcabench's parameters)."""
    if _kind(value) != "dict":
        return _plain(key, value)
    if len(value) > 200:
        return f"{key!r} holds {len(value)} entries, more than 200"
    for k, v in value.items():
        why = _key(k) or _plain(f"{key}.{k}", v)
        if why:
            return f"{key!r} {why}"
    return ""


def _key(key) -> str:
    if not isinstance(key, str):
        return f"a key {key!r} that is not a string"
    return "" if NAME.fullmatch(key) and len(key) <= 64 else f"a key {key[:40]!r} that is not a plain name"


def check_scene(scene: dict) -> str:
    """Why a row's ``scene`` dict is not a scene ('' if it is)."""
    for key, spec in SCENE_FIELDS.items():
        if key not in scene:
            if spec.required:
                return f"'scene' lacks {key}"
            continue
        why = check_value(key, spec, scene[key])
        if why:
            return f"'scene' {why}"
    for key, value in scene.items():
        if key not in SCENE_FIELDS:
            why = _key(key) or _plain(key, value)
            if why:
                return f"'scene' {why}"
    return ""


def check(row) -> str:
    """Why ``row`` is not a run record of this schema ('' if it is): the first field that fails."""
    if not isinstance(row, dict):
        return f"not a record but a JSON {_kind(row)}"
    version = row.get("schema", 1)
    if _kind(version) != "int" or version < 1:
        return f"'schema' must be an integer >= 1 (got {version!r:.40})"
    if version > SCHEMA:
        return f"a row of a newer pcabench (schema {version}; this one reads up to {SCHEMA}): upgrade to read it"
    for key, spec in FIELDS.items():
        if key not in row:
            if spec.required:
                return f"missing {key!r}"
            continue
        why = check_value(key, spec, row[key])
        if why:
            return why
    for key, value in row.items():
        if key not in FIELDS:
            why = _key(key) or _extra(key, value)
            if why:
                return why
    stages = row["stages"]
    for stage, seconds in stages.items():
        why = _key(stage) or check_value(f"stage {stage}", STAGE_TIME, seconds)
        if why:
            return why
    missing = [s for s in STAGES if s not in stages]
    if missing:
        return f"stages lack {', '.join(missing)}"
    for name, value in (row.get("errors") or {}).items():
        why = _key(name) or check_value(f"errors {name}", _MEASURE, value)
        if why:
            return why
    for name, version in (row.get("versions") or {}).items():
        why = _key(name) or check_value(f"versions {name}", Field(("str",), max_len=64), version)
        if why:
            return why
    return check_scene(row["scene"])


def clean_text(text: str, limit: int = MAX_MESSAGE) -> str:
    """``text`` as a record's message may hold it: control characters (but newlines and tabs) and lone
    surrogates replaced, cut to its last ``limit`` characters."""
    text = text.encode("utf-8", "replace").decode("utf-8")
    text = MESSAGE_CONTROL.sub("?", text)
    return text if len(text) <= limit else "..." + text[-(limit - 3) :]
