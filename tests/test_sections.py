"""The report's sections registry: each table computed once, and a new section is one entry."""

from __future__ import annotations

import pytest

from pcabench import store
from pcabench.reports.build import write_reports
from pcabench.reports.long_runs import long_run_limits
from pcabench.reports.section import SECTIONS, Section
from pcabench.studies.paper.rows import fig9_rows
from pcabench.studies.stability import long_runs as long_runs_section
from pcabench.studies.stability import section as stability_section
from pcabench.studies.stability.figures import stability_map
from pcabench.studies.stability.rows import stability

from .test_study import fixture_rows


def _results(tmp_path):
    path = tmp_path / "results"
    for r in fixture_rows():
        store.append(r, path / f"{r.profile_id}.jsonl")
    return path


def test_each_table_is_computed_once_per_report_and_table6_once_per_set(tmp_path, monkeypatch):
    import sys

    from pcabench.studies.front import rows as front_rows
    from pcabench.studies.paper import rows as paper_rows
    from pcabench.studies.stability import rows as stability_rows

    calls = {}
    for home, name in (
        (paper_rows, "table4"),
        (paper_rows, "table6"),
        (paper_rows, "error_series"),
        (front_rows, "speed_front"),
        (stability_rows, "stability"),
        (paper_rows, "cards"),
    ):
        original = getattr(home, name)

        def counted(*args, _name=name, _original=original, **kwargs):
            calls[_name] = calls.get(_name, 0) + 1
            return _original(*args, **kwargs)

        for module in [m for m in list(sys.modules.values()) if getattr(m, "__name__", "").startswith("pcabench")]:
            if getattr(module, name, None) is original:  # every module that took it by name
                monkeypatch.setattr(module, name, counted)
    write_reports(_results(tmp_path), tmp_path / "out")
    machines = 2  # machine-a and machine-b
    assert calls["table6"] == 1
    assert calls["cards"] == 1
    for name in ("table4", "error_series", "speed_front", "stability"):
        assert calls[name] == machines, (name, calls[name])


def test_a_new_section_is_one_entry_with_its_rows_text_and_figure(tmp_path, monkeypatch):
    def rows(ctx):
        return len(ctx.df)

    def text(n, ctx):
        return ["## My table", "", f"{n} runs on {ctx.name}", ""]

    def figure(n, ctx):
        path = ctx.out / "my_figure.png"
        path.write_bytes(b"")
        return path

    with SECTIONS.registered(Section("mine", rows, text, (figure,))):
        write_reports(_results(tmp_path), tmp_path / "out")
    report = (tmp_path / "out" / "machine-a" / "report.md").read_text()
    assert "## My table" in report and "runs on machine-a" in report and "![my_figure](my_figure.png)" in report


def _stability_frame(tmp_path):
    from pcabench.reports import frame

    from .test_study import row

    path = tmp_path / "stab" / "m.jsonl"
    for cfl, status, mse in (
        (0.2, "ok", 0.1),
        (1.0, "ok", 0.1),
        (2.0, "ok", 0.1),
        (3.0, "ok", 0.1),
        (4.0, "ok", 0.1),
        (4.5, "ok", 0.3),
        (5.0, "ok", 0.1),
        (6.0, "ok", 0.5),
        (7.0, "ok", 0.4),
        (8.0, "unstable", 1.0),
    ):
        store.append(
            row(
                model="linear",
                preset="stability",
                dx=0.25,
                t_end=10.0,
                strip_height=5.0,
                cfl=cfl,
                status=status,
                failed_step=4 if status == "unstable" else None,
                mse=mse,
            ),
            path,
        )
    for cfl, mse in ((0.2, 0.3), (4.0, 0.13)):  # a longer run: inaccurate at 0.2, accurate at 4
        store.append(
            row(model="linear", preset="stability", dx=0.25, t_end=30.0, strip_height=5.0, cfl=cfl, mse=mse), path
        )
    return frame.load(path.parent)


