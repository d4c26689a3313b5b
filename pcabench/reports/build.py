"""Write the Markdown reports: one per measured profile, the card comparison, and the index.

    reports/<profile>/report.md   Tables 4-6, Figs. 8-11, 13, speed vs accuracy,
                                  cost of simplifications, stability map, failed runs
    reports/cards.md              Table 6 and Fig. 14 across systems, GPU cards side by side
    reports/README.md             the index
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from pcabench import profiles, store
from pcabench.errors import NoResults
from pcabench.presets import INACCURATE_ABOVE
from solvers import Scene

from . import figures as F
from . import tables as T



def md_table(header, rows) -> str:
    out = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    out += ["| " + " | ".join(str(c) for c in row) + " |" for row in rows]
    return "\n".join(out)


def fmt(x, spec=".3g") -> str:
    if x is None or (isinstance(x, float) and not np.isfinite(x)):
        return "-"
    return format(x, spec)


def pct(x) -> str:
    return fmt(None if x is None else 100 * x, ".2f") + (" %" if x is not None and np.isfinite(x) else "")


def _machine(pid: str) -> str:
    prof = profiles.stored().get(pid)
    if not prof:
        return "profile not stored"
    cpu = prof.get("cpu") or {}
    gpu = prof.get("gpu") or {}
    text = f"CPU {cpu.get('model', '?')} ({cpu.get('cores_usable', cpu.get('logical_cores', '?'))} cores usable)"
    if gpu:
        text += f"; GPU {gpu.get('name')} ({fmt(gpu.get('memory_bytes', 0) / 2**30, '.0f')} GiB, " \
                f"CC {gpu.get('compute_capability')})"
    return text


def _sections_timing(df) -> list[str]:
    lines = []
    rows4 = T.table4(df)
    if rows4:
        lines += ["## Table 4: stage times (the paper's scene: lagrangian, full domain)", "",
                  "input, init and output in ms per run; SNP, PI and SU in ms per step. The paper's column compares "
                  "like with like: beside a GPU row its Table 4 (Tesla K20c, one step, ms: input / init / SNP / PI "
                  "/ SU / output), beside a CPU row its serial CPU step (Xeon E5-2680, ms: the 400K figure of its "
                  "text, and its Table 6 CPU runs / 100 steps). `[list]` and `[gather]` name the linked list's "
                  "pair loop (gather is the paper's); rows without one predate the pair list and used gather.", "",
                  md_table(["config", "N", "input", "init", "SNP", "PI", "SU", "output", "commit",
                            "paper, same kind (published)"],
                           [[r["config"], f"{r['N']:,}", fmt(r["input"], ".2f"), fmt(r["init"], ".2f"),
                             fmt(r["snp"], ".3f"), fmt(r["pi"], ".3f"), fmt(r["su"], ".3f"), fmt(r["output"], ".2f"),
                             r["commit"], _paper_cell(r)] for r in rows4]), "",
                  "## Table 5 and Fig. 11: share of a step", "",
                  "The paper's column compares like with like: beside a GPU row its Table 5 (Tesla K20c), beside a "
                  "CPU row its Fig. 11 (serial CPU: about 43 % SNP and 53 % PI, all N).", "",
                  md_table(["config", "N", "SNP %", "PI %", "SU %", "paper, same kind: SNP / PI / SU % (published)"],
                           [[r["config"], f"{r['N']:,}", fmt(r["snp"], ".1f"), fmt(r["pi"], ".1f"),
                             fmt(r["su"], ".1f"), " / ".join(f"{v:g}" for v in r["paper"]) if r["paper"] else "-"]
                            for r in T.table5(df)]), ""]
    return lines


def _paper_cell(r) -> str:
    if r["paper"] is None:
        return "-"
    if r["paper_kind"] == "gpu":
        return "K20c " + " / ".join(f"{v:g}" for v in r["paper"])
    return f"CPU step {r['paper']:g}"


def _section_table6(df_all, pid) -> list[str]:
    rows = [r for r in T.table6(df_all) if pid in (r["gpu_profile"],)]
    if not rows:
        return []
    same = [r for r in rows if r["same_machine"]]
    other = [r for r in rows if not r["same_machine"]]
    lines = ["## Table 6: CPU against GPU, one step", "",
             "Speedups from one machine only: this GPU against its own host's CPU (linkedlist-cpu float64), one "
             "thread (as the paper's) and every core (the honest peer). See [cards.md](../cards.md) for every "
             "system.", ""]
    lines += [_table6_md(same) if same else
              "No CPU run of the paper's scene on this GPU's host yet: no same-machine speedup to show "
              "(`pcabench gpu-check` times the host's CPU too).", ""]
    if other:
        lines += ["### Across machines (not a speedup of one machine)", "",
                  "This GPU's times against a CPU measured on another machine, named per row: a comparison of "
                  "two computers, not what a GPU buys one of them.", "", _table6_md(other), ""]
    return lines


def _table6_md(rows) -> str:
    return md_table(["N", "GPU precision", "GPU ms", "CPU (profile)", "CPU ms", "speedup", "speedup vs all cores"],
                    [[f"{r['N']:,}", r["precision"], fmt(r["gpu_ms"], ".3f"), r["cpu_profile"],
                      fmt(r["cpu_ms"], ".1f"), fmt(r["speedup"], ".1f"),
                      "-" if r["speedup_all_cores"] is None else f"{r['speedup_all_cores']:.1f} "
                                                                  f"(x{r['cpu_threads']})"] for r in rows])


def _section_speed(df) -> list[str]:
    rows = T.speed(df)
    if not rows:
        return []
    return ["## Speed per particle-step and per neighbour pair (the paper's domain)", "",
            "One step (SNP + PI + SU) per particle, and per neighbour pair (two sweeps over N x mean neighbours "
            "pairs per Verlet step). `[list]`: each pair once per search with its kernel factors; `[gather]`: "
            "the paper's loop over each particle's stencil in every sweep.", "",
            md_table(["config", "model", "N", "ns per particle-step", "ns per pair", "SNP %", "commit"],
                     [[r["config"], r["model"], f"{r['N']:,}", fmt(r["ns_per_particle_step"], ".0f"),
                       fmt(r["ns_per_pair"], ".2f"), fmt(r["snp_pct"], ".1f"), r["commit"]] for r in rows]), ""]


def _section_fig9(df) -> list[str]:
    rows = T.fig9(df)
    if not any(r["allpair_ms"] or r["allpair_status"] == "skipped" for r in rows):
        return []
    text = T.published()["text"]
    return ["## Fig. 9: all-pair against linked list (serial, float64, paper's scene)", "",
            f"Linked list: {T.FIG9_LOOP_NAMES[rows[0]['linkedlist_loop']]}"
            + ("." if rows[0]["linkedlist_loop"] == "gather"
               else " (no gather-loop runs stored; `--pair-loop gather` measures the paper's)."), "",
            md_table(["N", "all-pair ms/step", "linked list ms/step", "eta = t_AP / t_LL", "all-pair status"],
                     [[f"{r['N']:,}", fmt(r["allpair_ms"], ".2f"), fmt(r["linkedlist_ms"], ".2f"),
                       fmt(r["eta"], ".1f"), r["allpair_status"] + (f": {r['allpair_note']}" if r["allpair_note"]
                                                                   else "")] for r in rows]), "",
            "Paper (published, whole runs, s): all-pair " + ", ".join(
                f"{v:g} s at {int(n):,}" for n, v in text["fig9_allpair_s"].items()) + "; linked list " + ", ".join(
                f"{v:g} s at {int(n):,}" for n, v in text["fig9_linkedlist_s"].items()) + ".", ""]


def _lagrangian_note(s) -> str:
    t = s["t_final"][0] if len(set(np.round(s["t_final"], 6))) == 1 else None
    ref = T.ISOTHERMAL_VS_LINEAR.get(round(t, 6)) if t else None
    where = (f"It stops falling at dx = {s['stops_falling']:g}" if s["stops_falling"] else
             "It has not yet stopped falling over these dx")
    return (f"{where} ({', '.join(pct(e) for e in s['mse'])} for dx = {', '.join(f'{d:g}' for d in s['dx'])}). "
            "The lagrangian model solves the isothermal (nonlinear) equations at Ma = 0.05, not the linear "
            "ones, so against the linear pulse its error tends to the difference between the two solutions"
            + (f", {pct(ref)} at t = {t:g} s," if ref else "") + " however small dx gets; coarse lattices score "
            "lower only because their numerical smoothing hides the nonlinear steepening. No order is fitted.")


def _section_fig8(df) -> list[str]:
    series = T.error_series(df)
    if not series:
        return []
    lines = ["## Fig. 8: error against dx", "",
             "Relative RMS error of u against the analytic pulse (the paper's MSE) and max error ME (m/s). "
             "`t = 10 s` is a fixed physical time, the honest protocol for convergence; `100 steps` is the paper's, "
             "a different physical time (20 dx s) for each dx.", ""]
    rows = []
    for s in series:
        for dx, n, mse, me, t in zip(s["dx"], s["N"], s["mse"], s["me"], s["t_final"]):
            rows.append([s["model"], s["precision"], s["protocol"], s["domain"], f"{dx:g}", f"{n:,}", f"{t:g}",
                         fmt(mse, ".4g"), fmt(me, ".3g")])
    lines += [md_table(["model", "precision", "protocol", "domain", "dx", "N", "t (s)", "MSE", "ME"], rows), ""]
    for s in series:
        head = f"- {s['model']} {s['precision']}, {s['protocol']}, {s['domain']}: "
        if s["model"] == "lagrangian" and s["protocol"].startswith("t ="):
            lines.append(head + _lagrangian_note(s))
        elif s["stops_falling"] and s["protocol"].startswith("t ="):
            lines.append(head + f"its error stops falling at dx = {s['stops_falling']:g} "
                         f"({', '.join(pct(e) for e in s['mse'])} for dx = {', '.join(f'{d:g}' for d in s['dx'])})"
                         + ("; the fixed model keeps the nonlinear rho div(u) term of the paper's equations but "
                            "drops the advection terms (u . grad), so it solves neither the linear nor the "
                            "isothermal equations and its error against the linear pulse stays large"
                            if s["model"] == "fixed" else "") + ". No order is fitted.")
        else:
            lines.append(head + f"fitted order {s['order']:.2f}" + (
                " (apparent: each dx ends at a different time)" if s["protocol"].endswith("steps") else "") + ".")
    bars = [b for b in T.accuracy_bars(df) if b["verdict"] != "not measured" or b["bar"].startswith("relative")]
    if bars:
        lines += ["", "### Accuracy bars (linear, Verlet, cutoff 3h, strip, t = 10 s, float64)", "",
                  md_table(["bar", "measured", "verdict"], [[b["bar"], b["measured"], b["verdict"]] for b in bars]),
                  ""]
    return lines


def _section_front(df) -> list[str]:
    points, front = T.speed_front(df)
    if not points:
        return []
    rows = []
    for r in T.fastest_to(points):
        best, paper = r["best"], r["paper"]
        if best is None:
            continue
        rows.append([r["model"], fmt(r["t_final"], "g"), pct(r["target"]), best["method"], fmt(best["dx"], "g"),
                     best["domain"], f"{best['precision']}, {best['threads']} thread(s)", fmt(best["seconds"], ".3g"),
                     pct(best["error"]), fmt(paper["dx"], "g") if paper else "-",
                     f"{paper['threads']} thread(s)" if paper else "-", fmt(paper["seconds"], ".3g") if paper else "-",
                     fmt(r["speedup"], ".3g") if r["speedup"] else "-"])
    fronts = [[p["model"], fmt(p["t_final"], "g"), p["method"], fmt(p["dx"], "g"), p["domain"], p["precision"],
               fmt(p["seconds"], ".3g"), fmt(p["error"], ".3g"), fmt(T.predicted_error(p), ".3g")] for p in front]
    return ["## Time to a given accuracy", "",
            "Every finished run at a fixed physical time, whatever its method (kernel, h/dx, cutoff, CFL), dx and "
            "precision: time to solution (init + steps, no JIT) against the relative RMS error of u. For each "
            "error, the fastest run that reaches it, beside the fastest run of the paper's method (Gaussian, "
            "h = 2.13 dx, cut at 3h, CFL 0.2, Verlet) that reaches it, on this machine, serial or as labelled. "
            "The paper's method is compared on the same kind of domain as the fastest run (a strip holds fewer "
            "particles than the full domain for the same answer; on a strip each method runs on the thinnest "
            "strip its support allows, so a compact kernel's strip is thinner). Errors are against what each model converges to: the linear "
            "pulse for `linear`, the isothermal solution (solvers/isothermal1d.py) for `lagrangian` (its error "
            "against the linear pulse never falls below the two equations' 9.8 % difference at t = 10 s; "
            "lagrangian runs from before this was measured are left out). `fixed` solves neither and is in the "
            "cost of the simplifications below. A quick study runs the paper's method only (every ratio is then "
            "1); `pcabench study --front` adds the other kernels, h/dx and steps.", "",
            md_table(["model", "t (s)", "error target", "fastest method", "dx", "domain", "precision, threads",
                      "time (s)", "error", "paper's method: dx", "threads", "time (s)", "paper / fastest"], rows), "",
            "The front (the runs no faster run of the same model beats in error), with the error the dispersion "
            "relation predicts for each (`pcabench accuracy`, solvers/dispersion.py: the lattice's SPH operator "
            "and the integrator's own step on every wavenumber of the pulse, no simulation). For `linear` the "
            "two agree to many digits while the pulse's error waves stay clear of the domain's ends (tested to "
            "1e-8 on a longer strip); where they part here, at coarse dx and large steps, those waves have "
            "reached the ends, which the prediction's unbounded lattice lacks. For `lagrangian` the prediction "
            "is the linear part only: the moving particles and the nonlinear terms add to it.", "",
            md_table(["model", "t (s)", "method", "dx", "domain", "precision", "time (s)", "error", "predicted"],
                     fronts), "",
            *_predicted_by_model(df),
            *_why_the_paper_method()]


def _predicted_by_model(df) -> list[str]:
    rows = [[r["model"], fmt(r["dx"], "g"), pct(r["measured"]), pct(r["predicted"]), pct(r["isothermal"])]
            for r in T.predicted_by_model(df)]
    if not rows:
        return []
    return ["Predicted against measured for every model (the paper's method on the strip, t = 10 s, float64; "
            "errors against the linear pulse). `linear` is the operator the prediction is exact for. `fixed` "
            "keeps rho = rho0 + drho in its coefficients and masses from the initial density, a first-order "
            "change in Ma of the operator, and no advection: it solves neither the linear nor the isothermal "
            "equations, so it parts from the prediction by several times. `lagrangian` moves its particles and "
            "converges to the isothermal solution instead, whose distance from the linear pulse (9.8 % at "
            "t = 10 s) its error against the pulse approaches; against the isothermal solution (last column) its "
            "error follows the predicted linear part closely: the prediction describes its discretisation "
            "error, the pulse's Mach number the rest.", "",
            md_table(["model", "dx", "measured", "predicted (linear part)", "lagrangian: vs isothermal"], rows), ""]


def _why_the_paper_method() -> list[str]:
    """Why the paper's h and dt sit where they do, from the prediction at its own scene's dx."""
    from solvers import Scene
    from solvers.dispersion import lattice_offsets, predict

    base = Scene(dx=0.1, t_end=10.0, model="linear", memory_limit_bytes=2**62)
    rows = []
    for what, scene in (("the paper's method", base), ("CFL 2", base.replace(cfl=2.0)),
                        ("h = 1.5 dx", base.replace(h_factor=1.5)),
                        ("Wendland C4, h = 1.6 dx", base.replace(kernel="wendland-c4", h_factor=1.6))):
        p = predict(scene)
        nbrs = len(lattice_offsets(scene)[0])
        rows.append([what, str(nbrs), f"{100 * p.lattice_phase_error:+.3f} %", f"{100 * p.step_phase_error:+.3f} %",
                     fmt(p.stable_cfl, ".3g"), pct(p.predicted_error)])
    return ["Why the paper's h and dt sit where they do (predicted at dx = 0.1, t = 10 s): the lattice sum lags "
            "the true phase speed (a smoother, wider kernel lags more, and the 3h truncation biases the "
            "sound speed by about 0.12 %), while the leapfrog step leads it by about (c0 k dt)^2 / 24, so a "
            "larger step cancels part of the lag: the paper's small CFL keeps the whole lag, and its wide h pays "
            "for twice the neighbours with a larger lag.", "",
            md_table(["method", "neighbours", "phase speed: lattice", "with the step", "stable CFL",
                      "predicted error"], rows), ""]


def _section_simplifications(df) -> list[str]:
    rows = T.simplifications(df)
    if not rows:
        return []
    return ["## The cost of each simplification", "",
            "Each row changes one thing and keeps the rest: what the change buys in time to solution and "
            "what it costs (or gains) in error against the linear analytic pulse.", "",
            md_table(["simplification", "runs", "dx", "N", "time (s)", "speedup", "error"],
                     [[r["simplification"], r["runs"], f"{r['dx']:g}", f"{r['N'][0]:,} -> {r['N'][1]:,}",
                       f"{fmt(r['seconds'][0])} -> {fmt(r['seconds'][1])}", fmt(r["speedup"], ".2f"),
                       f"{pct(r['mse'][0])} -> {pct(r['mse'][1])}"] for r in rows]), ""]


def _section_stability(df) -> list[str]:
    points, limits = T.stability(df, INACCURATE_ABOVE)
    lines = []
    if limits:
        lines += ["## Stability: where methods fail", "",
                  f"`pcabench study --stability`: the linear model on a strip, each run classed stable, "
                  f"inaccurate (bounded, relative RMS above {100 * INACCURATE_ABOVE:g} %) or unstable (stopped "
                  "at the step where max|u| left its bound or went non-finite).", "",
                  md_table(["method", "dx", "CFLs run", "bounded up to CFL", "stable and accurate up to CFL",
                            "first failure"],
                           [[lim["config"], f"{lim['dx']:g}", ", ".join(f"{c:g}" for c in lim["cfls"]),
                             fmt(lim["bounded_up_to"], "g") if lim["bounded_up_to"] else "none",
                             fmt(lim["stable_up_to"], "g") if lim["stable_up_to"] else "none",
                             "-" if not lim["first_failure"] else
                             f"CFL {lim['first_failure'][0]:g}: {lim['first_failure'][1]}"
                             + (f" at step {lim['first_failure'][2]}" if lim["first_failure"][2] else "")
                             + (f" ({pct(lim['first_failure'][3])})" if lim["first_failure"][1] == "inaccurate"
                                else "")] for lim in limits]), ""]
        for lim in limits:
            if lim["h_factor"] == Scene.default("h_factor") and lim["precision"] == "float64" and len(lim["cfls"]) > 3:
                unb = lim["first_unbounded"]
                lines.append(f"- **{lim['integrator']}** ({lim['protocol']}): stays bounded up to CFL "
                             f"{fmt(lim['bounded_up_to'], 'g') if lim['bounded_up_to'] else 'none of those run'}"
                             + (f", blows up from CFL {unb[0]:g}" + (f" (step {unb[2]})" if unb[2] else "")
                                if unb else ", and never blew up")
                             + f"; within {100 * INACCURATE_ABOVE:g} % error up to CFL "
                             f"{fmt(lim['stable_up_to'], 'g') if lim['stable_up_to'] else 'none'}.")
        lines.append("")
    f32 = [r for r in T.float32_vs_float64(df) if any(d <= 0.05 for d, _, _ in r["pairs"])]
    if f32:
        lines += ["## float32 against float64", ""]
        for r in f32:
            pairs = "; ".join(f"dx {d:g}: {e64:.3g} / {e32:.3g}" for d, e64, e32 in r["pairs"])
            verdict = (f"float32 departs from float64 by more than {100 * r['tolerance']:g} % at dx = {r['stops_at']:g}"
                       if r["stops_at"] else
                       f"float32 tracks float64 within {100 * r['tolerance']:g} % down to dx = {r['pairs'][-1][0]:g}, "
                       "the smallest measured: it has not stopped converging")
            lines.append(f"- {r['model']}, {r['protocol']}, {r['domain']} (MSE float64 / float32: {pairs}): "
                         f"{verdict}.")
        lines.append("")
    return lines


def _first_words(message: str, limit: int = 120) -> str:
    """The message's first line, cut at a word boundary with an ellipsis if longer than ``limit``."""
    line = message.splitlines()[0] if message else ""
    return line if len(line) <= limit else line[:limit].rsplit(" ", 1)[0] + " ..."


