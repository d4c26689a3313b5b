"""Each run's headline error names what it measures and means something at the run's time (issue 59): against the
exact solution while the pulse is in the scored domain, what is left once it has gone, the workshop's probes
for the cylinder; never a relative error whose reference is zero."""

from __future__ import annotations

import json
import math

import pytest

from solvers import Scene

from .conftest import cli_main


@pytest.mark.parametrize(
    "kw, t, name",
    [
        ({}, 10.0, "rms_u"),  # the paper's scene: the pulse at x = 10 of [-10, 40]
        ({}, 40.0, "left_energy"),  # it has reached the free end at x = 40
        ({"open": "x", "strip_height": 5.0}, 64.0, "left_energy"),  # through the open end
        ({"open": "x", "strip_height": 5.0}, 20.0, "rms_u"),
        ({"name": "plane-wall"}, 10.0, "rms_u"),  # reflected by the wall at x = 6, not yet at the free end
        ({"name": "plane-wall"}, 40.0, "left_energy"),  # the reflection has reached the free left end
        ({"name": "acoustic-pulse"}, 100.0, "rms_drho"),  # a periodic square: the sound never leaves
        ({"name": "acoustic-pulse", "open": "xy"}, 5.0, "rms_drho"),  # the ring inside the 40 m square
        ({"name": "acoustic-pulse", "open": "xy"}, 28.0, "left_energy"),  # relative RMS 1.1 there: not a measure
        ({"name": "cylinder"}, 10.0, "probes_p"),  # the workshop's measure
        ({"name": "cylinder"}, 2.0, "rms_drho"),  # before the probes' window
    ],
)
def test_each_scene_names_the_measure_that_means_something_at_its_time(kw, t, name):
    scene = Scene(dx=0.25 if kw.get("name") != "cylinder" else 0.04, t_end=t, model="linear", **kw)
    assert scene.kind.measure(scene, t) == name


def test_an_open_run_past_the_pulse_stores_prints_and_lists_what_is_left(tmp_path, capsys):
    args = ("run", "--solver", "linkedlist-cpu", "--dx", "0.5", "--strip-height", "10", "--open", "x")
    args += ("--model", "linear", "--t-end", "64", "--quiet")
    rc, out, err = cli_main(*args, "--json", capsys=capsys)
    record = json.loads(out)
    assert rc == 0 and record["measure"] == "left_energy", err
    assert record["headline"] == record["errors"]["left_energy"] and 0 < record["headline"] < 0.1
    assert record["mse"] is None  # the relative error against a reference of zero: undefined, never 1e26
    rc, text, _ = cli_main(*args, capsys=capsys)
    assert f"headline         left_energy {record['headline']:.6g}: energy of the error left" in text
    rc, _, _ = cli_main(*args, "--store", "--results", str(tmp_path), capsys=capsys)
    rc, table, _ = cli_main("runs", "--results", str(tmp_path), capsys=capsys)
    header, row = table.strip().splitlines()[:2]
    assert header.split()[-4:-1] == ["measure", "error", "timestamp"], header  # measure, then its value
    assert f" left_energy {record['headline']:.4g} " in row and " x/default/" in row, table


def test_no_stored_reference_run_has_a_headline_against_a_vanished_pulse():
    """Rows stored before the headline (the reference store's 82 open runs once listed errors up to 4.6e28) are
    named by their scene's rule: every finished run's headline is a number of order one or less."""
    from pcabench import paths
    from pcabench.reports.frame import load

    df = load(paths.reference_results())
    ok = df[(df.status == "ok") & df.headline.notna()]
    assert len(ok) > 1000 and ok.headline.max() < 10, ok.sort_values("headline").tail(3)
    left = df[(df.status == "ok") & (df.measure == "left_energy")]
    assert len(left) > 100 and left.open.isin(["x", "xy", ""]).all()
    assert all(math.isfinite(v) for v in ok.headline)
