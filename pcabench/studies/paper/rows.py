"""The paper study's rows: Tables 4-6, the speed table, Figs. 8-14's series, the simplifications, float32 against
float64, the GPU cards side by side, each from the runs of the results store (frame.py)."""

from __future__ import annotations

import numpy as np

from pcabench.machine import profiles
from pcabench.reports.tables import PROTOCOL, label, paper_scene, per_step_ms, protocol, where
from pcabench.store.record import STEP_STAGES
from pcabench.store.rows import default_numerics, latest, newest_per
from pcabench.studies.paper import published as P
from solvers import STAGES

FIG9_LOOP_NAMES = {"gather": "the paper's gather loop", "list": "the pair list"}  # by ``linkedlist_loop``


def _paper_kind(r) -> bool:
    """Whether the paper has a row of ``r``'s kind: serial (its CPU codes are single-thread) and float64."""
    return int(r["threads"]) == 1 and r["precision"] == "float64"


# ---------------------------------------------------------------- Tables 4, 5 and Figs. 11, 13
def table4(df) -> list[dict]:
    """Stage times by configuration, protocol and N: input, init, output in ms per run; SNP, PI, SU in ms per
    step. ``paper``: the paper's published numbers of the same kind at the same N (:func:`paper.same_kind`;
    a GPU row also gets Table 4's stage times), [] where it has none."""
    keys = ["solver", "precision", "n_particles", *PROTOCOL]
    every = default_numerics(df[(df.status == "ok") & (df.model == "lagrangian") & (df.domain == "full")])
    # init is timed once per run: how far the stored reruns of one configuration (any commit) differ in it, and
    # the shortest of them (the least disturbed: a slow allocation in one rerun is not the configuration's cost)
    spread = (
        every.groupby(keys).t_init.agg(lambda x: x.max() / x.min() if len(x) > 1 and x.min() > 0 else 1.0)
        if not every.empty
        else {}
    )
    init_best = every.groupby(keys).t_init.min() if not every.empty else {}
    rows = []
    for _, r in (
        newest_per(paper_scene(df), keys)
        .sort_values(["solver", "precision", "threads", "loop", "steps", "n_particles"])
        .iterrows()
    ):
        row = {
            "config": label(r),
            "protocol": protocol(r),
            "run": r.protocol,
            "steps": int(r.steps),
            "N": int(r.n_particles),
            "device": r.device,
            "search": r.search,
            "threads": int(r.threads),
            "commit": str(r.commit)[:7],
        }
        row.update({s: 1e3 * r[f"t_{s}"] for s in ("input", "init", "output")})
        row["init_spread"] = float(spread.get(tuple(r[k] for k in keys), 1.0))
        row["init_best"] = 1e3 * float(init_best.get(tuple(r[k] for k in keys), r.t_init))
        row.update(per_step_ms(r))
        row["paper"] = P.same_kind(r.device, r.search, r.n_particles) if _paper_kind(r) else []
        row["paper_stages"] = P.table4().get(int(r.n_particles)) if r.device == "gpu" and _paper_kind(r) else None
        rows.append(row)
    return rows


def table5(rows4) -> list[dict]:
    """Each step stage's share of a step, %, from Table 4's rows, with the paper's of the same kind: its K20c
    (Table 5) beside a GPU row at the same N, its serial linked-list CPU (Fig. 11's text, every N) beside a
    serial linked-list CPU row. An all-pair row has no search stage: its pair search is inside PI."""
    t5, cpu = P.table5(), P.cpu_shares()
    rows = []
    for row in rows4:
        total = sum(row[s] for s in STEP_STAGES)
        if not total > 0:
            continue  # no timed step: no shares
        paper = None
        if row["threads"] == 1 and row["config"].endswith("float64"):
            if row["device"] == "gpu" and row["N"] in t5:
                paper = ("K20c, Table 5", t5[row["N"]])
            elif row["device"] == "cpu" and row["search"] == "linked list":
                paper = ("Xeon, Fig. 11 text", [cpu[s] for s in STEP_STAGES])
        rows.append(
            {
                "config": row["config"],
                "protocol": row["protocol"],
                "run": row["run"],
                "N": row["N"],
                "device": row["device"],
                "search": row["search"],
                **{s: 100 * row[s] / total for s in STEP_STAGES},
                "paper": paper,
            }
        )
    return rows