def _section_failed(df) -> list[str]:
    bad = T.latest(df[df.status != "ok"])
    if bad.empty:
        return []
    rows = [[r.solver, r.precision, r.model, r.integrator, f"{r.dx:g}", f"{int(r.n_particles):,}", r.protocol,
             fmt(r.cfl, "g"), r.status, "-" if r.failed_step is None or not np.isfinite(r.failed_step)
             else int(r.failed_step), _first_words(str(r.message)) if r.message else ""]
            for _, r in bad.sort_values(["status", "solver", "dx"]).iterrows()]
    return ["## Runs that did not finish", "",
            md_table(["solver", "precision", "model", "integrator", "dx", "N", "protocol", "CFL", "status", "step",
                      "message"], rows), ""]


def report_for(df, df_all, name: str, out: Path) -> Path:
    """The report of one machine's runs (``name``: its profile id, with its host where a profile has several)."""
    out.mkdir(parents=True, exist_ok=True)
    pid = str(df.profile_id.iloc[0])
    figs = [f(df, out, name) for f in (F.fig8, F.fig9, F.fig10, F.fig11, F.fig13, F.speed_vs_accuracy)]
    figs.append(F.stability_map(df, out, name, INACCURATE_ABOVE))
    if T.table6(df_all) and any(r["gpu_profile"] == pid for r in T.table6(df_all)):
        figs.append(F.fig14(df_all[df_all.profile_id.isin({pid} | {r["cpu_profile"] for r in T.table6(df_all)})],
                            out, pid))
    figs = [p for p in figs if p is not None]
    for stale in set(out.glob("*.png")) - set(figs):  # a figure whose data is gone is not left behind
        stale.unlink()
    counts = df.status.value_counts().to_dict()
    commits = sorted({c[:12] + ("+dirty" if c.endswith("+dirty") else "") for c in df.commit.astype(str)})
    hosts = sorted({str(h) for h in df.host.fillna("") if h}) or ["not recorded"]
    lines = [f"# pcabench report: {name}", "", f"Machine: {_machine(pid)}; host {', '.join(hosts)}.", "",
             f"Runs: {len(df)} ({', '.join(f'{v} {k}' for k, v in sorted(counts.items()))}); commits: "
             f"{', '.join(commits)}. Every row below is from this machine (a table headed \"across machines\" names "
             "the other one); Table 4 names the commit of each row. Regenerate with `pcabench report`.", ""]
    for section in (_sections_timing(df), _section_speed(df), _section_table6(df_all, pid), _section_fig9(df),
                    _section_fig8(df),
                    _section_front(df), _section_simplifications(df), _section_stability(df), _section_failed(df)):
        lines += section
    lines += ["## Figures", ""]
    for p in figs:
        lines += [f"![{p.stem}]({p.name})", ""]
    path = out / "report.md"
    path.write_text("\n".join(lines) + "\n")
    return path


