"""The report's sections registry: each table computed once, and a new section is one entry."""
from __future__ import annotations

from pcabench import store
from pcabench.reports import sections, write_reports
from pcabench.reports import tables as T

from .test_study import fixture_rows


def _results(tmp_path):
    path = tmp_path / "results"
    for r in fixture_rows():
        store.append(r, path / f"{r.profile_id}.jsonl")
    return path


def test_each_table_is_computed_once_per_report_and_table6_once_per_set(tmp_path, monkeypatch):
    calls = {}
    for name in ("table4", "table6", "error_series", "speed_front", "stability", "cards"):
        original = getattr(T, name)

        def counted(*args, _name=name, _original=original, **kwargs):
            calls[_name] = calls.get(_name, 0) + 1
            return _original(*args, **kwargs)

        monkeypatch.setattr(T, name, counted)
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

    monkeypatch.setattr(sections, "SECTIONS", (*sections.SECTIONS, sections.Section("mine", rows, text, (figure,))))
    monkeypatch.setattr("pcabench.reports.build.SECTIONS", sections.SECTIONS)
    write_reports(_results(tmp_path), tmp_path / "out")
    report = (tmp_path / "out" / "machine-a" / "report.md").read_text()
    assert "## My table" in report and "runs on machine-a" in report and "![my_figure](my_figure.png)" in report
