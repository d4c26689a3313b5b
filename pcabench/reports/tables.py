"""The numbers behind every table and figure, computed from the store's DataFrame.

Pure functions: a DataFrame from ``store.load`` in, lists of dicts out (one
per table row), so the values can be tested without drawing anything. Times
are s in the store and ms per step in the tables; errors are the paper's
relative RMS ("MSE") of u.
"""
from __future__ import annotations

import numpy as np
import pandas as pd

from pcabench import profiles
from pcabench.record import STEP_STAGES
from solvers import NUMERICS, STAGES, Scene

PAPER_SYSTEMS = ("paper-system-1", "paper-system-2", "paper-system-3")
# The scene's numerics unless a study varies them (Scene's defaults: Verlet, CFL, h/dx, cutoff).
DEFAULT_NUMERICS = {name: Scene.default(name) for name in NUMERICS}
# The exact isothermal solution at Ma = 0.05 against the linear pulse (design 1b; solvers/isothermal1d.py).
ISOTHERMAL_VS_LINEAR = {5.0: 0.051, 10.0: 0.098}


def published(system: str = "paper-system-1") -> dict:
    """The paper's published numbers for ``system`` (hardware_profiles/paper-system-*.json)."""
    return profiles.load(system)["published"]


def label(r) -> str:
    """``solver precision``, ``xN`` for a multi-threaded run, and ``[list]`` or ``[gather]``, the pair loop
    of a linked-list CPU run (rows made before the pair list have none: they used the gather loop)."""
    loop = f" [{r['pair_loop']}]" if r["solver"] == "linkedlist-cpu" and r.get("pair_loop") else ""
    return f"{r['solver']} {r['precision']}" + (f" x{int(r['threads'])}" if int(r["threads"]) > 1 else "") + loop


def latest(df: pd.DataFrame) -> pd.DataFrame:
    """One row per configuration and machine, the newest: reruns and overlapping presets count once."""
    return df if df.empty else _newest_per(df, ["profile_id", "solver", "threads", "pair_loop", "scene_key"])


def default_numerics(df: pd.DataFrame) -> pd.DataFrame:
    mask = np.ones(len(df), bool)
    for key, value in DEFAULT_NUMERICS.items():
        col = df[key]
        mask &= (col == value) if isinstance(value, str) else np.isclose(col.astype(float), value)
    return df[mask]


def paper_scene(df: pd.DataFrame) -> pd.DataFrame:
    """Finished runs of the paper's timing scene: lagrangian, full domain, default numerics."""
    d = default_numerics(df[(df.status == "ok") & (df.model == "lagrangian") & (df.domain == "full")])
    return latest(d)


def per_step_ms(r) -> dict:
    steps = max(int(r["steps"]), 1)
    return {s: 1e3 * r[f"t_{s}"] / steps for s in STEP_STAGES}


def _newest_per(df, keys):
    return df.sort_values("timestamp").drop_duplicates(keys, keep="last")


# ---------------------------------------------------------------- Tables 4, 5 and Figs. 11, 13
def paper_cpu_step_ms() -> dict:
    """The paper's serial CPU step (Xeon E5-2680), ms, by N: its 400K figure and Table 6's CPU runs / 100 steps
    (read as s, as for its GPU column)."""
    pub = published()
    out = {int(n): 1e3 * cpu / 100 for n, (cpu, _gpu, _s) in pub["table6"]["rows"].items()}
    out[400_000] = pub["text"]["cpu_vs_gpu_step_400k_ms"]["cpu"]
    return dict(sorted(out.items()))


