"""The walls study's figure: the error at a wall against the free pulse's, by dx."""

from __future__ import annotations

from pathlib import Path

from pcabench.reports.figures import (
    figure,
    nice_log_ticks,
    plain_log_ticks,
)


def wall_errors(rows, out: Path, pid: str):
    """The error near the wall and in the bulk against dx at t = 10 s, a panel per wall scene (``rows``: the walls
    section's accuracy rows): measured as markers (hollow: lagrangian), the linear prediction as lines."""
    scenes = sorted({r["scene"] for r in rows if r["wall_rms"] is not None})
    if not scenes:
        return None
    where = {
        "near the wall": ("wall_rms", "predicted_wall", "tab:red"),
        "bulk": ("bulk_rms", "predicted_bulk", "tab:blue"),
    }
    models = {r["model"] for r in rows}
    path = out / "walls_error.png"
    with figure(
        path,
        f"Error near the wall and in the bulk against dx, t = 10 s, the paper's method ({pid}); "
        f"colour: where{'; hollow: lagrangian (against the linear solution)' if len(models) > 1 else ''}; "
        "lines: the linear prediction on the mirror extension (the linear runs sit on it)",
        "dx, m",
        "RMS error / RMS of the exact field over the domain",
        ncols=len(scenes),
        logx=True,
        logy=True,
        size=(4.6 * len(scenes) + 3.2, 4.2),
    ) as axes:
        for ax, scene in zip(axes, scenes):
            mine = [r for r in rows if r["scene"] == scene and r["wall_rms"] is not None]
            values = []
            for label, (key, pkey, colour) in where.items():
                for model in ("linear", "lagrangian"):
                    pts = sorted((r["dx"], r[key]) for r in mine if r["model"] == model)
                    if pts:
                        ax.plot(
                            *zip(*pts),
                            ls="none",
                            marker="o",
                            ms=6,
                            color=colour,
                            mfc=colour if model == "linear" else "none",
                            label=f"{label}, {model} (measured)",
                        )
                        values += [v for _, v in pts]
                pred = sorted((r["dx"], r[pkey]) for r in mine if r["model"] == "linear" and r[pkey] is not None)
                if pred:
                    ax.plot(*zip(*pred), ls="-", lw=1.1, color=colour, label=f"{label}, linear (predicted)")
                    values += [v for _, v in pred]
            plain_log_ticks(ax, [r["dx"] for r in mine])
            nice_log_ticks(ax, values)
            ax.set_title(f"{scene} (error of {'u' if scene == 'plane-wall' else 'drho'})", fontsize=9)
    return path
