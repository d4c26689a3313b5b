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

from pcabench import store, studies  # noqa: E402
from pcabench.reports import frame  # noqa: E402
from pcabench.reports.section import in_order  # noqa: E402
from pcabench.studies.front.plan import FRONT_T_END, front_axes
from pcabench.studies.stability.plan import LONG_T_END, STABILITY_DX
from pcabench.studies.walls import section as W  # noqa: E402
from pcabench.studies.walls.plan import FREE_COUNTERPART, WALL_COST_DX, WALL_COST_ROUNDS, WALLS, cost_round
from solvers import Scene, kernel_names, scenes  # noqa: E402
from solvers.method import Method
from solvers.reference.dispersion import predict, predicted_stable_cfl  # noqa: E402

from .figure_check import record  # noqa: E402
from .test_study import row  # noqa: E402


@pytest.fixture(scope="module")
def plan():
    return studies.preset(WALLS)


def test_the_walls_preset_covers_every_wall_scene_of_the_registry(plan):
    walled = {name for name, kind in scenes().items() if kind.walls}
    assert walled and walled == set(W.wall_scenes())
    accuracy = [s for s in plan if s.preset == WALLS and s.scene.t_end == FRONT_T_END]
    for name in walled:
        mine = [s.scene for s in accuracy if s.scene.name == name]
        assert {s.model for s in mine} == {"linear", "lagrangian"}
        assert len({s.dx for s in mine}) >= 2 and all(Method.of(s).is_paper() for s in mine)
        assert all((s.strip_height is not None) == scenes()[name].strip for s in mine)  # plane-wall on its strip
    assert all(s.preset == WALLS or cost_round(s.preset) for s in plan)
    assert len(plan) == len(set(plan))


def test_the_stability_runs_bracket_each_methods_predicted_limit(plan):
    long = [s.scene for s in plan if s.scene.t_end == LONG_T_END]
    assert long and all(s.dx == STABILITY_DX for s in long)
    for name in W.wall_scenes():
        mine = [s for s in long if s.name == name]
        assert {s.kernel for s in mine if s.model == "linear"} == set(kernel_names())  # every registered kernel
        assert {s.model for s in mine if Method.of(s).is_paper() or s.cfl != Scene.default("cfl")} >= {
            "linear",
            "fixed",
            "lagrangian",
        }
        methods = {(s.model, s.kernel, s.h_factor) for s in mine}
        for model, kernel, h in methods:
            cfls = [s.cfl for s in mine if (s.model, s.kernel, s.h_factor) == (model, kernel, h)]
            limit = predicted_stable_cfl(Scene(dx=1.0, kernel=kernel, h_factor=h, model="linear"))
            assert min(cfls) < limit < max(cfls), (name, model, kernel, h, cfls, limit)
        # long enough for round-off to grow at 2 % past the limit; and the plane scene does not break before it
        assert all(s.t_final < s.kind.breaking_time(s) for s in mine if s.model != "linear")


def test_the_cost_runs_pair_each_wall_with_its_free_counterpart_in_alternating_rounds(plan):
    cost = [s for s in plan if cost_round(s.preset)]
    rounds = sorted({cost_round(s.preset) for s in cost})
    assert rounds == list(range(1, WALL_COST_ROUNDS + 1)) and len(rounds) >= 3
    firsts = []
    for i in rounds:
        mine = [s.scene for s in cost if cost_round(s.preset) == i]
        pairs = list(zip(mine[::2], mine[1::2]))
        for a, b in pairs:
            assert {a.name, b.name} in [{w, f} for w, f in FREE_COUNTERPART.items()]
            assert (a.n_particles, a.dx, a.n_steps, a.model, a.x_min, a.x_max) == (
                b.n_particles,
                b.dx,
                b.n_steps,
                b.model,
                b.x_min,
                b.x_max,
            )
        firsts.append(tuple(a.kind.walls != () for a, _ in pairs))
        for wall in FREE_COUNTERPART:
            assert len({s.dx for s in mine if s.name == wall}) >= 2
    assert firsts[0] != firsts[1]  # which side goes first alternates