def one_step_shares(rows4) -> list[dict]:
    """Fig. 13: each of the six stages' share of input + init + one step + output, %, one step being the mean
    step of each run (its protocol says how many it made), init the shortest of the configuration's stored
    reruns (timed once per run, it is the stage an allocation's noise moves most)."""
    rows = []
    for row in rows4:
        row = {**row, "init": row.get("init_best", row["init"])}  # the shortest stored rerun's init, ms
        total = sum(row[s] for s in STAGES)
        rows.append(
            {
                "config": row["config"],
                "protocol": row["protocol"],
                "run": row["run"],
                "steps": row["steps"],
                "N": row["N"],
                "device": row["device"],
                "init_spread": row.get("init_spread", 1.0),
                **{s: 100 * row[s] / total for s in STAGES},
            }
        )
    return rows


# ---------------------------------------------------------------- Table 6 and Fig. 14
def table6(df_all) -> list[dict]:
    """CPU (serial linked list, float64) against GPU per step at the same N and run length, per GPU profile.

    The CPU is taken from the same machine where it was measured there, else
    from another measured machine, and the row says which. The all-cores CPU
    row is the same machine's, same N and run length, most threads.
    """
    runs = paper_scene(df_all)
    gpu = runs[runs.device == "gpu"]
    cpu = runs[(runs.device == "cpu") & (runs.search == "linked list") & (runs.precision == "float64")]
    rows = []
    for _, g in (
        newest_per(gpu, ["profile_id", "precision", "n_particles", *PROTOCOL])
        .sort_values(["profile_id", "n_particles", "precision", "steps"])
        .iterrows()
    ):
        same_n = cpu[(cpu.n_particles == g.n_particles) & (cpu.protocol == g.protocol)]
        serial = same_n[same_n.threads == 1]
        if serial.empty:
            continue
        here = serial[serial.profile_id == g.profile_id]
        c = (here if not here.empty else serial).sort_values("timestamp").iloc[-1]
        multi = same_n[(same_n.threads > 1) & (same_n.profile_id == c.profile_id)]
        m = multi.sort_values(["threads", "timestamp"]).iloc[-1] if not multi.empty else None
        rows.append(
            {
                "gpu_profile": g.profile_id,
                "gpu_commit": str(g.commit)[:7],
                "cpu_profile": c.profile_id,
                "same_machine": c.profile_id == g.profile_id,
                "N": int(g.n_particles),
                "protocol": f"{g.protocol}, {g.domain}",
                "cpu_loop": c.loop,
                "precision": g.precision,
                "cpu_ms": 1e3 * c.t_step,
                "gpu_ms": 1e3 * g.t_step,
                "speedup": c.t_step / g.t_step,
                "cpu_threads": None if m is None else int(m.threads),
                "speedup_all_cores": None if m is None else m.t_step / g.t_step,
            }
        )
    return rows


# ---------------------------------------------------------------- speed per particle and per pair
def speed(df) -> list[dict]:
    """ns per particle-step and per neighbour pair for every solver, model, protocol and size of the paper's
    domain.

    A neighbour pair counts once per sweep and direction: a Verlet step makes
    two sweeps over N x mean-neighbour pairs (the GPU check's ps/pair likewise).
    An all-pair search visits every pair of particles, not the neighbours: no
    ns per neighbour pair for it (None).
    """
    runs = default_numerics(latest(df[(df.status == "ok") & (df.domain == "full")]))
    rows = []
    keys = ["solver", "precision", "model", "n_particles", *PROTOCOL]
    for _, r in (
        newest_per(runs, keys)
        .sort_values(["solver", "threads", "loop", "precision", "model", "steps", "n_particles"])
        .iterrows()
    ):
        pairs = 2 * r.n_particles * r.mean_neighbours
        rows.append(
            {
                "config": label(r),
                "protocol": protocol(r),
                "model": r.model,
                "N": int(r.n_particles),
                "commit": str(r.commit)[:7],
                "ns_per_particle_step": 1e9 * r.t_step / r.n_particles,
                "ns_per_pair": 1e9 * r.t_step / pairs if pairs > 0 and r.search == "linked list" else None,
                "snp_pct": 100 * r.t_snp / (r.t_snp + r.t_pi + r.t_su),
            }
        )
    return rows


