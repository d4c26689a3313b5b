"""The report's "Open edges" section (``pcabench study --open``): what an open edge leaves behind against the open
problem's exact solution, for each absorber, layer width and strength, at normal and oblique incidence; the
cheapest layer below 1 % of the amplitude; how it converges with dx; what the layer costs per step; and its
stable CFL over long runs beside the closed scenes'.

The measures are the scenes' own (solvers/scenes/base.left_behind): ``left_amplitude``, the largest error of the
primary field over the initial pulse's peak, and ``left_energy``, the acoustic energy of the error over the
pulse's, over the scored domain once the pulse has gone. What a perfect absorber leaves, the method's own
dispersive tail, is the dispersion prediction's same measures on an unbounded lattice
(solvers/reference/dispersion.unbounded); the closed scenes are the contrast: the plane pulse's free end, and the
2D pulse's periodic square, whose images come back (its linear prediction, exact for the linear runs, scored
against the open plane).
"""

from __future__ import annotations

import json

import numpy as np

from pcabench.reports import figures as F
from pcabench.reports.long_runs import long_run_limits
from pcabench.reports.md import fmt, md_table
from pcabench.reports.section import Section, stored_measure
from pcabench.spec import scene_from_row
from pcabench.store.rows import latest
from pcabench.studies.open_edges.plan import OPEN, OPEN_COST_TAG, OPEN_DX, OPEN_SCENES, open_cost_round
from pcabench.studies.protocols import LONG_T_END
from solvers.boundaries.absorbers import absorber_named
from solvers.fields import Fields

TARGET_AMPLITUDE = 1e-2  # the issue's: at most 1 % of the amplitude left behind
TARGET_ENERGY = 1e-4  # the for the plane pulse: at most 1e-4 of its energy
INCIDENCE = {"plane-pulse": "normal (plane pulse)", "acoustic-pulse": "oblique (2D pulse)"}


def _finished(df, preset: str):
    return df[(df.status == "ok") & (df.preset == preset)] if "preset" in df and not df.empty else df.iloc[:0]


def left_rows(df) -> list[dict]:
    """The preset's open runs (newest of each), one row each: scene, absorber, dx, the layer (m, pulse widths,
    particles a side), the strength (1/s and c0 / L), what the edges sent back (``reflected``: against a perfect
    absorber, amplitude and energy), what is left against the exact solution (amplitude, energy; the 2D pulse's
    along the axes and the diagonals too), the particles and the time per step."""
    rows = []
    for _, r in latest(_finished(df, OPEN)).iterrows():
        scene = scene_from_row(r)
        if not scene.open or r.scene not in OPEN_SCENES or not np.isclose(scene.t_final, OPEN_SCENES[r.scene]["t_end"]):
            continue
        rows.append(
            {
                "scene": r.scene,
                "absorber": scene.absorber_used,
                "dx": float(scene.dx),
                "layer": scene.layer,
                "widths": scene.layer / scene.pulse_width,
                "layer_particles": scene.n_layer,
                "strength": scene.strength,
                "strength_c0_L": scene.strength * scene.layer / scene.c0,
                "default": scene.layer_width is None and scene.absorber_strength is None,
                "reflected": stored_measure(r, "reflected_amplitude"),
                "reflected_energy": stored_measure(r, "reflected_energy"),
                "amplitude": stored_measure(r, "left_amplitude"),
                "energy": stored_measure(r, "left_energy"),
                "axis": stored_measure(r, "left_axis"),
                "diagonal": stored_measure(r, "left_diagonal"),
                "N": int(r.n_particles),
                "scored": scene.n_scored,
                "step_ms": 1e3 * float(r.t_step),
                "scene_value": scene,
            }
        )
    return sorted(rows, key=lambda r: (r["scene"], r["absorber"], r["dx"], r["widths"], r["strength_c0_L"]))


def floors(rows) -> dict:
    """{(scene, dx): (amplitude, energy)} a perfect absorber leaves (the prediction on an unbounded lattice)."""
    from solvers.reference.dispersion import predict

    out = {}
    for r in rows:
        key = (r["scene"], r["dx"])
        if key not in out:
            m = predict(r["scene_value"]).measures or {}
            out[key] = (m.get("left_amplitude"), m.get("left_energy"))
    return out