def test_cost_round_reads_only_its_own_tags():
    assert cost_round("walls-cost-2") == 2
    assert [cost_round(p) for p in ("walls", "walls-cost-", "walls-cost-x", "quick", "")] == [None] * 5


def _store(path):
    """A small store: accuracy runs of both wall scenes, pulse-wall linear long runs where h 1.3 blew up below its
    prediction, and two rounds of cost runs."""
    recs = []

    def add(rec, **errors):
        recs.append(dataclasses.replace(rec, errors=errors) if errors else rec)

    # linear as the prediction has it: plane-wall off by 1e-5 away from the wall (its free end), pulse-wall exactly
    for name, dx, strip, gap in (("plane-wall", 0.5, True, 1e-5), ("pulse-wall", 0.5, False, 0.0)):
        extra = {"strip_height": Scene.thinnest_strip(dx)} if strip else {}
        p = predict(Scene(dx=dx, name=name, t_end=10.0, model="linear", **extra))
        wall, bulk = p.measures["wall_rms"], p.measures["bulk_rms"]
        for model, mse in (("linear", p.predicted_error * (1 + gap)), ("lagrangian", 0.35)):
            add(
                row(name=name, dx=dx, t_end=10.0, model=model, mse=mse, preset="walls", **extra),
                wall_rms=wall,
                bulk_rms=bulk * (1 + gap),
            )
    limit = predicted_stable_cfl(Scene(dx=1.0, h_factor=1.3, model="linear"))
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
    acc_scenes = ("plane-wall", "pulse-wall")
    assert set(acc) == {(n, m) for n in acc_scenes for m in ("linear", "lagrangian")}
    lin = acc[("pulse-wall", "linear")]
    assert abs(lin["gap"]) < 1e-12 and acc[("plane-wall", "linear")]["gap"] == pytest.approx(1e-5)
    (stab,) = data["stability"]
    assert stab["below_prediction"] and stab["free"] is None and stab["bounded_to"] is None
    (cost,) = data["cost"]
    assert cost["rounds"] == 2 and cost["ratio"] == pytest.approx(1.1 / 1.0)  # each side's best round
    assert cost["round_ratios"] == pytest.approx([1.2, 1.1 / 1.05])
    text = "\n".join(W.text(data, None))
    assert text.startswith("## Sound at a rigid wall")
    for heading in ("### Accuracy at the wall", "### Stability at the wall", "### What the wall costs"):
        assert heading in text
    linear = {n: [r for r in data["accuracy"] if r["scene"] == n and r["model"] == "linear"] for n in acc_scenes}
    assert W.gap_cause("pulse-wall", linear["pulse-wall"]) == "round-off"
    assert W.gap_cause("plane-wall", linear["plane-wall"]) == "free end"  # equal near the wall, not away from it
    assert [W.near_wall_cause(linear[n]) for n in acc_scenes] == ["dispersion", "dispersion"]  # no error of its own
    assert W.blow_up_cause(stab) == "the wall alone"  # linear, no free end, no free counterpart's long runs
    for scene, cause in (("pulse-wall", ": round-off;"), ("plane-wall", "the free left end's, not the wall's")):
        assert f"- **{scene}**, linear: measured and predicted differ by at most" in text and cause in text
    assert "| pulse-wall / acoustic-pulse | lagrangian | full | 0.5 | 1,600 | 10 x 2 | 1 | 1.1 | 1.100 |" in text


def test_the_registrys_section_draws_its_figure_and_it_reads_right(tmp_path):
    from types import SimpleNamespace

    (section,) = [s for s in in_order() if s.name == "walls"]
    assert section.all_scenes  # it reads every scene's runs, not the paper's scene's only
    data = W.rows(frame.load(_store(tmp_path / "store" / "m.jsonl").parent))
    with record() as found:
        (path,) = [draw(data, SimpleNamespace(out=tmp_path, name="m")) for draw in section.figures]
    assert path.name == "walls_error.png" and path.exists()
    assert list(found.values()) == [[]]  # drawn once, and it reads right


