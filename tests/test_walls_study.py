"""The walls study (``pcabench study --walls``) and its report section, "Sound at a rigid wall".

The preset's run list is read as a plan: it must cover every wall scene of the registry, bracket each method's
predicted stable CFL, and pair each wall run of the cost part with its free counterpart at the same N in
alternating rounds. The section is rendered from a small synthetic store (no simulation): its numbers must be the
store's, its findings the ones the store implies, and its figure must read right.
"""

from __future__ import annotations

import dataclasses

import matplotlib

matplotlib.use("Agg")

import pytest  # noqa: E402

from pcabench import presets, store  # noqa: E402
from pcabench.reports import frame, sections, write_reports  # noqa: E402
from pcabench.reports import walls as W  # noqa: E402
from solvers import Scene, kernel_names, scenes  # noqa: E402
from solvers.dispersion import stable_cfl  # noqa: E402

from .figure_check import record  # noqa: E402
from .test_study import row  # noqa: E402


@pytest.fixture(scope="module")
def plan():
    return presets.preset(presets.WALLS)


def test_the_walls_preset_covers_every_wall_scene_of_the_registry(plan):
    walled = {name for name, kind in scenes().items() if kind.walls}
    assert walled and walled == set(W.wall_scenes())
    accuracy = [s for s in plan if s.preset == presets.WALLS and s.scene.t_end == presets.FRONT_T_END]
    for name in walled:
        mine = [s.scene for s in accuracy if s.scene.name == name]
        assert {s.model for s in mine} == {"linear", "lagrangian"}
        assert len({s.dx for s in mine}) >= 2 and all(s.uses_default_numerics() for s in mine)
        assert all((s.strip_height is not None) == scenes()[name].strip for s in mine)  # plane-wall on its strip
    assert all(s.preset == presets.WALLS or presets.cost_round(s.preset) for s in plan)
    assert len(plan) == len(set(plan))


def test_the_stability_runs_bracket_each_methods_predicted_limit(plan):
    long = [s.scene for s in plan if s.scene.t_end == presets.LONG_T_END]
    assert long and all(s.dx == presets.STABILITY_DX for s in long)
    for name in W.wall_scenes():
        mine = [s for s in long if s.name == name]
        assert {s.kernel for s in mine if s.model == "linear"} == set(kernel_names())  # every registered kernel
        assert {s.model for s in mine if s.uses_default_numerics() or s.cfl != Scene.default("cfl")} >= {
            "linear",
            "fixed",
            "lagrangian",
        }
        methods = {(s.model, s.kernel, s.h_factor) for s in mine}
        for model, kernel, h in methods:
            cfls = [s.cfl for s in mine if (s.model, s.kernel, s.h_factor) == (model, kernel, h)]
            limit = stable_cfl(Scene(dx=1.0, kernel=kernel, h_factor=h, model="linear", memory_limit_bytes=2**62))
            assert min(cfls) < limit < max(cfls), (name, model, kernel, h, cfls, limit)
        # long enough for round-off to grow at 2 % past the limit; and the plane scene does not break before it
        assert all(s.t_final < s.kind.breaking_time(s) for s in mine if s.model != "linear")


def test_the_cost_runs_pair_each_wall_with_its_free_counterpart_in_alternating_rounds(plan):
    cost = [s for s in plan if presets.cost_round(s.preset)]
    rounds = sorted({presets.cost_round(s.preset) for s in cost})
    assert rounds == list(range(1, presets.WALL_COST_ROUNDS + 1)) and len(rounds) >= 3
    firsts = []
    for i in rounds:
        mine = [s.scene for s in cost if presets.cost_round(s.preset) == i]
        pairs = list(zip(mine[::2], mine[1::2]))
        for a, b in pairs:
            assert {a.name, b.name} in [{w, f} for w, f in presets.FREE_COUNTERPART.items()]
            assert (a.n_particles, a.dx, a.n_steps, a.model, a.x_min, a.x_max) == (
                b.n_particles,
                b.dx,
                b.n_steps,
                b.model,
                b.x_min,
                b.x_max,
            )
        firsts.append(tuple(a.kind.walls != () for a, _ in pairs))
        for wall in presets.FREE_COUNTERPART:
            assert len({s.dx for s in mine if s.name == wall}) >= 2
    assert firsts[0] != firsts[1]  # which side goes first alternates


