"""The method as one value (issue 40, item 1): what a Scene's numerics are, what a stored row's are, and the one
answer to "is this the paper's method"."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from pcabench import store
from pcabench.reports import frame
from pcabench.reports.long_runs import long_run_limits
from pcabench.spec import RunSpec, scene_from_row
from pcabench.store.record import RunRecord
from pcabench.store.rows import default_numerics, is_paper_method, numerics_label
from solvers import Scene, SceneError
from solvers.method import Method


def test_the_paper_method_is_scenes_defaults_and_every_change_leaves_it():
    assert Method.of(Scene(dx=1.0, steps=2)) == Method.paper() and Method.paper().is_paper()
    assert Method.paper().label == "gaussian, h 2.13dx, 3h, CFL 0.2"
    for change in (
        dict(kernel="wendland-c2"),
        dict(h_factor=1.3),
        dict(cutoff_factor=2.5),
        dict(cfl=0.4),
        dict(integrator="rk2"),
    ):
        assert not Method.of(Scene(dx=1.0, steps=2, **change)).is_paper(), change


def test_a_compact_kernels_method_has_no_truncation():
    m = Method.of(Scene(dx=1.0, steps=2, kernel="wendland-c2"))
    assert m.cutoff_factor is None and m.label == "wendland-c2, h 2.13dx, CFL 0.2"
    stored = {"kernel": "wendland-c2", "h_factor": 2.13, "cutoff_factor": 2.5, "cfl": 0.2, "integrator": "verlet"}
    assert Method.of(stored) == m  # a compact kernel is cut at its support, whatever a row's factor says


def test_a_stored_row_and_its_frame_row_give_the_scenes_method_and_scene(tmp_path):
    scene = Scene(
        dx=0.5, name="plane-wall", x_max=12.0, t_end=10.0, kernel="wendland-c4", h_factor=1.7, cfl=0.9, model="linear"
    )
    rec = RunRecord.from_spec(RunSpec("linkedlist-cpu", scene).resolved(), "m", status="ok")
    row = store.append(rec, tmp_path / "m--h.jsonl")
    (r,) = [r for _, r in frame.load(tmp_path).iterrows()]
    assert Method.of(row["scene"]) == Method.of(r) == Method.of(scene)
    assert scene_from_row(row) == scene_from_row(r) == scene
    assert numerics_label(r) == Method.of(scene).label and not is_paper_method(r)
    assert default_numerics(frame.load(tmp_path)).empty


@pytest.mark.parametrize("missing", ["kernel", "cutoff_factor", "integrator"])
def test_a_row_that_predates_a_parameter_reads_it_at_its_default(missing):
    row = {k: Scene.default(k) for k in ("kernel", "h_factor", "cutoff_factor", "cfl", "integrator")}
    del row[missing]
    assert Method.of(row).is_paper()


def test_the_stable_cfl_is_the_dispersion_relations_for_the_method():
    from solvers.reference.dispersion import predicted_stable_cfl

    for scene in (
        Scene(dx=0.25, t_end=1.0, model="linear"),
        Scene(dx=1.0, t_end=1.0, kernel="wendland-c2", h_factor=1.3, model="linear", cfl=2.0),
    ):
        assert predicted_stable_cfl(Method.of(scene)) == pytest.approx(
            predicted_stable_cfl(scene), rel=1e-9
        )  # the method alone
    assert predicted_stable_cfl(Method.of(Scene(dx=1.0, steps=2, integrator="euler"))) == 0


def test_the_measured_limits_are_the_reference_stores_long_runs():
    """Every row of pcabench/predict/measured_limits.csv whose long runs are in the reference store says what
    those runs say (the smallest CFL that blew up, the largest bounded below it), and every limit the stored
    long runs put below the prediction has its row: the data is the store's, not a copy that can drift."""
    from pcabench import paths
    from pcabench.predict.stability import measured_limits
    from pcabench.reports import frame

    df = frame.load(paths.reference_results())
    data = {(s, m, k, h, i, corr): v for (s, m, k, h, _c, i, corr), v in measured_limits().items()}
    checked = 0
    from pcabench.studies.cylinder.plan import CYLINDER_ADVISED

    paper = ("gaussian", 2.13)
    from pcabench.studies.high_order.plan import LONG_CFLS, LONG_H

    high_order = {(kernel, LONG_H) for kernel, _integrator in LONG_CFLS}  # every corrected method advise searches
    presets = (
        ("stability-long", {paper}),
        ("walls", {paper}),
        ("cylinder", {CYLINDER_ADVISED}),
        ("cylinder-wall", {("laguerre-gauss-6", 1.5)}),  # the sixth-order kernel's step with the body
        ("high-order", high_order),
    )
    for preset, methods in presets:
        for r in long_run_limits(df, preset):
            if (r["kernel"], r["h_factor"]) not in methods or r["blew_up_from"] is None:
                continue
            key = (r["scene"], r["model"], r["kernel"], r["h_factor"], r["integrator"], r["correction"])
            if r["blew_up_from"] < r["predicted"]:
                assert data.get(key) == (r["blew_up_from"], r["bounded_to"]), (key, r)
                checked += 1
            else:
                assert key not in data, (key, r)  # no limit below the prediction where the runs found none
    assert checked == len(data) > 0  # every row checked against its runs, and there are rows
    # the 3D long runs (pcabench study --three-d long): no row of their own (the cube's limits are the cubic
    # lattice's; the sphere's wall takes the free end's, found no higher than where the sphere blew up), and the
    # step the suite takes for each is below the smallest CFL that blew up
    from pcabench.predict.stability import stable_cfl

    three_d = [r for r in long_run_limits(df, "three-d-long") if r["blew_up_from"] is not None]
    assert {r["scene"] for r in three_d} == {"acoustic-pulse-3d", "sphere"} and len(three_d) >= 6
    for r in three_d:
        key = (r["scene"], r["model"], r["kernel"], r["h_factor"], r["integrator"], r["correction"])
        assert key not in data and stable_cfl(r) < r["blew_up_from"], (key, stable_cfl(r), r)
        if r["scene"] == "acoustic-pulse-3d":
            assert r["blew_up_from"] >= r["predicted"] and (r["bounded_to"] or 0) < r["predicted"], r