def table4(df) -> list[dict]:
    """Stage times by N: input, init, output in ms per run; SNP, PI, SU in ms per step.

    ``paper`` is the paper's number for the same kind of processor: its K20c
    stage times (Table 4) beside a GPU row, its serial CPU step beside a CPU row.
    """
    t4 = published()["table4"]["rows"]
    cpu_ms = paper_cpu_step_ms()
    rows = []
    keys = ["solver", "precision", "threads", "pair_loop", "n_particles"]
    for _, r in _newest_per(paper_scene(df), keys).sort_values(keys).iterrows():
        row = {"config": label(r), "N": int(r.n_particles), "commit": str(r.commit)[:7]}
        row.update({s: 1e3 * r[f"t_{s}"] for s in ("input", "init", "output")})
        row.update(per_step_ms(r))
        if r.solver == "linkedlist-gpu":
            row["paper"], row["paper_kind"] = t4.get(str(int(r.n_particles))), "gpu"
        else:
            row["paper"], row["paper_kind"] = cpu_ms.get(int(r.n_particles)), "cpu"
        rows.append(row)
    return rows


def table5(df) -> list[dict]:
    """Each step stage's share of a step, %, with the paper's (GPU, Table 5) beside it."""
    t5 = published()["table5"]["rows"]
    cpu = published()["text"]["fig11_cpu_step_shares_pct"]
    rows = []
    for row in table4(df):
        total = sum(row[s] for s in STEP_STAGES)
        if not total > 0:
            continue  # no timed step: no shares
        if row["paper_kind"] == "gpu":  # Table 5 is the paper's GPU; its Fig. 11 text gives its serial CPU
            paper = t5.get(str(row["N"]))
        else:
            paper = [cpu["snp"], cpu["pi"], 100 - cpu["snp"] - cpu["pi"]]
        rows.append({"config": row["config"], "N": row["N"],
                     **{s: 100 * row[s] / total for s in STEP_STAGES}, "paper": paper})
    return rows


def one_step_shares(df) -> list[dict]:
    """Fig. 13: each of the six stages' share of a one-step run, %: input + init + one step + output."""
    rows = []
    for row in table4(df):
        total = sum(row[s] for s in STAGES)
        rows.append({"config": row["config"], "N": row["N"], **{s: 100 * row[s] / total for s in STAGES}})
    return rows


# ---------------------------------------------------------------- Table 6 and Fig. 14
def table6(df_all) -> list[dict]:
    """CPU (serial linked list, float64) against GPU per step at the same N, for each GPU profile.

    The CPU is taken from the same machine where it was measured there, else
    from another measured machine, and the row says which.
    """
    runs = paper_scene(df_all)
    gpu = runs[runs.solver == "linkedlist-gpu"]
    cpu = runs[(runs.solver == "linkedlist-cpu") & (runs.precision == "float64")]
    rows = []
    for _, g in _newest_per(gpu, ["profile_id", "precision", "n_particles"]) \
            .sort_values(["profile_id", "n_particles", "precision"]).iterrows():
        same_n = cpu[cpu.n_particles == g.n_particles]
        serial = same_n[same_n.threads == 1]
        if serial.empty:
            continue
        here = serial[serial.profile_id == g.profile_id]
        c = (here if not here.empty else serial).sort_values("timestamp").iloc[-1]
        multi = same_n[(same_n.threads > 1) & (same_n.profile_id == c.profile_id)]
        m = multi.sort_values("threads").iloc[-1] if not multi.empty else None
        rows.append({"gpu_profile": g.profile_id, "cpu_profile": c.profile_id, "same_machine": c.profile_id ==
                     g.profile_id, "N": int(g.n_particles),
                     "precision": g.precision, "cpu_ms": 1e3 * c.t_step, "gpu_ms": 1e3 * g.t_step,
                     "speedup": c.t_step / g.t_step,
                     "cpu_threads": None if m is None else int(m.threads),
                     "speedup_all_cores": None if m is None else m.t_step / g.t_step})
    return rows


def table6_published() -> list[dict]:
    rows = []
    for system in PAPER_SYSTEMS:
        prof = profiles.load(system)
        for n, (cpu, gpu, speedup) in prof["published"]["table6"]["rows"].items():
            rows.append({"system": system, "card": prof["gpu"]["name"], "N": int(n), "cpu": cpu, "gpu": gpu,
                         "speedup": speedup})
    return sorted(rows, key=lambda r: (r["system"], r["N"]))