def test_cost_round_reads_only_its_own_tags():
    assert presets.cost_round("walls-cost-2") == 2
    assert [presets.cost_round(p) for p in ("walls", "walls-cost-", "walls-cost-x", "quick", "")] == [None] * 5


def _store(path):
    """A small store: accuracy runs of both wall scenes, pulse-wall linear long runs where h 1.3 blew up below its
    prediction, and two rounds of cost runs."""
    recs = []

    def add(rec, **errors):
        recs.append(dataclasses.replace(rec, errors=errors) if errors else rec)

    for name, dx, strip in (("plane-wall", 0.5, True), ("pulse-wall", 0.5, False)):
        extra = {"strip_height": Scene.thinnest_strip(dx)} if strip else {}
        for model, mse in (("linear", 0.3), ("lagrangian", 0.35)):
            add(
                row(name=name, dx=dx, t_end=10.0, model=model, mse=mse, preset="walls", **extra),
                wall_rms=0.2,
                bulk_rms=0.1,
            )
    limit = stable_cfl(Scene(dx=1.0, h_factor=1.3, model="linear", memory_limit_bytes=2**62))
    for cfl, status, step in ((round(0.9 * limit, 2), "unstable", 31), (round(1.02 * limit, 2), "unstable", 20)):
        add(
            row(
                name="pulse-wall",
                dx=0.5,
                t_end=300.0,
                model="linear",
                h_factor=1.3,
                cfl=cfl,
                preset="walls",
                status=status,
                failed_step=step,
            )
        )
    box = {"x_min": -14.0, "x_max": 6.0, "y_min": -10.0, "y_max": 10.0}
    for i, (wall_ms, free_ms) in enumerate(((1.2, 1.0), (1.1, 1.05)), 1):
        add(row(name="pulse-wall", dx=0.5, steps=10, step_ms=(0.0, wall_ms, 0.0), preset=f"walls-cost-{i}", stamp=i))
        add(row(name="acoustic-pulse", dx=0.5, steps=10, step_ms=(0.0, free_ms, 0.0), preset=f"walls-cost-{i}", **box))
    for rec in recs:
        store.append(rec, path)
    return path


def test_the_section_renders_the_stores_numbers_and_findings(tmp_path):
    df = frame.load(_store(tmp_path / "store" / "m.jsonl").parent)
    data = W.rows(df)
    acc = {(r["scene"], r["model"]): r for r in data["accuracy"]}
    assert set(acc) == {(n, m) for n in ("plane-wall", "pulse-wall") for m in ("linear", "lagrangian")}
    lin = acc[("pulse-wall", "linear")]
    assert lin["gap"] == pytest.approx(0.3 / lin["predicted"] - 1) and lin["wall_rms"] == 0.2
    (stab,) = data["stability"]
    assert stab["below_prediction"] and stab["free"] is None and stab["bounded_to"] is None
    (cost,) = data["cost"]
    assert cost["rounds"] == 2 and cost["ratio"] == pytest.approx(1.1 / 1.0)  # each side's best round
    assert cost["round_ratios"] == pytest.approx([1.2, 1.1 / 1.05])
    text = "\n".join(W.text(data, None))
    assert text.startswith("## Sound at a rigid wall")
    for heading in ("### Accuracy at the wall", "### Stability at the wall", "### What the wall costs"):
        assert heading in text
    assert "pulse-wall**, linear" in text and "plane-wall**, linear" in text and "its left end is free" in text
    assert "blew up below the predicted" in text and "the wall: without a free end" in text
    assert "| pulse-wall / acoustic-pulse | lagrangian | full | 0.5 | 1,600 | 10 x 2 | 1 | 1.1 | 1.100 |" in text


def test_the_section_and_its_figure_in_a_written_report(tmp_path):
    results = _store(tmp_path / "store" / "m.jsonl").parent
    assert any(s.name == "walls" for s in sections.SECTIONS)
    with record() as found:
        write_reports(results, tmp_path / "reports")
    report = (tmp_path / "reports" / "machine-a" / "report.md").read_text()
    assert "## Sound at a rigid wall" in report and "![walls_error](walls_error.png)" in report
    drawn = [p for name, p in found.items() if "walls_error" in name]
    assert drawn == [[]]  # drawn once, and it reads right


def test_no_wall_run_no_section(tmp_path):
    path = tmp_path / "s" / "m.jsonl"
    store.append(row(dx=1.0), path)
    assert W.rows(frame.load(path.parent)) is None