def test_the_paper_method_is_named_in_words_from_scenes_defaults():
    """Issue 58: the reports name the paper's method from Method.paper() (Scene's defaults), not from a copy
    typed into each section: change a default and every sentence follows."""
    from solvers import Scene
    from solvers.method import Method

    words = Method.paper().words
    for part in (f"h = {Scene.default('h_factor'):g} dx", f"{Scene.default('cutoff_factor'):g}h",
                 f"CFL {Scene.default('cfl'):g}", Scene.default("kernel").capitalize()):  # fmt: skip
        assert part in words, (part, words)
    corrected = Method("laguerre-gauss", 1.5, 4.0, 1.0, "rk4", "gradient").words
    assert corrected.endswith("rk4, gradient-corrected") and "h = 1.5 dx, 4h" in corrected
    assert Method("wendland-c2", 2.0, None, 0.5, "verlet").words == "Wendland-c2, h = 2 dx, CFL 0.5, Verlet"
    studies = Path(__file__).resolve().parents[1] / "pcabench" / "studies"
    typed = [p for p in studies.rglob("*.py") if "h = 2.13 dx, 3h" in p.read_text() or "h 2.13dx, 3h" in p.read_text()]
    assert typed == []


def test_a_scene_holds_its_method_and_edges_and_its_parameters_are_one_list():
    """Scene.PARAMETERS is the scene as stored (every keyword, every record column the schema checks, every
    option's field), read back through the Method and Edges values it holds; the values round-trip."""
    from pcabench.parameters import PARAMETERS
    from pcabench.store.schema import SCENE_FIELDS
    from solvers.edges import Edges

    s = Scene(dx=0.5, kernel="wendland-c2", h_factor=1.5, open="x", absorber="sponge", layer_width=2.0, cfl=0.3)
    assert list(s.parameters()) == list(Scene.PARAMETERS)
    assert set(Scene.PARAMETERS) <= set(SCENE_FIELDS) and {p.field for p in PARAMETERS} <= set(Scene.PARAMETERS)
    assert s.method == Method.of(s.parameters()) == Method("wendland-c2", 1.5, None, 0.3, "verlet", "none")
    assert s.edges == Edges(open="x", layer_width=2.0, absorber="sponge") and s.n_layer == 4
    assert Scene(**s.parameters()) == s == Scene(0.5, method=s.method, edges=s.edges)
    gaussian = Scene(0.5, method=s.method, kernel="gaussian")  # a flat keyword refines the value it belongs to
    assert gaussian.method == Method("gaussian", 1.5, 3.0, 0.3, "verlet", "none") and gaussian.cutoff == 4.5 * 0.5
    assert s.replace(open="").edges == Edges()  # closing the edges lets go of the layer's options
    assert Scene(dx=0.5).method == Method.paper() and Scene.default("cutoff_factor") == 3.0