def closed_contrast(df) -> dict:
    """{scene: (amplitude, energy, what)}: what the closed scene leaves at the same time. The plane pulse's free
    end from its stored run (``me`` over the amplitude; its energy is not stored: None); the periodic square from
    its linear prediction (exact for the linear run) scored against the open plane."""
    from solvers.reference.dispersion import predicted_fields_2d

    out = {}
    for _, r in latest(_finished(df, OPEN)).iterrows():
        scene = scene_from_row(r)
        if scene.open or r.scene not in OPEN_SCENES or not np.isclose(scene.dx, OPEN_DX):
            continue
        if r.scene == "plane-pulse":
            out[r.scene] = (float(r.me) / (scene.mach * scene.c0), None, "the free end (the stored run)")
        else:
            opened = scene.replace(open="xy")
            x, y, drho, u, v, t = predicted_fields_2d(scene)
            fields = Fields(x=x.ravel(), y=y.ravel(), u=u.ravel(), v=v.ravel(), drho=drho.ravel(), t=t)
            m = opened.kind.errors(opened, fields)
            out[r.scene] = (m["left_amplitude"], m["left_energy"], "the periodic square (its images)")
    return out


def cheapest(rows) -> list[dict]:
    """Per scene and dx, the setup with the fewest layer particles whose reflection is below 1 % of the
    amplitude (ties: the least reflected)."""
    out = []
    for key in sorted({(r["scene"], r["dx"]) for r in rows}):
        ok = [r for r in rows if (r["scene"], r["dx"]) == key and r["reflected"] is not None]
        ok = [r for r in ok if r["reflected"] < TARGET_AMPLITUDE]
        if ok:
            # at equal reflection (two digits) the absorber without the PML's x part of the rate
            out.append(min(ok, key=lambda r: (r["N"], float(f"{r['reflected']:.2g}"), r["absorber"] == "pml")))
    return out


def cost(df) -> list[dict]:
    """Time per step closed and open (``open-cost-<round>`` runs): per scene, dx and setup, at the newest commit
    that has the closed run, the best step time over the rounds, its ratio to the closed one's, the particles."""
    d = df[(df.status == "ok") & df.preset.map(lambda p: open_cost_round(p) is not None)] if "preset" in df else df
    if d.empty:
        return []
    rows = []
    for (name, dx), g in d.groupby(["scene", "dx"]):
        g = g[g.commit == g.loc[g.timestamp.idxmax(), "commit"]]
        setups = {}
        for _, r in g.iterrows():
            scene = scene_from_row(r)
            key = (scene.open, scene.absorber_used if scene.open else "")
            best = setups.get(key)
            if best is None or r.t_step < best[0]:
                setups[key] = (float(r.t_step), int(r.n_particles))
        closed = setups.get(("", ""))
        if closed is None:
            continue
        for (edges, absorber), (t, n) in sorted(setups.items()):
            rows.append(
                {
                    "scene": name,
                    "dx": float(dx),
                    "open": edges,
                    "absorber": absorber,
                    "N": n,
                    "particles": n / closed[1],
                    "step_ms": 1e3 * t,
                    "ratio": t / closed[0],
                    "rounds": int(g.preset.nunique()),
                }
            )
    return rows


def stability(df) -> list[dict]:
    """The preset's long runs with open edges (t = LONG_T_END) at their default layer, as the long-run table
    measures them, each with ``closed``: the same model and method's long runs on the closed scene
    (``--stability long``), or None."""
    long = df[df.preset == OPEN] if "preset" in df and not df.empty else df.iloc[:0]  # unstable runs count
    long = long[np.isclose(long.t_final.astype(float), LONG_T_END)] if not long.empty else long
    if not long.empty:  # each at its default layer (a row from before the sponge's 1.5 pulse widths ran two)
        long = long[long.scene_key.map(lambda key: json.loads(key).get("layer_width") is None)]
    rows = long_run_limits(long, preset=OPEN) if not long.empty else []
    closed = {(r["scene"], r["model"]): r for r in long_run_limits(df, preset="stability-long")}
    for r in rows:
        r["closed"] = closed.get((r["scene"], r["model"]))
        r["lowers"] = lowers_limit(r)
    return rows


def lowers_limit(r) -> bool | None:
    """Whether the open edges lowered the stable CFL of a long-run row: True where they blew up at a CFL the
    closed scene held, False where they held as far as it did, None where the runs do not say (no closed long
    runs, or the open ones neither held that far nor blew up within it)."""
    held = (r.get("closed") or {}).get("bounded_to")
    if held is None:
        return None
    if r.get("blew_up_from") is not None and r["blew_up_from"] <= held:
        return True
    if r.get("bounded_to") is not None and r["bounded_to"] >= held:
        return False
    return None


