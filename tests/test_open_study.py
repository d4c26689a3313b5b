"""The open-edges study (``pcabench study --open``) and its report section, "Open edges".

The preset's run list is read as a plan: both incidences, both absorbers, every layer width and strength, the
closed contrast, the resolution runs, cost rounds that alternate, long runs with the edges open. The section is
rendered from a small synthetic store (no simulation): its numbers must be the store's, its cheapest setup the one
the store implies, and its figure must read right.
"""

from __future__ import annotations

import dataclasses
from types import SimpleNamespace

import matplotlib

matplotlib.use("Agg")

import pytest  # noqa: E402

from pcabench import store, studies  # noqa: E402
from pcabench.reports import frame  # noqa: E402
from pcabench.reports.section import in_order  # noqa: E402
from pcabench.studies.open_edges import plan as P  # noqa: E402
from pcabench.studies.open_edges import section as S  # noqa: E402
from pcabench.studies.stability.plan import LONG_T_END
from solvers import Scene  # noqa: E402

from .conftest import cli_main  # noqa: E402
from .figure_check import record  # noqa: E402
from .test_study import row  # noqa: E402


@pytest.fixture(scope="module")
def plan():
    return studies.preset(P.OPEN)


def test_the_open_preset_scans_both_incidences_absorbers_widths_and_strengths(plan):
    scan = [s.scene for s in plan if s.preset == P.OPEN and s.scene.dx == P.OPEN_DX and s.scene.t_end != 300.0]
    for name, setting in P.OPEN_SCENES.items():
        mine = [s for s in scan if s.name == name]
        assert any(not s.open for s in mine)  # the closed contrast
        opened = [s for s in mine if s.open]
        assert {s.open for s in opened} == {setting["open"]} and {s.t_end for s in mine} == {setting["t_end"]}
        cells = {(s.absorber, round(s.layer / s.pulse_width, 6), round(s.strength * s.layer / s.c0, 6)) for s in opened}
        assert cells == {(a, n, c) for a in P.OPEN_ABSORBERS for n in P.LAYER_PULSE_WIDTHS for c in P.LAYER_STRENGTHS}
        assert all(s.model == "linear" for s in mine)
    resolution = {(s.scene.dx, s.scene.absorber) for s in plan if s.scene.dx in P.OPEN_RESOLUTION_DX}
    assert resolution == {(dx, a) for dx in P.OPEN_RESOLUTION_DX for a in P.OPEN_ABSORBERS}
    assert len(plan) == len(set(plan))


def test_the_cost_runs_alternate_and_the_long_runs_open_the_stability_scenes(plan):
    rounds = {}
    for s in plan:
        if P.open_cost_round(s.preset):
            rounds.setdefault(P.open_cost_round(s.preset), []).append(s.scene)
    assert sorted(rounds) == list(range(1, P.OPEN_COST_ROUNDS + 1))
    first, second = rounds[1], rounds[2]
    assert [(s.name, s.open, s.absorber) for s in first] == [(s.name, s.open, s.absorber) for s in second[::-1]]
    for name, (dx, edges, absorbers) in P.OPEN_COST.items():
        mine = [s for s in first if s.name == name]
        assert {(s.open, s.absorber) for s in mine} == {("", ""), *((edges, a) for a in absorbers)}
        assert all(s.dx == dx and s.steps == P.OPEN_COST_STEPS and s.model == "lagrangian" for s in mine)
    long = [s.scene for s in plan if s.scene.t_end == LONG_T_END]
    assert {(s.name, s.open) for s in long} == set(P.OPEN_LONG_EDGES.items())
    assert {s.cfl for s in long} == set(P.OPEN_LONG_CFL) and {s.model for s in long} == set(P.OPEN_LONG_MODELS)


def test_open_cost_round_reads_only_its_own_tags():
    assert P.open_cost_round("open-cost-3") == 3
    assert [P.open_cost_round(p) for p in ("open", "open-cost-", "walls-cost-1", "")] == [None] * 4