# ---------------------------------------------------------------- speed per particle and per pair
def speed(df) -> list[dict]:
    """ns per particle-step and per neighbour pair for every solver, model and size of the paper's domain.

    A neighbour pair counts once per sweep and direction: a Verlet step makes
    two sweeps over N x mean-neighbour pairs (the GPU check's ps/pair likewise).
    """
    runs = default_numerics(latest(df[(df.status == "ok") & (df.domain == "full")]))
    rows = []
    keys = ["solver", "threads", "pair_loop", "precision", "model", "n_particles"]
    for _, r in _newest_per(runs, keys).sort_values(keys).iterrows():
        pairs = 2 * r.n_particles * r.mean_neighbours
        rows.append({"config": label(r), "model": r.model, "N": int(r.n_particles), "commit": str(r.commit)[:7],
                     "ns_per_particle_step": 1e9 * r.t_step / r.n_particles,
                     "ns_per_pair": 1e9 * r.t_step / pairs if pairs > 0 else None,  # NaN neighbours: None
                     "snp_pct": 100 * r.t_snp / (r.t_snp + r.t_pi + r.t_su)})
    return rows


# ---------------------------------------------------------------- Fig. 9
FIG9_LOOP_NAMES = {"gather": "the paper's gather loop", "list": "the pair list"}  # by ``linkedlist_loop``


def fig9(df) -> list[dict]:
    """All-pair against linked list (serial, float64, paper scene): ms per step and eta = t_AP / t_LL.

    One pair loop throughout: the paper's gather loop where it was measured ('' is a run from before the
    pair list, which had only that loop), so that eta means what the paper's does; else the pair list.
    Each row names it (``linkedlist_loop``).
    """
    runs = paper_scene(df)
    serial = runs[(runs.solver == "linkedlist-cpu") & (runs.threads == 1) & (runs.precision == "float64")]
    gather = serial.pair_loop.isin(["gather", ""])
    loop = "gather" if gather.any() else "list"
    ll = _newest_per(serial[gather] if gather.any() else serial[serial.pair_loop == "list"],
                     ["n_particles"]).set_index("n_particles")
    ap_all = latest(default_numerics(df[(df.solver == "allpair-cpu") & (df.model == "lagrangian")
                                        & (df.domain == "full")]))
    rows = []
    for n, g in ap_all.groupby("n_particles"):
        ok = g[g.status == "ok"]
        r = (ok if not ok.empty else g).sort_values("timestamp").iloc[-1]
        row = {"N": int(n), "allpair_ms": 1e3 * r.t_step if r.status == "ok" else None,
               "allpair_status": r.status, "allpair_note": "" if r.status == "ok" else str(r.message)[:160],
               "linkedlist_ms": 1e3 * ll.loc[n, "t_step"] if n in ll.index else None, "linkedlist_loop": loop}
        row["eta"] = (row["allpair_ms"] / row["linkedlist_ms"]
                      if row["allpair_ms"] and row["linkedlist_ms"] else None)
        rows.append(row)
    for n in ll.index:
        if n not in {r["N"] for r in rows}:
            rows.append({"N": int(n), "allpair_ms": None, "allpair_status": "not run", "allpair_note": "",
                         "linkedlist_ms": 1e3 * ll.loc[n, "t_step"], "eta": None, "linkedlist_loop": loop})
    return sorted(rows, key=lambda r: r["N"])


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
    for (model, precision, protocol, domain), g in acc.groupby(["model", "precision", "protocol", "domain"]):
        g = _newest_per(g, ["dx"]).sort_values("dx", ascending=False)
        if len(g) < 2:
            continue
        series = {"model": model, "precision": precision, "protocol": protocol, "domain": domain,
                  "dx": g.dx.tolist(), "N": g.n_particles.astype(int).tolist(), "mse": g.mse.tolist(),
                  "me": g.me.tolist(), "t_final": g.t_final.tolist(), "order": fit_order(g.dx, g.mse)}
        series["stops_falling"] = stops_falling(series["dx"], series["mse"])
        out.append(series)
    return sorted(out, key=lambda s: (s["protocol"], s["domain"], s["model"], s["precision"]))


