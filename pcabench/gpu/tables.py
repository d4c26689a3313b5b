"""The GPU check's Markdown: its profile, ceilings, agreement, timings and stages as tables."""

from __future__ import annotations

import json

from pcabench.store.record import STEP_STAGES, step_seconds


# ---------------------------------------------------------------- the tables
def timing_row(row: dict) -> dict:
    """One stored GPU run as the check's table row: step time, stage shares, ns per particle-step, ps per pair."""
    st, steps, n = row["stages"], max(row["steps"] or 0, 1), row["n_particles"]
    step = step_seconds(st, steps)
    loop = step * steps
    pairs = 2 * n * (row.get("mean_neighbours") or 0)  # both sweeps of a Verlet step
    share = {s: 100 * st[s] / loop if loop else float("nan") for s in STEP_STAGES}
    return {
        "dx": row["dx"],
        "N": n,
        "precision": row["precision"],
        "model": row["model"],
        "status": row["status"],
        "steps": steps,
        "step_ms": 1e3 * step,
        **{f"{s}_pct": share[s] for s in STEP_STAGES},
        "ns_per_particle_step": 1e9 * step / n,
        "ps_per_pair": 1e12 * step / pairs if pairs else float("nan"),
        "neighbours": row.get("mean_neighbours") or float("nan"),
        "mse": row.get("mse") if row.get("mse") is not None else float("nan"),
        "init_ms": 1e3 * st["init"],
        "output_ms": 1e3 * st["output"],
    }


def scene_agreement(what: str, rows) -> list[str]:
    """The table of a stage that runs the GPU against the CPU on named scenes (walls, open edges)."""
    return [
        "",
        f"## {what}: GPU vs linkedlist-cpu (max relative difference after the steps shown)",
        "",
        "| scene | N | precision | model | dx | steps | u | drho |",
        "|---|---|---|---|---|---|---|---|",
    ] + [
        f"| {r['scene']} | {r['N']:,} | {r['precision']} | {r['model']} | {r['dx']} | {r['steps']} | "
        f"{r['max_rel_diff_u']:.2e} | {r['max_rel_diff_drho']:.2e} |"
        for r in rows
    ]


def markdown(profile: dict, results: dict, stages=None) -> str:
    """The check's tables: stages run, ceilings, agreement, each stage's own tables (``stages``, default: the
    studies' stages), sweep, graph path, CPU peers."""
    if stages is None:
        from pcabench.gpu.stage import STAGES

        stages = STAGES.all().values()
    g = profile.get("gpu") or {}
    lines = [
        f"# GPU check: {g.get('name', 'no GPU (rehearsal)')} ({profile['id']})",
        "",
        f"Commit {results.get('commit', '?')}; budget {results['budget_s']:.0f} s, used {results['elapsed_s']:.0f} s.",
        "",
        "| stage | status | seconds |",
        "|---|---|---|",
    ]
    lines += [f"| {s['stage']} | {s['status']} | {s['seconds']:.1f} |" for s in results["stages"]]
    lines += ["", f"Measured ceilings: {json.dumps(profile.get('measured', {}))}", ""]
    if results.get("compare"):
        lines += [
            "## GPU vs linkedlist-cpu (max relative difference after the steps shown)",
            "",
            "| precision | model | dx | steps | u | drho |",
            "|---|---|---|---|---|---|",
        ]
        lines += [
            f"| {r['precision']} | {r['model']} | {r['dx']} | {r['steps']} | {r['max_rel_diff_u']:.2e} | "
            f"{r['max_rel_diff_drho']:.2e} |"
            for r in results["compare"]
        ]
    for stage in stages:  # the studies' stages: each its own tables (walls, open edges, the cylinder, high order)
        if stage.report is not None:
            lines += stage.report(results)
    if results.get("gpu_rows"):
        lines += [
            "",
            "## linkedlist-gpu, paper domain, Verlet, cutoff 3h (stage clock: events around each operation)",
            "",
            "| dx | N | precision | model | status | steps | step (ms) | SNP % | PI % | SU % | ns/particle-step "
            "| ps/pair | neighbours | MSE | init (ms) | output (ms) |",
            "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|",
        ]
        for r in map(timing_row, results["gpu_rows"]):
            lines.append(
                f"| {r['dx']} | {r['N']:,} | {r['precision']} | {r['model']} | {r['status']} | {r['steps']} | "
                f"{r['step_ms']:.3f} | {r['snp_pct']:.1f} | {r['pi_pct']:.1f} | {r['su_pct']:.1f} | "
                f"{r['ns_per_particle_step']:.3f} | {r['ps_per_pair']:.2f} | {r['neighbours']:.1f} | "
                f"{r['mse']:.3g} | {r['init_ms']:.1f} | {r['output_ms']:.1f} |"
            )
        lines += ["", "ps/pair counts both sweeps of a Verlet step (2 x N x mean neighbours pairs)."]
    if results.get("graph"):
        lines += [
            "",
            "## The step as a CUDA graph against plain launches (same process, alternating, best round)",
            "",
            "| dx | N | precision | steps x rounds | plain (ms/step) | graph (ms/step) | plain / graph | "
            "u: graph vs plain |",
            "|---|---|---|---|---|---|---|---|",
        ]
        lines += [
            f"| {r['dx']} | {r['N']:,} | {r['precision']} | {r['steps']} x {r['rounds']} | {r['plain_ms']:.4f} "
            f"| {r['graph_ms']:.4f} | {r['speedup']:.2f} | {r['max_rel_diff_u']:.1e} |"
            for r in results["graph"]
            if "plain_ms" in r
        ]
        lines += [f"- dx {r['dx']} {r['precision']}: {r['error']}" for r in results["graph"] if "error" in r]
    if results.get("cpu_rows"):
        lines += [
            "",
            "## linkedlist-cpu on this host (lagrangian, float64)",
            "",
            "| dx | N | threads | status | steps | step (ms) |",
            "|---|---|---|---|---|---|",
        ]
        lines += [
            f"| {r['dx']} | {r['n_particles']:,} | {r['threads']} | {r['status']} | {r['steps']} | "
            f"{1e3 * step_seconds(r['stages'], r['steps']):.1f} |"
            for r in results["cpu_rows"]
        ]
    for key in ("pytest_gpu", "bench", "asv", "ncu"):
        if results.get(key):
            lines += ["", f"## {key}", "", "```", json.dumps(results[key], indent=1, default=str), "```"]
    return "\n".join(lines) + "\n"