def test_the_stability_summary_agrees_with_the_prediction_and_the_map(tmp_path, monkeypatch):
    import matplotlib.axes
    import matplotlib.figure

    points, limits = stability(_stability_frame(tmp_path), 0.2)
    for p in points:  # at or past the predicted 4.97 a run is unstable, blown up or by prediction
        assert (p["class"] in ("unstable", "unstable by prediction")) == (p["cfl"] >= 4.97), p
    lines = stability_section.text((points, limits), None)
    text = "\n".join(lines)
    short = next(lim for lim in limits if lim["protocol"] == "t = 10 s")
    assert short["stable_cfl"] == 4.8 and short["limit_from"] == "long runs"  # the free ends' measured limit
    assert short["predicted"] == pytest.approx(4.97, abs=0.005)  # the periodic lattice's
    assert short["blew_up_at"] == [(8.0, 4)] and short["blew_up_below_limit"] == []
    assert [c for c, _steps, _e in short["bounded_past_limit"]] == [5.0, 6.0, 7.0]  # bounded, unstable by prediction
    assert all(1 < e < 30 for _c, _steps, e in short["bounded_past_limit"])  # too few e-foldings to show
    assert short["accurate_at"] == [0.2, 1.0, 2.0, 3.0, 4.0] and short["inaccurate_at"] == [(4.5, 0.3)]
    summary = next(line for line in lines if line.startswith("- **verlet** (t = 10 s)"))
    for number in ("CFL 4.8", "4.97", "CFL 8", "CFL 5-7", "CFL 0.2-4."):  # the row's values, rendered
        assert number in summary, (number, summary)
    assert "never blew up" not in text and "bounded up to" not in text
    long = next(lim for lim in limits if lim["protocol"] == "t = 30 s")
    assert long["accurate_at"] == [4.0] and [c for c, _ in long["inaccurate_at"]] == [0.2]  # not "none"

    drawn, limit_bars, ticks = {}, [], []
    scatter, plot, savefig = matplotlib.axes.Axes.scatter, matplotlib.axes.Axes.plot, matplotlib.figure.Figure.savefig

    def record_scatter(self, x, y, *args, label=None, **kw):
        drawn[label.split(" (")[0]] = sorted(zip(x, y))  # the class, without its explanation
        return scatter(self, x, y, *args, label=label, **kw)

    def record_plot(self, *args, **kw):
        if kw.get("color") == "black":
            limit_bars.append(args[0][0])
        return plot(self, *args, **kw)

    def record_ticks(self, *args, **kw):
        ticks.extend(self.axes[0].get_xticks())
        return savefig(self, *args, **kw)

    monkeypatch.setattr(matplotlib.axes.Axes, "scatter", record_scatter)
    monkeypatch.setattr(matplotlib.axes.Axes, "plot", record_plot)
    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", record_ticks)
    assert stability_map(points, limits, tmp_path, "m", 0.2)
    configs = [lim["config"] for lim in limits]
    by_class = {}
    for p in points:
        by_class.setdefault(p["class"], []).append((p["cfl"], configs.index(p["config"])))
    assert drawn == {cls: sorted(v) for cls, v in by_class.items()}  # one colour per class, the table's classes
    assert limit_bars == [lim["stable_cfl"] for lim in limits]  # the predicted limit on every row
    assert {p["cfl"] for p in points} <= set(ticks)  # a tick at every CFL swept


def test_fig9_keeps_the_loop_measured_beside_the_most_all_pair_runs(tmp_path):
    from pcabench.reports import frame

    from .test_study import row

    path = tmp_path / "f9" / "m.jsonl"
    for dx in (1.0, 0.5):  # all-pair and the pair list at two N; a plug-in study adds gather at one N only
        store.append(row(solver="allpair-cpu", dx=dx, steps=10), path)
        rec = row(dx=dx, steps=10)
        rec.pair_loop = "list"
        store.append(rec, path)
    rec = row(dx=1.0, steps=10, stamp=5)
    rec.pair_loop = "gather"
    store.append(rec, path)
    rows = fig9_rows(frame.load(path.parent))
    assert {r["linkedlist_loop"] for r in rows} == {"list"}
    assert all(r["linkedlist_ms"] for r in rows)  # both N keep their linked-list time