def stops_falling(dx, err, gain=0.75):
    """The dx below which refining no longer cuts the error by 25 % per halving, or None."""
    for i in range(len(dx) - 1):
        ratio = np.log(dx[i] / dx[i + 1]) / np.log(2)  # halvings between the two
        if err[i + 1] > err[i] * gain ** ratio:
            return dx[i]
    return None


def accuracy_bars(df) -> list[dict]:
    """The issue's bars: linear, Verlet, cutoff 3h, strip, t = 10 s: order >= 1 and < 2 % at dx = 0.05."""
    series = [s for s in error_series(df) if s["model"] == "linear" and s["protocol"] == "t = 10 s"
              and s["domain"] == "strip" and s["precision"] == "float64"]
    if not series:
        return [{"bar": "linear, t = 10 s, strip: order >= 1 and error < 2 % at dx = 0.05",
                 "measured": "not measured", "verdict": "not measured"}]
    s = series[0]
    at = dict(zip(np.round(s["dx"], 9), s["mse"]))
    e05 = at.get(0.05)
    return [
        {"bar": f"fitted order >= 1 (dx = {', '.join(f'{d:g}' for d in s['dx'])})",
         "measured": f"{s['order']:.2f}", "verdict": "met" if s["order"] >= 1 else "missed"},
        {"bar": "relative RMS < 2 % at dx = 0.05", "measured": "not measured" if e05 is None else f"{100 * e05:.2f} %",
         "verdict": "not measured" if e05 is None else "met" if e05 < 0.02 else "missed"},
    ]


# ---------------------------------------------------------------- speed against accuracy
def numerics_label(r) -> str:
    """The method of a run: kernel, h/dx, cutoff (Gaussian only) and CFL."""
    kern = r.get("kernel") or "gaussian"
    cut = f", {r['cutoff_factor']:g}h" if kern == "gaussian" else ""
    return f"{kern}, h {r['h_factor']:g}dx{cut}, CFL {r['cfl']:g}"


def is_paper_method(r) -> bool:
    """The paper's numerics: the Gaussian at Scene's default h/dx, cutoff, CFL and integrator."""
    return (r.get("kernel") or "gaussian") == "gaussian" and all(
        (r[k] == v) if isinstance(v, str) else bool(np.isclose(float(r[k]), v)) for k, v in DEFAULT_NUMERICS.items())


FRONT_MODELS = ("linear", "lagrangian")  # fixed solves neither equation: it is in the simplifications' table


def speed_front(df) -> tuple[list[dict], list[dict]]:
    """Error against time to solution at a fixed physical time: every finished run, and each model's front.

    Time to solution is init + SNP + PI + SU (s), without JIT, input and output.
    Every method counts (kernel, h/dx, cutoff, CFL, dx, precision). A run's
    ``error`` is against what its model converges to: the linear pulse for
    `linear`, the isothermal solution for `lagrangian` (its error against the
    linear pulse never falls below the two equations' 9.8 % difference; rows
    from before that was measured are left out). The front of a model at a
    time holds the runs no faster run of that model beats in error.
    """
    from pcabench.advise import error_column

    pts = latest(df[(df.status == "ok") & df.protocol.str.startswith("t =") & df.model.isin(FRONT_MODELS)])
    points = []
    for _, r in pts.iterrows():
        error = r[error_column(r.model)]
        if error is None or not np.isfinite(error):
            continue
        points.append({"config": label(r), "method": numerics_label(r), "paper_method": is_paper_method(r),
                       "kernel": r.get("kernel") or "gaussian", "h_factor": r.h_factor, "cfl": r.cfl,
                       "integrator": r.integrator, "cutoff_factor": r.cutoff_factor, "precision": r.precision,
                       "model": r.model, "domain": r.domain, "dx": r.dx, "N": int(r.n_particles),
                       "t_final": r.t_final, "seconds": r.t_solution, "error": float(error), "mse": r.mse,
                       "strip_height": r.strip_height, "solver": r.solver, "threads": int(r.threads),
                       "commit": str(r.commit)})
    front = []
    for t_final, model in sorted({(p["t_final"], p["model"]) for p in points}):
        best = np.inf
        for p in sorted((p for p in points if p["t_final"] == t_final and p["model"] == model),
                        key=lambda p: (p["seconds"], p["error"])):
            if p["error"] < best:
                best = p["error"]
                front.append(p)
    return points, front


