"""Stored runs as tables (pandas): list and filter them, and compare two machines or two commits (a commit, or
a code key: the code that made the runs, which tells apart two runs of one commit with edits between).

pcabench runs --solver linkedlist-cpu --status ok
pcabench runs --compare amd-epyc h100-80gb-hbm3__intel-xeon      # two machines
pcabench runs --compare 0ff5d9e 92b452f                          # two commits
"""

from __future__ import annotations

import pandas as pd

COLUMNS = [
    "machine",
    "commit",
    "code",
    "solver",
    "threads",
    "pair_loop",
    "scene",
    "mach",
    "precision",
    "model",
    "kernel",
    "h_factor",
    "cfl",
    "integrator",
    "domain",
    "edges",
    "protocol",
    "dx",
    "n_particles",
    "steps",
    "status",
    "step_ms",
    "measure",
    "error",
    "timestamp",
    "note",
]
NOTE_WIDTH = 160  # characters of a failed run's message in the table's note column
CONFIG = ["solver", "threads", "pair_loop", "scene_key"]  # the same run on two machines or commits


def machines(names, key: str) -> list[str]:
    """The machines of ``names`` that ``key`` names: itself if one is called so, else those it is a prefix of
    (sorted; empty if none). The one rule for ``--machine`` and ``--compare``."""
    names = sorted(set(names))
    return [key] if key in names else [m for m in names if m.startswith(key)]


def note(message: str, width: int = NOTE_WIDTH) -> str:
    """``message`` on one line, cut at a word boundary past ``width`` characters (marked by " ...")."""
    text = " ".join(message.split())
    return text if len(text) <= width else text[:width].rsplit(" ", 1)[0] + " ..."


def codes(df: pd.DataFrame) -> pd.Series:
    """Each run's code key (provenance.code_key: two runs of one commit made by different code differ here;
    "" in rows older than it)."""
    return (df.code if "code" in df else pd.Series("", index=df.index)).fillna("").astype(str)


def table(df: pd.DataFrame, **filters) -> pd.DataFrame:
    """The runs of ``df`` (from :func:`pcabench.reports.frame.load`) as a readable table, filtered by column
    prefix matches (a machine by :func:`machines`). Its error is the run's headline measure, named in the
    ``measure`` column (SceneKind.measure: ``rms_u``, ``probes_p``, ``left_energy`` once an open scene's pulse has
    left). A run that made no step (skipped on its prediction, timed out, crashed before a step) has no step
    time, steps or error (NA, shown as "-"), and its note says why."""
    if df.empty:
        return pd.DataFrame(columns=COLUMNS)
    stepped = df.steps > 0
    out = df.assign(
        step_ms=(1e3 * df.t_step).where(stepped),
        steps=df.steps.astype("Int64").where(stepped),
        measure=(df.measure if "measure" in df else pd.Series("", index=df.index)).fillna("").replace("", "-"),
        error=(df.headline if "headline" in df else df.mse).where(stepped),  # the headline measure's value
        commit=df.commit.astype(str).str[:7],
        code=codes(df).str[:8].replace("", "-"),  # "-": a row older than the code key
        note=(df.message if "message" in df else pd.Series("", index=df.index))
        .fillna("")
        .astype(str)
        .map(note)
        .where(df.status != "ok", ""),
    )
    for column, value in filters.items():
        if value:
            hit = (
                out.machine.isin(machines(out.machine, str(value)))
                if column == "machine"
                else out[column].astype(str).str.startswith(str(value))
            )
            out = out[hit]
    return out.sort_values(["machine", "timestamp"])[COLUMNS]


def render(out: pd.DataFrame) -> str:
    """``out`` (from :func:`table` or :func:`compare`) as text: no index column, "-" where nothing was measured."""
    counts = [c for c in out if isinstance(out[c].dtype, pd.Int64Dtype)]  # steps: "<NA>" otherwise
    out = out.astype({c: object for c in counts}).fillna({c: "-" for c in counts})
    return out.to_string(index=False, na_rep="-", float_format=lambda v: f"{v:.4g}")


def side(df: pd.DataFrame, key: str) -> tuple[str, pd.DataFrame]:
    """The runs ``key`` names: a machine (by :func:`machines`) or else a commit (prefix); ('', empty) if neither.
    A prefix of several machines is an error that names them."""
    hit = machines(df.machine, key)
    if len(hit) > 1:
        raise KeyError(f"--compare: {key!r} is a prefix of several machines ({', '.join(hit)}): give more of one")
    if hit:
        return "machine", df[df.machine == hit[0]]
    hit = df[df.commit.astype(str).str.startswith(key) | (codes(df).str.startswith(key) & (len(key) >= 4))]
    return ("commit", hit) if not hit.empty else ("", hit)


def compare(df: pd.DataFrame, a: str, b: str) -> pd.DataFrame:
    """The configurations both ``a`` and ``b`` ran (ok, newest of each): step times, their ratio, errors."""
    ok = df[df.status == "ok"]
    kind_a, ra = side(ok, a)
    kind_b, rb = side(ok, b)
    for key, kind in ((a, kind_a), (b, kind_b)):
        if not kind:
            raise KeyError(
                f"--compare: {key!r} is neither a machine nor a commit of a finished run in the store "
                f"(machines: {', '.join(machines(df.machine, ''))})"
            )
    if kind_a != kind_b:  # a machine's runs span commits, a commit's span machines: no like with like
        raise KeyError(f"--compare: {a!r} is a {kind_a} and {b!r} a {kind_b}: compare two machines or two commits")
    # a machine's columns are named by the machine, a prefix's included
    a, b = (r.machine.iloc[0] if kind == "machine" else key for key, kind, r in ((a, kind_a, ra), (b, kind_b, rb)))
    newest = [c for c in CONFIG if c in ok]
    ra = ra.sort_values("timestamp").drop_duplicates(newest, keep="last")
    rb = rb.sort_values("timestamp").drop_duplicates(newest, keep="last")
    both = ra.merge(rb, on=newest, suffixes=("_a", "_b"))
    out = pd.DataFrame(
        {
            "solver": both.solver,
            "threads": both.threads,
            "pair_loop": both.pair_loop,
            "precision": both.precision_a,
            "model": both.model_a,
            "domain": both.domain_a,
            "protocol": both.protocol_a,
            "N": both.n_particles_a,
            f"step_ms {a}": 1e3 * both.t_step_a,
            f"step_ms {b}": 1e3 * both.t_step_b,
            "b / a": both.t_step_b / both.t_step_a,
            f"mse {a}": both.mse_a,
            f"mse {b}": both.mse_b,
            "mse b - a": both.mse_b - both.mse_a,
        }
    )
    return out.sort_values(["solver", "threads", "precision", "model", "N"]).reset_index(drop=True)