def rows(df) -> dict | None:
    """The section's tables from its presets' runs ``df`` (the report's ``ctx.runs``: the study's, its cost
    rounds', and ``--stability long``'s closed runs beside its own long ones); None without the study's runs."""
    if df is None or df.empty or not (df.preset == OPEN).any():
        return None
    left = left_rows(df)
    return {
        "left": left,
        "floors": floors(left),
        "closed": closed_contrast(df),
        "cheapest": cheapest(left),
        "cost": cost(df),
        "stability": stability(df),
    }


# ---------------------------------------------------------------- the section's Markdown
def _left_text(data) -> list[str]:
    left, floor, closed = data["left"], data["floors"], data["closed"]
    scan = [r for r in left if np.isclose(r["dx"], OPEN_DX)]
    if not scan:
        return []
    table = [
        [
            INCIDENCE[r["scene"]],
            r["absorber"],
            f"{r['layer']:g} ({r['widths']:g}; {r['layer_particles']})",
            f"{r['strength_c0_L']:g}",
            fmt(r["reflected"], ".2e"),
            fmt(r["reflected_energy"], ".2e"),
            fmt(r["amplitude"], ".2e"),
            fmt(r["energy"], ".2e"),
            fmt(r["axis"], ".2e"),
            fmt(r["diagonal"], ".2e"),
        ]
        for r in scan
    ]
    lines = [
        f"### What the open edges leave behind (dx = {OPEN_DX:g} m, linear)",
        "",
        "Once the pulse has gone (the plane pulse at t = 64 s through both x edges; the 2D pulse at t = 28 s "
        "through the four edges of a 24 m square). Reflected: the run against a perfect absorber's answer (the "
        "dispersion prediction on an unbounded lattice, exact for these linear runs), the largest difference of "
        "the primary field (u, drho) over the initial peak and the sum of its squares over the initial field's: "
        "the reflection coefficient in amplitude and energy. Left: against the open problem's exact solution, "
        "the largest error over the initial peak and the acoustic energy of the error over the pulse's (the "
        "method's own dispersive tail included); for the 2D pulse also the amplitude left within 15 degrees of "
        "the axes (normal incidence) and beyond 30 degrees from them (towards the corners).",
        "",
        md_table(
            [
                "incidence",
                "absorber",
                "layer, m (pulse widths; particles)",
                "strength, c0 / L",
                "reflected: amplitude",
                "reflected: energy",
                "left: amplitude",
                "left: energy",
                "left along the axes",
                "left along the diagonals",
            ],
            table,
        ),
        "",
    ]
    for scene in sorted({r["scene"] for r in scan}):
        amp, energy = floor.get((scene, OPEN_DX), (None, None))
        if amp is not None:
            lines.append(
                f"- {INCIDENCE[scene]}: a perfect absorber (the prediction on an unbounded lattice) leaves "
                f"{amp:.2e} of the amplitude and {energy:.2e} of the energy: the method's own dispersive tail."
            )
        if scene in closed:
            c_amp, c_energy, what = closed[scene]
            lines.append(
                f"- {INCIDENCE[scene]}, closed: {what} leaves {c_amp:.2g} of the amplitude"
                + (f" and {c_energy:.2g} of the energy." if c_energy is not None else ".")
            )
    for r in data["cheapest"]:
        if np.isclose(r["dx"], OPEN_DX):
            lines.append(
                f"- Cheapest reflecting less than 1 % of the amplitude, {INCIDENCE[r['scene']]}: the "
                f"{r['absorber']}, {r['layer']:g} m of layer ({r['widths']:g} pulse "
                f"width{'' if r['widths'] == 1 else 's'}, {r['layer_particles']} "
                f"particles a side) at {r['strength_c0_L']:g} c0 / L: it reflects {r['reflected']:.2e} of the "
                f"amplitude and {r['reflected_energy']:.2e} of the energy, with {r['N'] / r['scored'] - 1:.0%} "
                "more particles than the domain."
            )
    return lines + [""]