def comparable(a, b) -> bool:
    """Two runs whose times compare: the same kind of domain (on a strip each method has its own thinnest
    strip), the same threads, and the same code (commit): speed changes from commit to commit."""
    return a["domain"] == b["domain"] and int(a["threads"]) == int(b["threads"]) and a["commit"] == b["commit"]


def predicted_error(p: dict) -> float:
    """The error the dispersion relation predicts for front point ``p`` (its linear part; solvers/dispersion.py)."""
    from solvers.dispersion import predict

    scene = {"kernel": p["kernel"], "h_factor": p["h_factor"], "cfl": p["cfl"], "integrator": p["integrator"]}
    if p["kernel"] == "gaussian":
        scene["cutoff_factor"] = p.get("cutoff_factor") or Scene.default("cutoff_factor")
    strip = p.get("strip_height")
    strip = None if strip is None or (isinstance(strip, float) and np.isnan(strip)) else strip
    return predict(Scene(dx=p["dx"], t_end=p["t_final"], model="linear", strip_height=strip,
                         memory_limit_bytes=2**62, **scene)).predicted_error


def predicted_by_model(df, dxs=(0.4, 0.2, 0.1)) -> list[dict]:
    """Measured against predicted error for every model: the paper's method on the strip at t = 10 s."""
    d = latest(paper_method_rows(df[(df.status == "ok") & (df.domain == "strip") & (df.protocol == "t = 10 s")]))
    rows = []
    for model in ("linear", "fixed", "lagrangian"):
        for dx in dxs:
            r = d[(d.model == model) & np.isclose(d.dx.astype(float), dx) & (d.precision == "float64")]
            if r.empty:
                continue
            r = r.sort_values("timestamp").iloc[-1]
            p = {"kernel": "gaussian", "h_factor": r.h_factor, "cfl": r.cfl, "integrator": r.integrator,
                 "cutoff_factor": r.cutoff_factor, "dx": dx, "t_final": r.t_final, "strip_height": r.strip_height}
            rows.append({"model": model, "dx": dx, "measured": r.mse, "predicted": predicted_error(p),
                         "isothermal": r.mse_isothermal})
    return rows


def paper_method_rows(df):
    """The rows of the paper's numerics (``is_paper_method``)."""
    return df[[is_paper_method(r) for _, r in df.iterrows()]] if not df.empty else df