def test_a_scenes_body_is_a_value_beside_its_edges():
    """The body's radius and wall model are one value (solvers/body.py): resolved to the kind's radius, read
    through by the flat keywords, given whole or refined by a keyword, and refused in one line on a scene
    without that body."""
    from solvers.body import BodyOptions

    s = Scene(0.1, "cylinder", boundary_method="lattice")
    assert s.body_options == BodyOptions(cylinder_radius=0.5, boundary_method="lattice") and s.body == (0.0, 0.0, 0.5)
    assert (s.cylinder_radius, s.sphere_radius, s.boundary_method_used) == (0.5, None, "lattice")
    assert Scene(**s.parameters()) == s == Scene(0.1, "cylinder", body_options=s.body_options)
    wider = Scene(0.1, "cylinder", body_options=s.body_options, cylinder_radius=0.7)
    assert wider.body == (0.0, 0.0, 0.7) and wider.boundary_method == "lattice"
    assert Scene(0.125, "sphere", correction="gradient").body_options == BodyOptions(sphere_radius=0.5)
    assert Scene(0.125, "sphere", correction="gradient").boundary_method_used == "cut"  # the corrected default
    assert Scene(0.5).body_options == BodyOptions() and Scene(0.5).body is None
    with pytest.raises(SceneError, match=r"^--sphere-radius: the cylinder scene has no body of that shape"):
        Scene(0.1, "cylinder", sphere_radius=0.5)
    with pytest.raises(SceneError, match=r"^body_options must be a BodyOptions value"):
        Scene(0.1, "cylinder", body_options={"cylinder_radius": 0.5})


def test_a_method_names_why_it_cannot_run_and_a_scene_refuses_it_with_that_line():
    ok = [Method.paper(), Method("wendland-c4", 1.3, None, 2.0, "rk4", "gradient")]
    assert all(list(m.problems()) == [] for m in ok)
    bad = {
        Method("gaussian", 0.3, 3.0, 0.2, "verlet"): "h_factor (h/dx) must be in [0.5, 10]",
        Method("gaussian", 2.13, 0.5, 0.2, "verlet"): "cutoff_factor (cutoff/h) must be >= 1",
        Method("wendland-c2", 2.13, 4.0, 0.2, "verlet"): "cutoff_factor applies to the truncated Gaussian only",
        Method("wendland-c2", 0.5, None, 0.2, "verlet"): "must be > 1 to reach the nearest particles",
        Method("gaussian", 2.13, 3.0, 0.2, "leapfrog"): "integrator must be one of",
        Method("nope", 2.13, 3.0, 0.2, "verlet"): "nope",
    }
    for method, words in bad.items():
        (line,) = method.problems()  # one line each
        assert words in line, line
        with pytest.raises(SceneError, match=re.escape(words)):
            Scene(0.5, method=method)
    for bad in ({"method": "gaussian"}, {"edges": "x"}):  # a value of the wrong kind: one line naming it
        with pytest.raises(SceneError, match=f"{next(iter(bad))} must be a"):
            Scene(0.5, **bad)