def cards_page(df_all, reports_dir: Path) -> list[Path]:
    """Table 6 and Fig. 14 across every system, and the GPU cards side by side."""
    ours, pub, cards = T.table6(df_all), T.table6_published(), T.cards(df_all)
    lines = ["# Systems and GPU cards side by side", "",
             "Regenerated by `pcabench report` from every results store and stored profile.", "",
             "## Table 6: CPU against GPU per step", "",
             "Measured, each GPU against its own host's CPU (one thread):", ""]
    same = [r for r in ours if r["same_machine"]]
    other = [r for r in ours if not r["same_machine"]]
    lines += [md_table(["GPU profile", "N", "precision", "GPU ms", "CPU ms (1 thread)", "speedup",
                        "speedup vs all cores"],
                       [[r["gpu_profile"], f"{r['N']:,}", r["precision"], fmt(r["gpu_ms"], ".3f"),
                         fmt(r["cpu_ms"], ".1f"), fmt(r["speedup"], ".1f"),
                         "-" if r["speedup_all_cores"] is None else f"{r['speedup_all_cores']:.1f}"] for r in same])
              if same else "No GPU has been measured with its own host's CPU at the same N yet."]
    if other:
        lines += ["", "Across machines (a GPU against another machine's CPU core; not a speedup of one machine):",
                  "", md_table(["GPU profile", "N", "precision", "GPU ms", "CPU profile", "CPU ms (1 thread)",
                                "ratio"],
                               [[r["gpu_profile"], f"{r['N']:,}", r["precision"], fmt(r["gpu_ms"], ".3f"),
                                 r["cpu_profile"], fmt(r["cpu_ms"], ".1f"), fmt(r["speedup"], ".1f")]
                                for r in other])]
    lines += ["", "Published (the paper's Table 6, 100 steps; its runtime unit is printed as min, but Table 4 "
                  "makes seconds the consistent reading):", "",
              md_table(["system", "card", "N", "CPU runtime", "GPU runtime", "speedup per step"],
                       [[r["system"], r["card"], f"{r['N']:,}", f"{r['cpu']:g}", f"{r['gpu']:g}", f"{r['speedup']:g}"]
                        for r in pub]), ""]
    lines += ["## GPU cards: one lagrangian step (SNP + PI + SU)", ""]
    if cards:
        lines += [md_table(["card", "precision", "N", "step ms", "SNP %", "PI %", "SU %", "ns per particle-step",
                            "ps per pair"],
                           [[r["card"], r["precision"], f"{r['N']:,}", fmt(r["step_ms"], ".3f"),
                             fmt(r["snp_pct"], ".1f"), fmt(r["pi_pct"], ".1f"), fmt(r["su_pct"], ".1f"),
                             fmt(r["ns_per_particle_step"], ".2f"), fmt(r["ps_per_pair"], ".2f")] for r in cards]),
                  "", "ps per pair counts both sweeps of a Verlet step (2 x N x mean neighbours pairs).", ""]
        ceilings = T.card_ceilings(df_all)
        if ceilings:
            lines += ["### Each card's measured ceilings", "",
                      md_table(["card", "copy bandwidth TB/s", "FP32 FMA TFLOP/s", "FP64 FMA TFLOP/s"],
                               [[c["card"], fmt(c["copy_bandwidth_tbs"]), fmt(c["fp32_fma_tflops"]),
                                 fmt(c["fp64_fma_tflops"])] for c in ceilings]), ""]
        ratios = T.card_ratios(df_all)
        if ratios:
            lines += ["### Two cards against the ratio of their ceilings", "",
                      "Step-time ratio at the same N and precision beside the ratio of each measured ceiling: a "
                      "kernel bound by memory follows the bandwidth ratio, one bound by instruction issue follows "
                      "the FMA ratio.", "",
                      md_table(["cards (A / B)", "precision", "N", "step time B / A", "bandwidth A / B",
                                "FMA A / B"],
                               [[f"{r['a']} / {r['b']}", r["precision"], f"{r['N']:,}", fmt(r["speed_ratio"]),
                                 fmt(r["bandwidth_ratio"]), fmt(r["fma_ratio"])] for r in ratios]), ""]
    else:
        lines += ["No GPU runs stored yet: run `pcabench gpu-check` on a GPU machine and merge its results.", ""]
    figs = [F.fig14(df_all, reports_dir, "all systems"), F.cards_figure(df_all, reports_dir)]
    lines += [f"![{p.stem}]({p.name})\n" for p in figs]
    path = reports_dir / "cards.md"
    path.write_text("\n".join(lines) + "\n")
    return [path, *figs]