def _store(path):
    """A small store: the plane pulse's scan at two widths (the thin one above 1 %), the 2D pulse's at one, its
    closed square, and two rounds of cost runs on the paper's scene."""
    recs = []

    def add(rec, **errors):
        recs.append(dataclasses.replace(rec, errors=errors) if errors else rec)

    plane = dict(dx=0.25, model="linear", t_end=64.0, strip_height=5.0, preset="open")
    add(row(mse=0.0, **plane))  # the free end: its max error
    recs[-1] = dataclasses.replace(recs[-1], me=0.89 * 0.05)
    for layer, amplitude in ((3.0, 2.4e-2), (6.0, 1.8e-3)):
        for absorber in ("sponge", "pml"):
            add(
                row(open="x", layer_width=layer, absorber_strength=12.0 / layer, absorber=absorber, **plane),
                reflected_amplitude=amplitude,
                reflected_energy=amplitude**2,
                left_amplitude=amplitude + 6e-3,
                left_energy=amplitude**2 + 3e-5,
            )
    square = dict(name="acoustic-pulse", dx=0.25, model="linear", t_end=28.0, preset="open")
    square.update(x_min=-12.0, x_max=12.0, y_min=-12.0, y_max=12.0)
    add(row(**square))
    for absorber, amplitude in (("sponge", 3.0e-2), ("pml", 7.0e-4)):
        add(
            row(open="xy", layer_width=6.0, absorber_strength=2.0, absorber=absorber, **square),
            reflected_amplitude=amplitude,
            reflected_energy=amplitude**2,
            left_amplitude=amplitude,
            left_energy=amplitude**2,
            left_axis=amplitude / 2,
            left_diagonal=amplitude,
        )
    for cfl, status, step in ((3.0, "ok", None), (3.5, "unstable", 120)):  # a long run held, one blew up
        long = dict(name="acoustic-pulse", dx=0.25, model="linear", t_end=300.0, cfl=cfl, open="xy", preset="open")
        long.update(x_min=-10.0, x_max=10.0, y_min=-10.0, y_max=10.0, status=status, failed_step=step)
        add(row(**long))
    for i, (closed_ms, open_ms) in enumerate(((1.0, 1.2), (1.1, 1.15)), 1):
        tag = f"open-cost-{i}"
        add(row(dx=0.1, steps=40, step_ms=(0.0, closed_ms, 0.0), preset=tag, stamp=i))
        add(row(dx=0.1, steps=40, step_ms=(0.0, open_ms, 0.0), preset=tag, stamp=i, open="x", absorber="sponge"))
    for rec in recs:
        store.append(rec, path)
    return path


def test_the_section_renders_the_stores_numbers_and_its_cheapest_layer(tmp_path):
    path = _store(tmp_path / "store" / "m.jsonl")
    closed_long = dict(name="acoustic-pulse", dx=0.25, model="linear", t_end=300.0, cfl=4.0, preset="stability-long")
    store.append(row(x_min=-10.0, x_max=10.0, y_min=-10.0, y_max=10.0, **closed_long), path)  # closed: held at 4
    df = frame.load(path.parent)
    data = S.rows(df)
    left = {(r["scene"], r["absorber"], r["layer"]): r for r in data["left"]}
    assert left[("plane-pulse", "pml", 6.0)]["reflected"] == 1.8e-3 and left[("plane-pulse", "pml", 6.0)]["widths"] == 2
    assert left[("plane-pulse", "pml", 6.0)]["amplitude"] == pytest.approx(7.8e-3)
    assert left[("acoustic-pulse", "pml", 6.0)]["axis"] == pytest.approx(3.5e-4)
    cheapest = {r["scene"]: r for r in data["cheapest"]}
    assert cheapest["plane-pulse"]["layer"] == 6.0  # the 3 m layers reflect more than 1 %
    assert cheapest["acoustic-pulse"]["absorber"] == "pml"  # the sponge leaves 3 %
    amp, _, what = data["closed"]["plane-pulse"]
    assert amp == pytest.approx(0.89) and "free end" in what
    amp, energy, what = data["closed"]["acoustic-pulse"]
    assert amp > 0.1 and energy > 1e-2 and "periodic square" in what  # the images are back by t = 28 s
    floor_amp, floor_energy = data["floors"][("acoustic-pulse", 0.25)]
    assert 0 < floor_amp < 1e-2 and 0 < floor_energy < 1e-4  # a perfect absorber: the method's own tail
    (closed, opened) = sorted(data["cost"], key=lambda r: r["open"])
    assert closed["ratio"] == 1.0 and opened["ratio"] == pytest.approx(1.15 / 1.0)  # each side's best round
    layer = Scene(dx=0.1, open="x", absorber="sponge")  # the sponge's default layer: 1.5 pulse widths a side
    assert opened["particles"] == pytest.approx(layer.n_particles / layer.n_scored)
    (stable,) = data["stability"]
    assert stable["bounded_to"] == 3.0 and stable["blew_up_from"] == 3.5 and stable["first_step"] == 120
    assert stable["closed"]["bounded_to"] == 4.0 and stable["lowers"] is True  # it blew up where closed held
    text = "\n".join(S.text(data, None))
    assert text.startswith("## Open edges")
    for heading in ("### What the open edges leave behind", "### What a layer costs", "### The stable CFL"):
        assert heading in text
    assert "| normal (plane pulse) | pml | 6 (2; 24) | 12 | 1.80e-03 | 3.24e-06 | 7.80e-03 |" in text
    assert "Cheapest reflecting less than 1 % of the amplitude, oblique (2D pulse): the pml, 6 m of layer" in text
    assert "closed, bounded up to 4: the layer lowered it." in text


