"""The reports' DataFrame: the store's records, one row each, with the columns the tables read.

The store loads records (:func:`pcabench.store.read_rows`); what a report
derives from them lives here: stage times as ``t_<stage>`` (s), the scene's
parameters as columns (at their defaults where a row predates them), the run's
protocol (``protocol``: steps or a physical time; ``domain``: full or strip),
what ran (``device``; ``search``: linked list or all-pair; ``loop``: the pair
loop), the machine (a profile, and its host where several share it), ``t_step`` (s
per step) and ``t_solution`` (init + steps, s, no JIT or I/O).
"""

from __future__ import annotations

import json

import numpy as np
import pandas as pd

from pcabench import store
from pcabench.spec import scene_from_row, stored_parameters
from pcabench.store.record import STEP_STAGES
from solvers import registry

SCENE_COLUMNS = (
    "strip_height",
    "cutoff_factor",
    "kernel",
    "correction",
    "h_factor",
    "cfl",
    "t_final",
    "height",
    "mach",
    "pulse_width",
    "open",
)
NUMERIC = ("mse", "me", "mean_neighbours", "jit_seconds", "dx", "t_end", "mse_isothermal", "headline")


def load(paths) -> pd.DataFrame:
    """The stores ``paths`` (files or folders of *.jsonl) as one DataFrame, one row per run."""
    return frame(store.read_rows(paths))


def headline_of(row: dict) -> tuple[str, float | None]:
    """(name, value) of a stored row's headline measure (solvers.scenes.base.SceneKind.measure): as the row
    stores it; in a row older than it, as its scene kind names it for the time the run reached ("" and None for a
    run that was not scored, or whose scene kind is not installed)."""
    if row.get("measure"):
        return str(row["measure"]), row.get("headline")
    if row.get("status") != "ok" or not isinstance(row.get("t_end"), (int, float)):
        return "", None
    try:
        scene = scene_from_row(row)
    except (ValueError, TypeError, KeyError):  # a scene this checkout no longer builds: no name to give it
        return "", None
    name = scene.kind.measure(scene, float(row["t_end"]))
    return name, scene.kind.measure_value(name, row.get("mse"), row.get("errors") or {})


def _flat(row: dict) -> dict:
    r = {k: v for k, v in row.items() if k not in ("stages", "scene", "versions", "errors", "probes", "plane")}
    r["probes"] = json.dumps(row.get("probes") or {})  # readings at the probe points: one hashable cell
    r["plane"] = json.dumps(row.get("plane") or {})  # a 3D run's final drho on the plane nearest z = 0: one cell
    for name, value in (row.get("errors") or {}).items():  # the scene's other error measures
        r[f"err_{name}"] = value
    for stage, seconds in (row.get("stages") or {}).items():
        r[f"t_{stage}"] = seconds
    stored = row.get("scene") or {}
    parameters = stored_parameters(stored)  # each parameter the row predates at its default (kernel)
    scene = {**parameters, **stored}
    for key in SCENE_COLUMNS:
        r[key] = scene.get(key)
    r["scene"] = scene["name"]  # rows from before the scene registry: the paper's (stored_parameters)
    r["measure"], r["headline"] = headline_of(row)  # the one error that means something at the run's end
    # how the run ends: the paper's fixed step count, or a fixed physical time
    r["protocol"] = f"t = {scene['t_end']:g} s" if scene.get("t_end") else f"{scene.get('steps')} steps"
    r["domain"] = "strip" if scene.get("strip_height") else "full"
    layer = scene.get("layer")
    r["edges"] = (  # one word (a table column): open edges/absorber/layer, e.g. x/sponge/4.5m
        f"{scene['open']}/{scene.get('absorber') or 'default'}"
        + (f"/{layer:g}m" if isinstance(layer, (int, float)) else "")
        if scene.get("open")
        else "-"
    )
    # the configuration: the scene's parameters alone, as the resume key has them (pcabench.spec.identity), so that
    # a derived key a newer row stores (its layer's width) does not split one configuration in two
    r["scene_key"] = json.dumps(parameters, sort_keys=True)
    r.setdefault("preset", "")
    r.setdefault("pair_loop", "")  # rows from before the pair list: the gather loop
    r["threads"] = int(r.get("threads") or 1)
    # what ran: the device, the neighbour search and the pair loop (a record that does not state its
    # device or loop: its solver's class says them, a solver no longer installed ran on the CPU; the
    # linked list's loop before the pair list, and the GPU's, was the paper's gather loop)
    cls = registry().get(str(row.get("solver", "")))
    r["device"] = row.get("device") or (cls.device if cls else "cpu")
    r["search"] = cls.search if cls else "all-pair" if r["pair_loop"] == "all-pairs" else "linked list"
    r["loop"] = r["pair_loop"] or ("all-pairs" if r["search"] == "all-pair" else "gather")
    return r


def frame(rows: list[dict]) -> pd.DataFrame:
    """Stored records (dicts) as the reports' DataFrame."""
    df = pd.DataFrame([_flat(row) for row in rows])
    if df.empty:
        return df
    if "mse_isothermal" not in df:
        df["mse_isothermal"] = np.nan  # rows from before it was measured
    for col in NUMERIC:  # null -> NaN
        if col in df:
            df[col] = pd.to_numeric(df[col], errors="coerce")
    df["host"] = df["host"].fillna("") if "host" in df else ""
    # one machine: a hardware profile, and its host where several hosts share the profile
    hosts = df.groupby("profile_id")["host"].transform("nunique")
    df["machine"] = np.where(hosts > 1, df["profile_id"] + "--" + df["host"], df["profile_id"])
    step_total = sum(df[f"t_{s}"] for s in STEP_STAGES)
    df["t_step"] = step_total / df["steps"].clip(lower=1)
    df["t_solution"] = df["t_init"] + step_total  # s, without JIT and I/O
    return df
