"""Every figure a report writes, read as a reader would (tests/figure_check.py), and the checker itself.

The quick study's figures are drawn from records made from the quick preset's own run specs (the
times and errors synthetic, the runs exactly those `study --quick` makes), so that the report of a
quick study holds every section of the report's section registry (each study's section.py,
``SECTIONS``) with every figure that section declares, each passing the checks: the list of sections
and figures is the registry's, never one kept here. The committed reference's figures pass them too.
"""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import dataclasses  # noqa: E402

import matplotlib.pyplot as plt  # noqa: E402
import pytest  # noqa: E402

from pcabench import paths, store, studies  # noqa: E402
from pcabench.reports import build  # noqa: E402
from pcabench.reports.build import write_reports  # noqa: E402
from pcabench.reports.section import Section, in_order  # noqa: E402
from pcabench.store.record import RunRecord  # noqa: E402

from .figure_check import problems, record  # noqa: E402

PROFILE = "laptop-cpu"


def quick_records() -> list[RunRecord]:
    """One record per run of `study --quick`, with times that grow with N (all-pair as N^2, skipped past
    16K as a sweep would predict) and errors of the right shape (linear second order, the stability
    scene stable to CFL 2, inaccurate near 5, unstable past it)."""
    out = []
    for i, spec in enumerate(studies.preset("quick")):
        spec = spec.resolved()
        s = spec.scene
        n = s.n_particles
        allpair = spec.solver.startswith("allpair")
        step = 2e-7 * n * (n / 1000 if allpair else 1) * (0.6 if s.precision == "float32" else 1)
        status, steps, failed = "ok", s.n_steps, None
        if allpair and n > 16000:
            status, steps = "skipped", 0
        mse = {"linear": 0.016 * (s.dx / 0.1) ** 2, "fixed": 0.2, "lagrangian": 0.1 + s.dx / 10}[s.model]
        if s.precision == "float32":
            mse *= 1.02
        if s.cfl >= 7:
            status, steps = "unstable", min(12, s.n_steps)  # a blow-up within its scene's steps
            failed = steps
        elif s.cfl >= 5:
            mse = 0.3
        stages = {
            "input": 1e-4,
            "init": 1e-6 * n,
            "output": 1e-6 * n,
            "snp": 0.3 * step * steps,
            "pi": 0.65 * step * steps,
            "su": 0.05 * step * steps,
        }
        out.append(
            RunRecord(
                solver=spec.solver,
                precision=s.precision,
                model=s.model,
                integrator=s.integrator,
                dx=s.dx,
                n_particles=n,
                steps=steps,
                t_end=s.t_final,
                stages=stages,
                jit_seconds=1.0,
                mse=mse,
                me=mse / 20,
                mean_neighbours=120.0,
                status=status,
                failed_step=failed,
                threads=int(spec.threads),
                pair_loop=spec.pair_loop,
                steps_requested=s.n_steps,
                scene=s.as_dict(),
                mse_isothermal=mse / 2 if s.model == "lagrangian" else None,
                message="predicted 999 s > run budget 120 s" if status == "skipped" else "",
                profile_id=PROFILE,
                commit="abc1234",
                preset="quick",
                host="host1",
                timestamp=f"2026-01-01T00:{i // 60:02d}:{i % 60:02d}+00:00",
            )
        )
    return out


def recorded(section: Section, texts: dict, drawn: dict) -> Section:
    """``section`` as the registry declares it, its Markdown and each figure it draws recorded by its name."""

    def text(rows, ctx):
        lines = section.text(rows, ctx)
        texts.setdefault(section.name, []).extend(lines)
        return lines

    def figure(draw):
        def drawn_by(rows, ctx):
            path = draw(rows, ctx)
            drawn.setdefault(section.name, []).append(path)
            return path

        return drawn_by

    return dataclasses.replace(section, text=text, figures=tuple(figure(f) for f in section.figures))


@pytest.fixture(scope="module")
def quick_report(tmp_path_factory):
    """The quick study's reports: their folder, every figure read by the checker (name -> problems), and what
    each section of the registry wrote (name -> Markdown lines) and drew (name -> a path or None per figure)."""
    tmp = tmp_path_factory.mktemp("quick")
    for rec in quick_records():
        store.append(rec, tmp / "store" / f"{PROFILE}.jsonl")
    texts, drawn = {}, {}
    with pytest.MonkeyPatch.context() as patch, record() as found:
        recorded_sections = [recorded(s, texts, drawn) for s in in_order()]
        patch.setattr(build, "in_order", lambda: recorded_sections)
        write_reports(tmp / "store", tmp / "reports")
    return tmp / "reports", found, texts, drawn