def fig9_rows(df) -> list[dict]:
    """All-pair against linked list (serial, float64, paper scene): ms per step and eta = t_AP / t_LL, by run
    length (``steps``) and N: the two sides of a row always made the same number of steps.

    One pair loop throughout: the one measured beside the most all-pair runs
    (same run length and N), the paper's gather loop on a tie, so that a few
    gather rows added by another study never switch the figure to a loop with
    fewer points. Each row names it (``linkedlist_loop``).
    """
    runs = paper_scene(df)
    serial = runs[
        (runs.device == "cpu") & (runs.search == "linked list") & (runs.threads == 1) & (runs.precision == "float64")
    ]
    everything = latest(default_numerics(df[(df.model == "lagrangian") & (df.domain == "full")]))
    ap_all = everything[everything.search == "all-pair"]
    # a run's length: the steps it made, or for a run that made none (skipped, timed out) the steps it asked for
    asked = ap_all.steps_requested.fillna(ap_all.steps) if "steps_requested" in ap_all else ap_all.steps
    length = ap_all.steps.where(ap_all.status == "ok", asked)
    ap_keys = set(zip(length.astype(int), ap_all.n_particles))
    beside = {lp: len(ap_keys & set(zip(g.steps.astype(int), g.n_particles))) for lp, g in serial.groupby("loop")}
    loop = max(beside, key=lambda lp: (beside[lp], lp == "gather")) if beside else "list"
    ll = newest_per(serial[serial.loop == loop], ["steps", "n_particles"]).set_index(["steps", "n_particles"])
    rows = []
    for (steps, n), g in ap_all.groupby([length.astype(int), "n_particles"]):
        ok = g[g.status == "ok"]
        r = (ok if not ok.empty else g).sort_values("timestamp").iloc[-1]
        key = (int(steps), n)
        row = {
            "steps": int(steps),
            "N": int(n),
            "allpair_ms": 1e3 * r.t_step if r.status == "ok" else None,
            "allpair_status": r.status,
            "allpair_note": "" if r.status == "ok" else str(r.message),
            "linkedlist_ms": 1e3 * ll.loc[key, "t_step"] if key in ll.index else None,
            "linkedlist_loop": loop,
        }
        row["eta"] = row["allpair_ms"] / row["linkedlist_ms"] if row["allpair_ms"] and row["linkedlist_ms"] else None
        rows.append(row)
    have = {(r["steps"], r["N"]) for r in rows}
    ap_steps = {r["steps"] for r in rows}
    for steps, n in ll.index:
        if (steps, n) not in have and steps in ap_steps:  # a linked-list run length all-pair never ran is not Fig. 9
            rows.append(
                {
                    "steps": int(steps),
                    "N": int(n),
                    "allpair_ms": None,
                    "allpair_status": "not run",
                    "allpair_note": "",
                    "linkedlist_ms": 1e3 * ll.loc[(steps, n), "t_step"],
                    "eta": None,
                    "linkedlist_loop": loop,
                }
            )
    return sorted(rows, key=lambda r: (r["steps"], r["N"]))


def fig9_steps(rows) -> int | None:
    """The run length Fig. 9 draws: the one with the most finished all-pair runs (then the paper's 10, then
    the fewest steps)."""
    counts = {}
    for r in rows:
        counts[r["steps"]] = counts.get(r["steps"], 0) + bool(r["allpair_ms"])
    if not counts or not max(counts.values()):
        return None
    return max(counts, key=lambda s: (counts[s], s == P.FIG9_STEPS, -s))


