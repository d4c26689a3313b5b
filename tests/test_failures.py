"""A run that fails says what failed (issue 66): a blow-up names its step, its time and the field past its bound,
every field is bounded (drho too), and a combination known to blow up is the default nowhere and is named before
any work (a ghost body with a corrected kernel) by `run` and `accuracy`; a kernel cut below where it keeps its
order is named too."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from pcabench.execute.run import past_bound, run, score
from pcabench.spec import RunSpec
from solvers import Scene, SceneError, make_solver

from .conftest import cli_main

CORRECTED = {"kernel": "laguerre-gauss", "h_factor": 1.5, "cutoff_factor": 4.0, "correction": "gradient"}


def test_a_corrected_method_on_a_body_defaults_to_the_wall_that_holds():
    """Standard SPH keeps its ghost rings; with the correction the default body is the weak wall with its cut
    cells (ghosts with a corrected kernel blew up at the body: docs/accuracy.md), and nothing is cautioned."""
    assert Scene(dx=0.04, name="cylinder").boundary_method_used == "rings"
    corrected = Scene(dx=0.04, name="cylinder", **CORRECTED)
    assert corrected.boundary_method_used == "cut" and not corrected.known_failure and not corrected.cautions
    assert "cut wall" in corrected.describe()


@pytest.mark.parametrize("method", ["rings", "lattice"])
def test_a_ghost_body_with_a_correction_is_named_as_known_to_blow_up(method, capsys):
    scene = Scene(dx=0.04, name="cylinder", boundary_method=method, **CORRECTED)
    assert f"--boundary-method {method} with --correction gradient is known to blow up" in scene.known_failure
    assert "--boundary-method cut holds" in scene.known_failure
    args = ["accuracy", "--scene", "cylinder", "--dx", "0.04", "--t-end", "10", "--boundary-method", method]
    args += ["--kernel", "laguerre-gauss", "--h-factor", "1.5", "--cutoff", "4", "--correction", "gradient"]
    rc, out, err = cli_main(*args, capsys=capsys)
    assert rc == 0 and out.startswith("warning: --boundary-method") and "known to blow up" in out, out + err
    rc, out, err = cli_main(*args, "--json", capsys=capsys)
    assert rc == 0 and "known to blow up" in json.loads(out)["known_failure"]


def test_a_blown_up_run_says_so_with_its_step_time_and_field_and_no_measures(capsys):
    """The 2D pulse at CFL 8 grows past its bound: the text says it blew up, where and in which field, and
    prints no error, no 'no pulse in the scored domain' and no NaN neighbour count."""
    args = ["run", "--solver", "linkedlist-cpu", "--scene", "acoustic-pulse", "--dx", "1", "--t-end", "200"]
    rc, out, err = cli_main(*args, "--model", "linear", "--cfl", "8", "--quiet", capsys=capsys)
    assert rc == 1, out + err
    status = next(line for line in out.splitlines() if line.startswith("status"))
    assert "unstable: blew up at step" in status and "(t = " in status, status
    message = next(line for line in out.splitlines() if line.startswith("message"))
    assert "max|velocity|" in message or "max|drho|" in message or "not finite" in message, message
    assert "nan" not in out.lower() and "no pulse" not in out and "mean neighbours" not in out, out


def test_every_field_is_bounded_drho_too():
    """A drho-only blow-up (x 1e300) is past the bound, in the run's check and in the parent's scoring."""
    scene = Scene(dx=1.0, name="acoustic-pulse", steps=2, model="linear")
    assert past_bound(scene, {"velocity": 0.0, "drho": 1e300}, "=", "at step 2").startswith("max|drho| = 1e+300")
    assert "velocity is not finite" in past_bound(scene, {"velocity": float("nan"), "drho": 0.0}, "=", "")
    assert past_bound(scene, {"velocity": 0.0, "drho": 0.0}, "=", "") == ""
    record = run(RunSpec("linkedlist-cpu", scene).resolved(), "m", scored=False)  # its steps, unscored
    solver = make_solver("linkedlist-cpu")
    solver.input(scene)
    solver.init()
    fields = solver.output()
    fields = dataclasses.replace(fields, drho=np.asarray(fields.drho) * 1e300, t=record.steps * scene.dt)
    scored = score(record, scene, fields)
    assert scored.status == "error" and "max|drho| reaches" in scored.message, scored.message


def test_a_fourth_order_kernel_cut_below_4h_is_named_and_the_cutoff_message_names_the_kernel():
    assert "loses its order" in Scene(dx=0.5, name="acoustic-pulse", **{**CORRECTED, "cutoff_factor": 2.0}).cautions[0]
    assert not Scene(dx=0.5, name="acoustic-pulse", **CORRECTED).cautions
    with pytest.raises(SceneError, match="truncated kernel laguerre-gauss must be in"):
        Scene(dx=0.5, kernel="laguerre-gauss", cutoff_factor=40.0)


def test_a_corrected_row_on_a_body_stored_before_cut_cells_were_the_default_reads_as_the_staircase_it_ran():
    """A stored corrected row on a body that names no wall says the wall it ran (``boundary_method_used``); one
    stored before rows said it took the staircase (``weak``, then the default) and reads so: another
    configuration than today's default runs, whose cut cells it did not have."""
    from pcabench.spec import identity, scene_from_row

    today = Scene(dx=0.04, name="cylinder", **CORRECTED)
    assert today.as_dict()["boundary_method_used"] == "cut" and scene_from_row({"scene": today.as_dict()}) == today
    old = Scene(dx=0.04, name="cylinder", boundary_method="weak", **CORRECTED).as_dict()
    old["boundary_method"] = ""
    del old["boundary_method_used"]
    read = scene_from_row({"scene": old})
    assert read.boundary_method_used == "weak" and read.boundary_method == "weak"
    key = {"solver": "linkedlist-cpu", "threads": 1, "preset": "", "profile": "m", "code": "c", "host": "h"}
    assert identity(scene=old, **key) != identity(scene=today, **key)
    standard = Scene(dx=0.04, name="cylinder").as_dict()
    del standard["boundary_method_used"]
    assert scene_from_row({"scene": standard}).boundary_method == ""  # uncorrected: its default never changed