def summary(results_dir: Path, profile: str) -> str:
    """A study's closing table for the terminal: this machine's step times (Table 4's SNP / PI / SU columns)."""
    df = store.load(results_dir)
    rows = T.table4(df[df.profile_id == profile]) if not df.empty else []
    if not rows:
        return ""
    return "Step times on this machine, ms per step (the paper's scene; the report has every table):\n" + md_table(
        ["config", "N", "SNP", "PI", "SU", "step"],
        [[r["config"], f"{r['N']:,}", fmt(r["snp"], ".3f"), fmt(r["pi"], ".3f"), fmt(r["su"], ".3f"),
          fmt(r["snp"] + r["pi"] + r["su"], ".3f")] for r in rows])


def write_reports(results_dir: Path, reports_dir: Path) -> list[Path]:
    df_all = store.load(results_dir)
    if df_all.empty:
        raise NoResults(f"no results in {results_dir}: run `pcabench study --quick` first")
    reports_dir = Path(reports_dir)
    reports_dir.mkdir(parents=True, exist_ok=True)
    # a machine's name becomes a folder: checked (store.validate made it so) so that nothing lands outside
    paths = [report_for(g, df_all, str(name), reports_dir / store.check_name(str(name), "machine"))
             for name, g in df_all.groupby("machine")]
    paths += cards_page(df_all, reports_dir)
    index = ["# Reports", "", f"Regenerated by `pcabench report` from the stores in `{Path(results_dir).name}/`; "
             "one report per machine (hardware profile, and host where one profile has several).", "",
             "- [cards.md](cards.md): Table 6, Fig. 14 and the GPU cards side by side, every system"]
    index += [f"- [{p.parent.name}]({p.parent.name}/report.md): {_machine(p.parent.name.split('--')[0])}"
              for p in paths if p.name == "report.md"]
    if (reports_dir / "gpu" / "NOTES.md").exists():  # the committed reference has them; a user's results do not
        index += ["", "GPU check tables and Nsight Compute profiles: [gpu/](gpu/); notes: [gpu/NOTES.md](gpu/NOTES.md)."]
    (reports_dir / "README.md").write_text("\n".join(index) + "\n")
    return paths + [reports_dir / "README.md"]