def fastest_to(points, targets=(0.10, 0.05, 0.02, 0.01, 0.005)) -> list[dict]:
    """For each time, model and error target: the fastest run reaching it, the fastest run of the paper's
    method reaching it, and how many times faster the first is."""
    rows = []
    for t_final, model in sorted({(p["t_final"], p["model"]) for p in points}):
        pts = sorted((p for p in points if p["t_final"] == t_final and p["model"] == model), key=lambda p: p["seconds"])
        for target in targets:
            hit = next((p for p in pts if p["error"] <= target), None)
            paper = hit and next((p for p in pts if p["error"] <= target and p["paper_method"] and comparable(p, hit)),
                                 None)
            rows.append({"t_final": t_final, "model": model, "target": target, "best": hit, "paper": paper,
                         "speedup": paper["seconds"] / hit["seconds"] if hit and paper else None})
    return rows


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
    shared = ["solver", "threads", "model", "precision", "domain", "protocol", "dx"]
    for what, col, base, simple in SIMPLIFICATIONS:
        keys = [k for k in shared if k != col]
        for key, g in runs.groupby(keys):
            a, b = g[g[col] == base], g[g[col] == simple]
            if a.empty or b.empty:
                continue
            a, b = a.sort_values("timestamp").iloc[-1], b.sort_values("timestamp").iloc[-1]
            ctx = dict(zip(keys, key))
            rows.append({"simplification": what,
                         "runs": " ".join(str(ctx[k]) for k in ("solver", "model", "precision", "domain", "protocol")
                                          if k in ctx) + (f" x{ctx['threads']}" if ctx.get("threads", 1) > 1 else ""),
                         "dx": ctx["dx"], "N": (int(a.n_particles), int(b.n_particles)),
                         "seconds": (a.t_solution, b.t_solution), "speedup": a.t_solution / b.t_solution,
                         "mse": (a.mse, b.mse)})
    return rows


# ---------------------------------------------------------------- stability
def _step_or_none(x):
    return None if x is None or not np.isfinite(x) else int(x)


def classify(r, inaccurate_above: float) -> str:
    """stable / inaccurate (bounded, error above the bar) / unstable, or the failed run's status."""
    if r["status"] == "ok":
        return "stable" if r["mse"] <= inaccurate_above else "inaccurate"
    return r["status"]


def stability(df, inaccurate_above: float) -> tuple[list[dict], list[dict]]:
    """The stability map's points and, per configuration, the largest CFL up to which every run is stable."""
    runs = latest(df[df.preset == "stability"])
    runs = runs[runs.protocol.str.startswith("t =")]
    points, limits = [], []
    for (integ, h, precision, protocol, dx), g in runs.groupby(["integrator", "h_factor", "precision", "protocol",
                                                               "dx"]):
        g = g.sort_values("cfl")
        name = f"{integ}, h = {h:g} dx, {precision}, {protocol}"
        limit, bounded, first_bad, first_unbounded = None, None, None, None
        for _, r in g.iterrows():
            cls = classify(r, inaccurate_above)
            step = _step_or_none(r.failed_step)
            points.append({"config": name, "cfl": r.cfl, "class": cls, "mse": r.mse,
                           "failed_step": step, "steps": r.steps_requested})
            if first_bad is None:
                if cls == "stable":
                    limit = r.cfl
                else:
                    first_bad = (r.cfl, cls, step, r.mse)
            if first_unbounded is None:
                if cls in ("stable", "inaccurate"):
                    bounded = r.cfl
                else:
                    first_unbounded = (r.cfl, cls, step)
        limits.append({"config": name, "integrator": integ, "h_factor": h, "precision": precision,
                       "protocol": protocol, "dx": dx, "cfls": g.cfl.tolist(), "stable_up_to": limit,
                       "first_failure": first_bad, "bounded_up_to": bounded, "first_unbounded": first_unbounded})
    return points, limits


def float32_vs_float64(df, tolerance: float = 0.10) -> list[dict]:
    """float32 against float64 for the same runs: the ratio of errors, and where float32 stops converging."""
    runs = default_numerics(latest(df[df.status == "ok"]))
    out = []
    for (model, protocol, domain), g in runs.groupby(["model", "protocol", "domain"]):
        a = _newest_per(g[g.precision == "float64"], ["dx"]).set_index("dx")
        b = _newest_per(g[g.precision == "float32"], ["dx"]).set_index("dx")
        both = sorted(set(a.index) & set(b.index), reverse=True)
        if not both:
            continue
        pairs = [(d, a.loc[d, "mse"], b.loc[d, "mse"]) for d in both]
        bad = next((d for d, e64, e32 in pairs if abs(e32 / e64 - 1) > tolerance), None)
        out.append({"model": model, "protocol": protocol, "domain": domain, "pairs": pairs,
                    "stops_at": bad, "tolerance": tolerance})
    return out