def runtime_series(df) -> list[dict]:
    """Fig. 10: one step (SNP + PI + SU, ms) against N, one series per configuration and protocol."""
    runs = paper_scene(df)
    out = []
    for _, g in runs.groupby(["solver", "precision", *PROTOCOL]):
        g = g.sort_values(["n_particles", "timestamp"]).drop_duplicates("n_particles", keep="last")
        r = g.iloc[0]
        out.append(
            {
                "config": label(r),
                "protocol": protocol(r),
                "run": r.protocol,
                "domain": r.domain,
                "loop": r.loop,
                "threads": int(r.threads),
                "precision": r.precision,
                "device": r.device,
                "search": r.search,
                "N": g.n_particles.astype(int).tolist(),
                "ms": (1e3 * g.t_step).tolist(),
            }
        )
    return out


# ---------------------------------------------------------------- Fig. 8 and the accuracy bars
def fit_order(dx, err) -> float:
    """Least-squares slope of log(err) against log(dx): the observed convergence order."""
    dx, err = np.asarray(dx, float), np.asarray(err, float)
    ok = np.isfinite(err) & (err > 0)
    if ok.sum() < 2:
        return float("nan")
    return float(np.polyfit(np.log(dx[ok]), np.log(err[ok]), 1)[0])


def error_series(df) -> list[dict]:
    """Fig. 8: error against dx for each (model, precision, protocol, domain), with the fitted order.

    Solvers agree to round-off, so one error per dx is kept (the newest).
    """
    acc = default_numerics(latest(df[df.status == "ok"]))
    acc = acc[(acc.protocol == "100 steps") | acc.protocol.str.startswith("t =")]  # the paper's, or fixed time
    out = []
    for (model, precision, run_protocol, domain), g in acc.groupby(["model", "precision", "protocol", "domain"]):
        g = newest_per(g, ["dx"]).sort_values("dx", ascending=False)
        if len(g) < 2:
            continue
        series = {
            "model": model,
            "precision": precision,
            "protocol": run_protocol,
            "domain": domain,
            "dx": g.dx.tolist(),
            "N": g.n_particles.astype(int).tolist(),
            "mse": g.mse.tolist(),
            "me": g.me.tolist(),
            "t_final": g.t_final.tolist(),
            "order": fit_order(g.dx, g.mse),
        }
        series["stops_falling"] = stops_falling(series["dx"], series["mse"])
        out.append(series)
    return sorted(out, key=lambda s: (s["protocol"], s["domain"], s["model"], s["precision"]))


def trend(s) -> str:
    """How a Fig. 8 series falls, in the words the figure's legend and the report both use."""
    if s["protocol"].startswith("t ="):
        if s["stops_falling"]:
            at = s["stops_falling"]
            below = [e for d, e in zip(s["dx"], s["mse"]) if d <= at]
            if below[-1] >= below[0]:  # no lower at the finest dx than at ``at``: it stopped
                return f"stops falling at dx = {at:g}"
            return f"falls by less than 25 % per halving of dx below dx = {at:g}"
        if s["model"] == "lagrangian":
            return "has not yet stopped falling over these dx"
        return f"fitted order {s['order']:.2f}"
    return f"fitted order {s['order']:.2f} (apparent: each dx ends at a different time)"


def stops_falling(dx, err, gain=0.75):
    """The dx below which refining no longer cuts the error by 25 % per halving, or None."""
    for i in range(len(dx) - 1):
        ratio = np.log(dx[i] / dx[i + 1]) / np.log(2)  # halvings between the two
        if err[i + 1] > err[i] * gain**ratio:
            return dx[i]
    return None