def test_a_quick_study_writes_every_section_and_figure_of_the_registry(quick_report):
    """Each section of the registry that has rows in a quick study writes its heading and draws every figure it
    declares; one with none (Table 6 needs a GPU's runs) writes and draws nothing. Every PNG is a section's."""
    out, found, texts, drawn = quick_report
    report = (out / PROFILE / "report.md").read_text()
    written = [s for s in in_order() if texts.get(s.name)]
    assert len(written) > len(in_order()) // 2, [s.name for s in written]  # the quick study's purpose
    for section in in_order():
        lines, paths = texts.get(section.name), drawn.get(section.name, [])
        if not lines:
            assert not any(paths), (section.name, paths)  # no rows: no figure either
            continue
        assert lines[0].startswith("## ") and lines[0] in report, (section.name, lines[:1])
        # each figure drawn; but the scenes' fronts, which need FRONT_PANEL_RUNS runs on two scenes (a quick
        # study makes two 2D runs at the default amplitude: no front to draw)
        expected = [p is not None or (section.name, i) == ("scenes", 0) for i, p in enumerate(paths)]
        assert len(paths) == len(section.figures) and all(expected), (section.name, paths)
    declared = [p.name for paths in drawn.values() for p in paths if p is not None]
    figures = {p.name for p in (out / PROFILE).glob("*.png")}
    assert figures and len(declared) == len(set(declared)) and figures == set(declared)
    for name in figures:
        assert f"![{name[:-4]}]({name})" in report, name
    assert len(found) == len(figures) + 2  # and the cards page's two


def test_every_figure_of_a_quick_study_reads_right(quick_report):
    _, found, _, _ = quick_report
    assert {name: p for name, p in found.items() if p} == {}


@pytest.mark.tier2  # draws every reference figure again: minutes
def test_every_committed_reference_figure_reads_right(tmp_path):
    if paths.checkout() is None:
        pytest.skip("needs a source checkout")
    with record() as found:
        write_reports(paths.reference_results(), tmp_path)
    assert found and {name: p for name, p in found.items() if p} == {}


def test_a_row_never_mixes_protocols_and_the_paper_sits_beside_its_own_kind(quick_report):
    out, *_ = quick_report
    text = (out / PROFILE / "report.md").read_text()
    table4 = text.split("## Table 4")[1].split("\n## ")[0]
    rows = [line for line in table4.splitlines() if line.startswith("| ") and "steps" in line]
    assert rows and all(", full, " in r and "thread" in r for r in rows)  # run length, domain, loop, threads
    for line in rows:
        if "allpair" in line:
            assert "linked list" not in line.split("|")[-2]
    table5 = text.split("## Table 5")[1].split("\n## ")[0]
    for line in table5.splitlines():
        if line.startswith("| allpair"):
            assert line.rstrip(" |").endswith("-"), line  # no linked-list shares beside an all-pair row
    assert "K20c" not in text  # a CPU-only report has none of the paper's GPU numbers


# ---------------------------------------------------------------- the checker can fail
def _fig(**kw):
    fig, ax = plt.subplots(figsize=kw.pop("size", (5, 3)), layout="constrained")
    return fig, ax


def test_the_checker_finds_each_fault():
    cases = {}
    fig, ax = _fig()
    ax.plot([0, 1], [0, 1], "o-", label="data")
    ax.legend(loc="center")  # over the line
    cases["legend"] = fig
    fig, ax = _fig()
    ax.plot(range(40), range(40))
    ax.set_xticks(range(40), [f"tick {i}" for i in range(40)])
    cases["overlap"] = fig
    fig, ax = _fig()
    ax.plot([1, 2], [1, 2], color="grey", marker="o", label="a")
    ax.plot([1, 2], [2, 3], color="grey", marker="s", label="b")
    fig.suptitle("colour: solver")
    cases["channel"] = fig
    fig, ax = _fig()
    ax.plot([1, 2], [1, 2], color="tab:blue", marker="o", label="a")
    ax.plot([1, 2], [2, 3], color="tab:blue", marker="o", label="b")
    fig.legend(loc="outside right center")
    cases["alike"] = fig
    fig, ax = _fig()
    ax.plot([1, 2], [1, 2], color="tab:red", marker="^", label="paper all-pair (published)")
    fig.legend(loc="outside right center")
    cases["published"] = fig
    fig, ax = _fig()
    ax.set_yscale("log")
    ax.plot([1, 2], [20, 60])
    cases["log ticks"] = fig
    fig, ax = _fig(size=(3, 2))
    fig.suptitle("a title far too long for its figure, which a reader would find cut at both edges " * 2)
    cases["cut"] = fig
    for name, fig in cases.items():
        assert problems(fig), name
        plt.close(fig)
    fig, ax = _fig()
    ax.plot([1, 2], [1, 2], color="tab:blue", marker="o", label="measured")
    ax.plot([1, 2], [2, 3], color="0.35", ls="--", marker="^", mfc="none", label="paper (published)")
    fig.legend(loc="outside right center")
    assert problems(fig) == []
    plt.close(fig)