def test_open_edges_lower_the_limit_where_they_blow_up_at_a_cfl_the_closed_scene_held_and_keep_it_only_as_far():
    closed = {"bounded_to": 4.75, "blew_up_from": 4.8}
    assert S.lowers_limit({"bounded_to": 3.75, "blew_up_from": 4.0, "closed": closed}) is True
    assert S.lowers_limit({"bounded_to": 4.75, "blew_up_from": 4.75, "closed": closed}) is True  # closed held it
    assert S.lowers_limit({"bounded_to": 4.9, "blew_up_from": 5.0, "closed": closed}) is False
    assert S.lowers_limit({"bounded_to": 5.0, "blew_up_from": None, "closed": closed}) is False  # never blew up
    # held only to 4.6 and blew up past 4.75 (no run between): the runs do not say
    assert S.lowers_limit({"bounded_to": 4.6, "blew_up_from": 4.8, "closed": closed}) is None
    assert S.lowers_limit({"bounded_to": 4.9, "blew_up_from": 5.0, "closed": None}) is None


def test_the_registrys_section_draws_its_figure_and_it_reads_right(tmp_path):
    (section,) = [s for s in in_order() if s.name == "open_edges"]
    assert section.all_scenes
    data = S.rows(frame.load(_store(tmp_path / "store" / "m.jsonl").parent))
    with record() as found:
        (path,) = [draw(data, SimpleNamespace(out=tmp_path, name="m")) for draw in section.figures]
    assert path.name == "open_edges.png" and path.exists()
    assert list(found.values()) == [[]]  # drawn once, and it reads right


def test_no_open_run_no_section(tmp_path):
    path = tmp_path / "s" / "m.jsonl"
    store.append(row(dx=1.0), path)
    assert S.rows(frame.load(path.parent)) is None


def test_open_alone_is_the_preset_and_with_values_the_matrix(tmp_path, capsys):
    code, out, err = cli_main("study", "--open", "--list", "--results", str(tmp_path / "r"), capsys=capsys)
    assert code == 0, err
    assert len(out.strip().splitlines()) == len(studies.preset(P.OPEN)) and not (tmp_path / "r").exists()
    code, out, err = cli_main(
        "study", "--open", "x", "--dx", "0.5", "--list", "--results", str(tmp_path / "r"), capsys=capsys
    )
    assert code == 0 and len(out.strip().splitlines()) == 1 and "open=x" in out, (out, err)
    code, _, err = cli_main("study", "--open", "--dx", "0.5", "--list", capsys=capsys)
    assert code == 2 and "--open is a preset" in err and len(err.strip().splitlines()) == 1, err


def test_the_open_studys_runs_are_its_sections_only(tmp_path):
    """Open runs, the preset's closed contrasts and its cost baselines stay out of the other sections (a closed
    run scored after its pulse has gone has a meaningless relative error): only "Open edges" reads them."""
    from pcabench.reports.build import apart, write_reports

    path = _store(tmp_path / "store" / "m.jsonl")
    store.append(row(dx=0.5, t_end=10.0, model="linear", preset="front", stamp=9), path)  # a closed study's run
    df = frame.load(path.parent)
    flagged = apart(df)
    assert flagged.sum() == len(df) - 1 and not flagged[df.preset == "front"].any()
    (report,) = [p for p in write_reports(path.parent, tmp_path / "reports") if p.name == "report.md"]
    text = report.read_text()
    head, open_part = text.split("## Open edges")
    opened = f"{Scene(dx=0.1, open='x').n_particles:,}"  # the open cost run's particles
    assert "Runs: 1 (1 ok)" in head and opened not in head  # the other sections saw the front's run alone
    assert "### What a layer costs" in open_part