def accuracy_bars(series) -> list[dict]:
    """The issue's bars, from Fig. 8's ``series``: linear, Verlet, cutoff 3h, strip, t = 10 s: order >= 1 and
    < 2 % at dx = 0.05."""
    series = [
        s
        for s in series
        if s["model"] == "linear"
        and s["protocol"] == "t = 10 s"
        and s["domain"] == "strip"
        and s["precision"] == "float64"
    ]
    if not series:
        return [
            {
                "bar": "linear, t = 10 s, strip: order >= 1 and error < 2 % at dx = 0.05",
                "measured": "not measured",
                "verdict": "not measured",
            }
        ]
    s = series[0]
    at = dict(zip(np.round(s["dx"], 9), s["mse"]))
    e05 = at.get(0.05)
    return [
        {
            "bar": f"fitted order >= 1 (dx = {', '.join(f'{d:g}' for d in s['dx'])})",
            "measured": f"{s['order']:.2f}",
            "verdict": "met" if s["order"] >= 1 else "missed",
        },
        {
            "bar": "relative RMS < 2 % at dx = 0.05",
            "measured": "not measured" if e05 is None else f"{100 * e05:.2f} %",
            "verdict": "not measured" if e05 is None else "met" if e05 < 0.02 else "missed",
        },
    ]


# ---------------------------------------------------------------- cost of each simplification
SIMPLIFICATIONS = (
    # (what changes, column, baseline value, simplified value)
    ("y-periodic strip instead of the 20 m domain", "domain", "full", "strip"),
    ("fixed particles (one search) instead of lagrangian", "model", "lagrangian", "fixed"),
    ("linear (frozen coefficients) instead of lagrangian", "model", "lagrangian", "linear"),
    ("float32 instead of float64", "precision", "float64", "float32"),
)


def simplifications(df) -> list[dict]:
    """What each simplification buys (time to solution) and costs (error), same runs otherwise."""
    runs = default_numerics(latest(df[df.status == "ok"]))
    rows = []
    shared = ["solver", "threads", "loop", "model", "precision", "domain", "protocol", "dx"]
    for what, col, base, simple in SIMPLIFICATIONS:
        keys = [k for k in shared if k != col]
        for key, g in runs.groupby(keys):
            a, b = g[g[col] == base], g[g[col] == simple]
            if a.empty or b.empty:
                continue
            a, b = a.sort_values("timestamp").iloc[-1], b.sort_values("timestamp").iloc[-1]
            ctx = dict(zip(keys, key))
            rows.append(
                {
                    "simplification": what,
                    "runs": " ".join(
                        str(ctx[k]) for k in ("solver", "model", "precision", "domain", "protocol") if k in ctx
                    )
                    + f", {ctx['loop']}, {where(ctx['threads'], a.device)}",
                    "dx": ctx["dx"],
                    "N": (int(a.n_particles), int(b.n_particles)),
                    "seconds": (a.t_solution, b.t_solution),
                    "speedup": a.t_solution / b.t_solution,
                    "mse": (a.mse, b.mse),
                }
            )
    return rows


def float32_vs_float64(df, tolerance: float = 0.10) -> list[dict]:
    """float32 against float64 for the same runs: the ratio of errors, and where float32 stops converging."""
    runs = default_numerics(latest(df[df.status == "ok"]))
    out = []
    for (model, run_protocol, domain), g in runs.groupby(["model", "protocol", "domain"]):
        a = newest_per(g[g.precision == "float64"], ["dx"]).set_index("dx")
        b = newest_per(g[g.precision == "float32"], ["dx"]).set_index("dx")
        both = sorted(set(a.index) & set(b.index), reverse=True)
        if not both:
            continue
        pairs = [(d, a.loc[d, "mse"], b.loc[d, "mse"]) for d in both]
        bad = next((d for d, e64, e32 in pairs if abs(e32 / e64 - 1) > tolerance), None)
        out.append(
            {
                "model": model,
                "protocol": run_protocol,
                "domain": domain,
                "pairs": pairs,
                "stops_at": bad,
                "tolerance": tolerance,
            }
        )
    return out