def _resolution_text(data) -> list[str]:
    rows_ = [r for r in data["left"] if r["scene"] == "acoustic-pulse" and r["default"]]
    if len({r["dx"] for r in rows_}) < 2:
        return []
    floor = data["floors"]
    table = [
        [
            r["absorber"],
            f"{r['dx']:g}",
            f"{r['widths']:g} ({r['layer_particles']})",
            fmt(r["reflected"], ".2e"),
            fmt(r["reflected_energy"], ".2e"),
            fmt(r["amplitude"], ".2e"),
            fmt(floor.get(("acoustic-pulse", r["dx"]), (None,))[0], ".2e"),
        ]
        for r in sorted(rows_, key=lambda r: (r["absorber"], -r["dx"]))
    ]
    return [
        "### The default layer against dx (the 2D pulse, four open edges)",
        "",
        "Each absorber's default layer and strength (12 c0 / L): what it reflects, what is left against the exact "
        "solution, and what a perfect absorber leaves (the method's own dispersive tail) at the same dx.",
        "",
        md_table(
            [
                "absorber",
                "dx",
                "layer, pulse widths (particles a side)",
                "reflected: amplitude",
                "reflected: energy",
                "left: amplitude",
                "perfect absorber leaves",
            ],
            table,
        ),
        "",
    ]


def _cost_text(rows_) -> list[str]:
    if not rows_:
        return []
    table = [
        [
            r["scene"],
            f"{r['dx']:g}",
            r["open"] or "closed",
            r["absorber"] or "-",
            f"{r['N']:,}",
            f"{r['particles']:.2f}",
            f"{r['step_ms']:.4g}",
            f"{r['ratio']:.3f}",
        ]
        for r in rows_
    ]
    return [
        "### What a layer costs",
        "",
        "Time per step (SNP + PI + SU, best of the rounds, which alternate the order), the paper's timing model "
        "(lagrangian, serial, the default CPU solver), each scene closed and with its default open layer.",
        "",
        md_table(["scene", "dx", "edges", "absorber", "N", "particles / closed", "ms / step", "time / closed"], table),
        "",
    ]


def _stability_text(rows_) -> list[str]:
    if not rows_:
        return []
    table = [
        [
            r["scene"],
            r["model"],
            ", ".join(f"{c:g}" for c in r["cfls"]),
            fmt(r["bounded_to"], "g"),
            fmt(r["blew_up_from"], "g"),
            fmt((r["closed"] or {}).get("bounded_to"), "g"),
            fmt((r["closed"] or {}).get("blew_up_from"), "g"),
            f"{r['predicted']:.3g}",
        ]
        for r in rows_
    ]
    return [
        f"### The stable CFL with open edges (t = {LONG_T_END:g} s)",
        "",
        "The long runs of `--stability long` with the edges open (the plane pulse's x edges with the sponge, the "
        "2D pulse's four with the PML, each at its default layer), beside the closed scenes' own long runs where "
        "this store has them. The layer's damping is a term of each update, half before and half after every "
        "kick and advance of the fields it damps (solvers/boundaries/absorbers/base.py), so that the leapfrog's "
        "discrete "
        "energy still only falls: it should hold wherever the closed scene holds. (Damping every field once "
        "after the step, as runs before 2026-12-05 did, blew up from CFL 4.)",
        "",
        md_table(
            [
                "scene",
                "model",
                "CFLs run",
                "open: bounded up to",
                "open: blew up from",
                "closed: bounded up to",
                "closed: blew up from",
                "predicted (linear)",
            ],
            table,
        ),
        "",
        *_stability_findings(rows_),
    ]


def _stability_findings(rows_) -> list[str]:
    """One line per scene and model: whether the open edges lowered the closed scene's stable CFL."""
    lines = []
    for r in rows_:
        closed = r["closed"] or {}
        if r["lowers"] is None:
            continue
        said = "lowered it" if r["lowers"] else "kept it"
        blew = f" and blew up from {fmt(r['blew_up_from'], 'g')}" if r["blew_up_from"] is not None else ""
        lines.append(
            f"- **{r['scene']}, {r['model']}**: open, bounded up to {fmt(r['bounded_to'], 'g')}{blew}; closed, "
            f"bounded up to {fmt(closed.get('bounded_to'), 'g')}: the layer {said}."
        )
    return [*lines, ""] if lines else []


def text(data, ctx) -> list[str]:
    if not data:
        return []
    body = _left_text(data) + _resolution_text(data) + _cost_text(data["cost"]) + _stability_text(data["stability"])
    if not body:
        return []
    return [
        "## Open edges",
        "",
        "An open edge (`--open x`, `y` or `xy`) grows the lattice by an absorbing layer of particles beyond the "
        "domain, which stays the scored one; the sponge damps u, v and drho at once, the split-field PML each "
        "field at its own axis's rate (solvers/boundaries/absorbers/). `pcabench study --open` makes every run below; "
        "`open_edges.png` draws what is left against the layer's width.",
        "",
        *body,
    ]