# ---------------------------------------------------------------- cards side by side
def cards(df_all) -> list[dict]:
    """GPU step time by N for each measured card and precision (paper scene), ms."""
    runs = paper_scene(df_all)
    gpu = _newest_per(runs[runs.solver == "linkedlist-gpu"], ["profile_id", "precision", "n_particles"])
    rows = []
    for _, r in gpu.sort_values(["n_particles", "profile_id", "precision"]).iterrows():
        card = (profiles.stored().get(r.profile_id, {}).get("gpu") or {}).get("name", r.profile_id)
        per = per_step_ms(r)
        total = sum(per.values())
        pairs = 2 * r.n_particles * (r.mean_neighbours if np.isfinite(r.mean_neighbours or np.nan) else np.nan)
        rows.append({"profile": r.profile_id, "card": card, "precision": r.precision, "N": int(r.n_particles),
                     "step_ms": 1e3 * r.t_step, **{f"{s}_ms": v for s, v in per.items()},
                     **{f"{s}_pct": 100 * v / total if total else np.nan for s, v in per.items()},
                     "ns_per_particle_step": 1e9 * r.t_step / r.n_particles,
                     "ps_per_pair": 1e12 * r.t_step / pairs if pairs and np.isfinite(pairs) else np.nan})
    return rows


def card_ceilings(df_all) -> list[dict]:
    """Each measured card's ceilings from its profile (``pcabench gpu-check``: copy bandwidth, FMA rates)."""
    out = []
    for pid in sorted({r["profile"] for r in cards(df_all)}):
        prof = profiles.stored().get(pid, {})
        measured = prof.get("measured") or {}
        if measured:
            out.append({"profile": pid, "card": (prof.get("gpu") or {}).get("name", pid),
                        **{k: measured.get(k) for k in ("copy_bandwidth_tbs", "fp32_fma_tflops", "fp64_fma_tflops")}})
    return out


def card_ratios(df_all) -> list[dict]:
    """For every two measured cards: step-time ratio at each shared N and precision beside their ceiling ratios."""
    rows, ceil = cards(df_all), {c["profile"]: c for c in card_ceilings(df_all)}
    out = []
    pids = sorted(ceil)
    for i, a in enumerate(pids):
        for b in pids[i + 1:]:
            ta = {(r["precision"], r["N"]): r["step_ms"] for r in rows if r["profile"] == a}
            tb = {(r["precision"], r["N"]): r["step_ms"] for r in rows if r["profile"] == b}
            for precision, n in sorted(set(ta) & set(tb)):
                fma = "fp32_fma_tflops" if precision == "float32" else "fp64_fma_tflops"
                out.append({"a": ceil[a]["card"], "b": ceil[b]["card"], "precision": precision, "N": n,
                            "speed_ratio": tb[(precision, n)] / ta[(precision, n)],
                            "bandwidth_ratio": _ratio(ceil[a]["copy_bandwidth_tbs"], ceil[b]["copy_bandwidth_tbs"]),
                            "fma_ratio": _ratio(ceil[a][fma], ceil[b][fma])})
    return out


def _ratio(x, y):
    return x / y if x and y else None


def cards_published() -> list[dict]:
    """The paper's cards: K20c one step from Table 4 (ms), all three from Table 6 / 100 steps (read as s)."""
    rows = []
    for n, v in published()["table4"]["rows"].items():
        rows.append({"system": "paper-system-1", "card": "Tesla K20c", "N": int(n), "step_ms": sum(v[2:5]),
                     "source": "Table 4"})
    for r in table6_published():
        rows.append({"system": r["system"], "card": r["card"], "N": r["N"], "step_ms": 1e3 * r["gpu"] / 100,
                     "source": "Table 6 / 100 steps, read as s"})
    return rows