# ---------------------------------------------------------------- cards side by side
def cards(df_all) -> list[dict]:
    """GPU step time by N for each measured card, precision and protocol (paper scene), ms."""
    runs = paper_scene(df_all)
    gpu = newest_per(runs[runs.device == "gpu"], ["profile_id", "precision", "n_particles", *PROTOCOL])
    rows = []
    for _, r in gpu.sort_values(["n_particles", "profile_id", "precision", "steps"]).iterrows():
        card = (profiles.stored().get(r.profile_id, {}).get("gpu") or {}).get("name", r.profile_id)
        per = per_step_ms(r)
        total = sum(per.values())
        pairs = 2 * r.n_particles * (r.mean_neighbours if np.isfinite(r.mean_neighbours or np.nan) else np.nan)
        rows.append(
            {
                "profile": r.profile_id,
                "card": card,
                "precision": r.precision,
                "N": int(r.n_particles),
                "protocol": f"{r.protocol}, {r.domain}",
                "step_ms": 1e3 * r.t_step,
                **{f"{s}_ms": v for s, v in per.items()},
                **{f"{s}_pct": 100 * v / total if total else np.nan for s, v in per.items()},
                "ns_per_particle_step": 1e9 * r.t_step / r.n_particles,
                "ps_per_pair": 1e12 * r.t_step / pairs if pairs and np.isfinite(pairs) else np.nan,
            }
        )
    return rows


def card_ceilings(rows) -> list[dict]:
    """Each measured card's ceilings (``rows``: :func:`cards`) from its profile (``pcabench gpu-check``: copy
    bandwidth, FMA rates)."""
    out = []
    for pid in sorted({r["profile"] for r in rows}):
        prof = profiles.stored().get(pid, {})
        measured = prof.get("measured") or {}
        if measured:
            out.append(
                {
                    "profile": pid,
                    "card": (prof.get("gpu") or {}).get("name", pid),
                    **{k: measured.get(k) for k in ("copy_bandwidth_tbs", "fp32_fma_tflops", "fp64_fma_tflops")},
                }
            )
    return out


def card_ratios(rows) -> list[dict]:
    """For every two measured cards (``rows``: :func:`cards`): step-time ratio at each shared N, precision and
    protocol beside their ceiling ratios."""
    ceil = {c["profile"]: c for c in card_ceilings(rows)}
    out = []
    pids = sorted(ceil)
    for i, a in enumerate(pids):
        for b in pids[i + 1 :]:
            ta = {(r["precision"], r["N"], r["protocol"]): r["step_ms"] for r in rows if r["profile"] == a}
            tb = {(r["precision"], r["N"], r["protocol"]): r["step_ms"] for r in rows if r["profile"] == b}
            for key in sorted(set(ta) & set(tb)):
                precision, n, how = key
                fma = "fp32_fma_tflops" if precision == "float32" else "fp64_fma_tflops"
                out.append(
                    {
                        "a": ceil[a]["card"],
                        "b": ceil[b]["card"],
                        "precision": precision,
                        "N": n,
                        "protocol": how,
                        "speed_ratio": tb[key] / ta[key],
                        "bandwidth_ratio": _ratio(ceil[a]["copy_bandwidth_tbs"], ceil[b]["copy_bandwidth_tbs"]),
                        "fma_ratio": _ratio(ceil[a][fma], ceil[b][fma]),
                    }
                )
    return out


def _ratio(x, y):
    return x / y if x and y else None


def cards_published() -> list[dict]:
    """The paper's cards, one step (ms) by N, one source per card: the K20c's Table 4 (measured per step),
    the other two cards' Table 6 (:mod:`pcabench.studies.paper.published` states the conversion)."""
    return [
        r
        for r in P.step_times()
        if r["device"] == "gpu" and r["source"] == ("Table 4" if r["system"] == "paper-system-1" else "Table 6")
    ]


def table4_of(ctx) -> list[dict]:
    """Table 4 of a report's machine, computed once per report (Table 5 and Fig. 13 read it too)."""
    return ctx.once("table4", lambda: table4(ctx.df))


def table6_of(ctx) -> list[dict]:
    """Table 6 across every machine, computed once for every report and the cards page (``"table6"``)."""
    return ctx.once("table6", lambda: table6(ctx.df_all), across_machines=True)