def test_no_wall_run_no_section(tmp_path):
    path = tmp_path / "s" / "m.jsonl"
    store.append(row(dx=1.0), path)
    assert W.rows(frame.load(path.parent)) is None


# ---------------------------------------------------------------- the wall scenes join the front and advise
@pytest.mark.parametrize("name", ["plane-wall", "pulse-wall"])
def test_the_front_of_a_wall_scene_is_its_own_product_with_the_papers_method(name):
    kind = scenes()[name]
    runs = studies.preset("front", name)
    assert runs and {s.scene.name for s in runs} == {name}
    assert all((s.scene.strip_height is not None) == kind.strip for s in runs)  # plane-wall on its strip
    axes = front_axes("quick", name)
    assert axes == front_axes("quick", "plane-pulse" if kind.strip else "acoustic-pulse")
    assert {s.scene.kernel for s in runs} == set(kernel_names())
    paper = [s.scene for s in runs if Method.of(s.scene).is_paper()]
    assert {s.model for s in paper} == {"linear", "lagrangian"} and len({s.dx for s in paper}) >= 2
    # no isothermal reference at a wall: no runs of "which model this scene needs" (they score against it)
    assert not kind.has_isothermal and {s.scene.mach for s in runs} == {Scene.default("mach")}


def test_study_list_prints_the_plan_and_runs_nothing(tmp_path, capsys):
    from pcabench import cli

    code = cli.main(["study", "--walls", "--list", "--results", str(tmp_path / "r")])
    out = capsys.readouterr().out.splitlines()
    assert code == 0 and len(out) == len(studies.preset(WALLS)) and not (tmp_path / "r").exists()
    assert out[0].startswith(f"[1/{len(out)}] walls: ")
    assert sum("walls-cost-3:" in line for line in out) == 2 * sum(len(d) for d in WALL_COST_DX.values())


def test_advise_searches_the_prediction_on_a_wall_scene(tmp_path, capsys):
    """No stored run of plane-wall reaches the error: the prediction's search runs on plane-wall itself (its strip)
    and names a study of that scene; the paper's configuration's dx is the coarsest predicted to reach it."""
    import json

    from pcabench import cli

    path = tmp_path / "r" / "m.jsonl"
    strip = Scene.thinnest_strip(0.5)
    store.append(row(name="plane-wall", dx=0.5, t_end=10.0, model="linear", mse=0.33, strip_height=strip), path)
    code = cli.main(["advise", "--scene", "plane-wall", "--error", "0.2", "--results", str(path.parent), "--json"])
    out = json.loads(capsys.readouterr().out)
    s = out["suggestion"]
    assert code == 1 and not out["found"] and s["predicted_error"] <= 0.2
    assert "--scene plane-wall --strip" in s["study"]
    paper = s["paper_dx"]

    def error(dx):
        return predict(Scene(dx=dx, name="plane-wall", t_end=10.0, model="linear")).predicted_error

    from pcabench.predict.search import SEARCH_DX
    from solvers import SceneError

    coarser = []
    for dx in (d for d in SEARCH_DX if d > paper):
        try:
            coarser.append(error(dx))
        except SceneError:  # too coarse for the wall's support: not searched
            pass
    assert error(paper) <= 0.2 and coarser and min(coarser) > 0.2
    code = cli.main(
        ["advise", "--scene", "plane-wall", "--error", "0.2", "--model", "lagrangian", "--results", str(path.parent)]
    )
    text = capsys.readouterr().out
    assert code == 1 and "no lagrangian run of plane-wall can be scored (no isothermal solution is known there)" in text
    assert "--model linear" in text  # the suggested study is one whose runs can be scored