# ---------------------------------------------------------------- the figure
def figure(data, ctx):
    """What is left (amplitude, energy) against the layer's width, a column per incidence: colour the absorber,
    line style the strength; the perfect absorber dashed, the closed scene dotted, the 1 % target grey."""
    if not data:
        return None
    scan = [r for r in data["left"] if np.isclose(r["dx"], OPEN_DX) and r["reflected"] is not None]
    scenes = [s for s in OPEN_SCENES if any(r["scene"] == s for r in scan)]
    if not scenes:
        return None
    colours = {"sponge": "tab:orange", "pml": "tab:blue"}
    styles = ["-", "--", ":", "-."]
    strengths = sorted({round(r["strength_c0_L"], 6) for r in scan})
    path = ctx.out / "open_edges.png"
    with F.figure(
        path,
        f"What open edges reflect, against the layer's width, dx = {OPEN_DX:g} m, linear ({ctx.name}): the run "
        "against a perfect absorber once the pulse has gone; colour: absorber, marker: strength (c0 / L); black "
        "dotted: the closed scene (a free end, the periodic square's images), grey: the issue's targets, pale "
        "bands: each absorber's default layer; on the plane pulse the two absorbers are the same",
        "layer width, pulse widths",
        "reflected / the pulse's",
        ncols=len(scenes),
        nrows=2,
        logy=True,
        size=(5.2 * len(scenes) + 3.0, 7.6),
    ) as axes:
        markers = ["o", "s", "^", "D", "v"]
        for col, scene in enumerate(scenes):
            for row, (key, what) in enumerate((("reflected", "amplitude"), ("reflected_energy", "energy"))):
                ax = axes[row * len(scenes) + col]
                mine = [r for r in scan if r["scene"] == scene and r[key] is not None]
                values = [r[key] for r in mine]
                for absorber in sorted({r["absorber"] for r in mine}):
                    for i, c in enumerate(strengths):
                        pts = sorted(
                            (r["widths"], r[key])
                            for r in mine
                            if r["absorber"] == absorber and np.isclose(r["strength_c0_L"], c)
                        )
                        if pts:
                            ax.plot(
                                *zip(*pts),
                                color=colours.get(absorber, "tab:green"),
                                ls=styles[0] if absorber == "pml" else styles[1],
                                marker=markers[i % len(markers)],
                                ms=5,
                                label=f"{absorber}, {c:g} c0 / L",
                            )
                closed = data["closed"].get(scene)
                level = None if closed is None else (closed[0] if what == "amplitude" else closed[1])
                if level:
                    ax.axhline(level, color="black", ls=":", lw=1.2, label="closed scene (what it leaves)")
                    values.append(level)
                if what == "amplitude":
                    ax.axhline(TARGET_AMPLITUDE, color="0.6", lw=1.0, label="target: 1 % of the amplitude")
                    values.append(TARGET_AMPLITUDE)
                elif scene == "plane-pulse":
                    ax.axhline(TARGET_ENERGY, color="0.6", ls="--", lw=1.0, label="target: 1e-4 of the energy")
                    values.append(TARGET_ENERGY)
                for absorber in sorted({r["absorber"] for r in mine}):
                    ax.axvline(
                        absorber_named(absorber).default_widths,
                        color=colours.get(absorber, "tab:green"),
                        lw=3,
                        alpha=0.2,
                        label=f"{absorber}: its default layer",
                    )
                F.nice_log_ticks(ax, values)
                ax.set_xticks(sorted({r["widths"] for r in mine}))
                ax.set_title(f"{INCIDENCE[scene]}: {what} reflected", fontsize=9)
                if row == 0:
                    ax.set_xlabel("")
    return path


def own_rows(df):
    """Which rows are this study's: open edges, or the preset's own closed runs (``open``, ``open-cost-<round>``:
    contrasts scored once the pulse has gone, and cost baselines); only this section reads them."""
    edges = df["open"].fillna("") != "" if "open" in df else False
    return edges | (df.preset == OPEN) | df.preset.map(lambda p: open_cost_round(p) is not None)


SECTION = Section(
    "open_edges",
    lambda ctx: rows(ctx.runs),
    text,
    (figure,),
    all_scenes=True,
    order=155,
    apart=own_rows,
    reads=(OPEN, OPEN_COST_TAG + "*", "stability-long"),
)