def test_the_long_run_table_measures_each_models_limit_below_its_first_blow_up(tmp_path):
    """A bounded run above a blow-up does not raise the measured limit; the control's limit is the prediction's;
    a moving model that blew up below its linear part's limit is named, with the limit advise uses for it."""
    from pcabench.reports import frame

    from .test_study import row

    path = tmp_path / "long" / "m.jsonl"
    runs = {
        "linear": {4.6: ("ok", None), 4.9: ("ok", None), 5.0: ("unstable", 200)},
        "fixed": {4.6: ("ok", None), 4.7: ("unstable", 236), 4.8: ("ok", None), 4.9: ("unstable", 47)},
    }
    for model, by_cfl in runs.items():
        for cfl, (status, step) in by_cfl.items():
            store.append(
                row(
                    name="acoustic-pulse",
                    model=model,
                    preset="stability-long",
                    dx=1.0,
                    t_end=30.0,
                    x_min=-10.0,
                    x_max=10.0,
                    y_min=-10.0,
                    y_max=10.0,
                    cfl=cfl,
                    status=status,
                    failed_step=step,
                    steps=60,
                ),
                path,
            )
    rows = {r["model"]: r for r in long_run_limits(frame.load(path.parent))}
    lin, fixed = rows["linear"], rows["fixed"]
    assert lin["predicted"] == pytest.approx(4.97, abs=0.01) and lin["bounded_to"] == 4.9
    assert lin["blew_up_from"] == 5.0 and lin["e_foldings"] < 1e-9 and lin["held"] is None
    assert fixed["bounded_to"] == 4.6 and fixed["blew_up_from"] == 4.7 and fixed["first_step"] == 236  # not 4.8
    assert fixed["held"] == 4.75  # pcabench/predict/measured_limits.csv: fixed on the 2D pulse
    text = "\n".join(long_runs_section.text(list(rows.values()), None))
    assert "**fixed** on acoustic-pulse blew up below the predicted 4.97, from CFL 4.7" in text
    assert "**linear** blew up below" not in text


def test_a_page_across_machines_is_a_studys_registered_page(tmp_path):
    """The cards page is the paper study's Page (pcabench/studies/paper/page.py), found by the page registry;
    the index links what each page wrote with the page's own line, and a page's files are the build's."""
    from pcabench.reports import page as pages
    from pcabench.reports.page import Page

    found = {p.name: p for p in pages.in_order()}
    assert isinstance(found["cards"], Page) and found["cards"].write.__module__ == "pcabench.studies.paper.page"
    paths = write_reports(_results(tmp_path), tmp_path / "reports")
    assert tmp_path / "reports" / "cards.md" in paths
    index = (tmp_path / "reports" / "README.md").read_text()
    assert f"- [cards.md](cards.md): {found['cards'].index}" in index


def test_a_section_reads_the_presets_it_declares(tmp_path):
    """``Section.reads`` names presets; the report hands the section their runs as ``ctx.runs`` (a name ending in
    ``*`` is a study's rounds) and nothing of another preset's."""
    import dataclasses

    import pandas as pd

    from pcabench.reports.section import Context

    df = pd.DataFrame({"preset": ["walls", "walls-cost-1", "walls-cost-2", "front", "three-d"], "x": range(5)})
    ctx = Context(df.iloc[:0], df.iloc[:0], "m", tmp_path, df_scenes=df)
    assert list(ctx.runs_of(("walls-cost-*", "three-d")).x) == [1, 2, 4]
    assert list(ctx.runs_of(("front",)).x) == [3] and ctx.runs_of(("nope",)).empty
    seen = {}
    probe = Section("probe", lambda c: seen.setdefault("runs", c.runs), lambda rows, c: [], reads=("front",))
    own = dataclasses.replace(ctx, runs=ctx.runs_of(probe.reads))
    probe.rows(own)
    assert list(seen["runs"].preset) == ["front"] and own.cache is ctx.cache  # the caches shared


def test_the_front_leaves_out_the_runs_of_presets_that_measure_no_error(tmp_path):
    """A preset that says its runs are not scored (the long stability runs, a plug-in's) gives no front point,
    at whatever time it ends; the same run under a scored preset is one."""
    from pcabench.reports import frame
    from pcabench.studies.front.rows import speed_front
    from pcabench.studies.preset import PRESETS, Preset

    from .test_study import row

    path = tmp_path / "front" / "m.jsonl"
    scene = dict(dx=1.0, t_end=10.0, model="linear", x_min=-10.0, x_max=10.0, y_min=-10.0, y_max=10.0)
    for preset, cfl in (("front", 1.0), ("stability-long", 1.5), ("my-long", 2.0)):
        store.append(row(name="acoustic-pulse", preset=preset, cfl=cfl, **scene), path)
    mine = Preset("my-long", lambda: [], 60.0, flag="my-long", scored=False)
    with PRESETS.registered(mine):
        points, _ = speed_front(frame.load(path.parent))
    assert sorted(p["cfl"] for p in points) == [1.0]
    points, _ = speed_front(frame.load(path.parent))  # the plug-in gone: its run is an ordinary one again
    assert sorted(p["cfl"] for p in points) == [1.0, 2.0]
