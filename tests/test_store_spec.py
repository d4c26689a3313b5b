"""Issue 39: one writer, one reader, one spec. Each test is a break found by a hostile probe of the store, the
children, the files and the printed commands, failing before the mechanism it names was mended."""

from __future__ import annotations

import errno
import json
import os
import re
import signal
import subprocess
import sys
import textwrap
import time
import warnings
from pathlib import Path

import numpy as np
import pytest

from pcabench import store
from pcabench.execute.run import run
from pcabench.execute.sweep import run_child, sweep
from pcabench.spec import RunSpec
from pcabench.store import provenance
from pcabench.store.record import RunRecord
from solvers import Scene

from .conftest import cli_main
from .test_registry import install


def advisable(**kw) -> RunRecord:
    """A finished run of the 2D pulse advise can use (t_end 10 s, linear), on machine m, host h."""
    spec = RunSpec("linkedlist-cpu", Scene(dx=1.0, t_end=10.0, model="linear")).resolved()
    rec = RunRecord.from_spec(spec, "m", status="ok")
    rec.steps, rec.mse, rec.me, rec.host = spec.scene.n_steps, 0.1, 0.001, "h"
    rec.stages.update(snp=0.001, pi=0.01, su=0.0005)
    for k, v in kw.items():
        setattr(rec, k, v)
    return rec


# ---------------------------------------------------------------- 1. reading: one typed record
def test_an_unknown_key_beside_a_missing_stage_breaks_no_reader(tmp_path, capsys):
    results = tmp_path / "results"
    path = results / "m--h.jsonl"
    good = store.append(advisable(), path)
    odd = dict(good, run_id="odd1", t_init="soon", t_step="x", machine="forged", scene_key=3)
    torn_stage = dict(good, run_id="odd2", t_init="soon")
    torn_stage["stages"] = {k: v for k, v in good["stages"].items() if k != "init"}
    with open(path, "a") as f:
        for row in (odd, torn_stage):
            f.write(json.dumps(row) + "\n")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rows = store.read_rows(results)
    assert sorted(r["run_id"] for r in rows) == sorted([good["run_id"], "odd1"])  # the unknown keys, dropped
    assert all("t_init" not in r and "machine" not in r for r in rows)
    assert [str(w.message) for w in caught if "stages lack init" in str(w.message)] == [
        next(str(w.message) for w in caught if f"{path}:3:" in str(w.message))
    ]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", store.StoreWarning)
        code, out, err = cli_main("runs", "--results", str(results), capsys=capsys)
        assert code == 0 and len(out.splitlines()) == 3 and "Traceback" not in err, (out, err)
        code, out, err = cli_main("report", "--results", str(results), "--out", str(tmp_path / "out"), capsys=capsys)
        assert code == 0 and "Traceback" not in err, err
        code, out, err = cli_main(
            "advise", "--results", str(results), "--error", "0.5", "--machine", "m", capsys=capsys
        )
        assert code == 0 and "pcabench run --solver linkedlist-cpu" in out, (out, err)


@pytest.mark.parametrize(
    "change, says",
    [
        ({"n_particles": 10**9}, "'n_particles' 1000000000 is not its scene's"),
        ({"n_particles": 10**9, "scene.n_particles": 10**9}, "not the 1000 particles its scene's lattice holds"),
        ({"steps": 10**6}, "'steps' 1000000 is more than its scene's"),
        ({"model": "lagrangian"}, "'model' 'lagrangian' is not its scene's 'linear'"),
        ({"dx": 0.5}, "'dx' 0.5 is not its scene's 1.0"),
    ],
)
def test_a_rows_derived_fields_are_checked_against_its_scene(tmp_path, change, says):
    """A row that claims another particle count, more steps than asked, or another model or dx than its scene
    (a forged or hand-edited line: 1e9 particles for a 2,500-particle scene would reach the report) is skipped
    with one warning naming the field; the good row beside it is read."""
    path = tmp_path / "m--h.jsonl"
    good = store.append(advisable(), path)
    forged = json.loads(json.dumps(good))
    forged["run_id"] = "forged"
    for key, value in change.items():
        where, _, name = key.rpartition(".")
        (forged[where] if where else forged)[name] = value
    with open(path, "a") as f:
        f.write(json.dumps(forged) + "\n")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rows = store.read_rows(path)
    assert [r["run_id"] for r in rows] == [good["run_id"]]
    (message,) = [str(w.message) for w in caught]
    assert f"{path}:2:" in message and says in message, message


def test_one_run_id_with_two_records_warns_naming_both_and_the_later_write_wins(tmp_path):
    results = tmp_path / "results"
    real = store.append(advisable(timestamp="2026-12-01T10:00:00+00:00"), results / "m--h.jsonl")
    forged = dict(real, mse=1e-12, timestamp="2027-11-01T10:00:00+00:00")  # read first, a later time claimed
    (results / "a--h.jsonl").write_text(json.dumps(forged) + "\n")
    copy = results / "z--h.jsonl"
    copy.write_text(json.dumps(real) + "\n")  # the same record copied into another store: one run, no warning
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rows = store.read_rows(results)
    assert [r["mse"] for r in rows] == [real["mse"]]
    (message,) = [str(w.message) for w in caught]
    assert f"{results / 'a--h.jsonl'}:1" in message and f"{results / 'm--h.jsonl'}:1" in message
    assert "later write" in message and str(copy) not in message
    # the later line wins, whatever the rows' own times say: the order of appends (issue 57: a copy of the real
    # row with a later timestamp, written before it, must not win)
    again = dict(real, mse=0.2, timestamp="2020-01-01T00:00:00+00:00")
    with open(results / "m--h.jsonl", "a") as f:
        f.write(json.dumps(again) + "\n")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", store.StoreWarning)
        assert [r["mse"] for r in store.read_rows(results / "m--h.jsonl")] == [0.2]


# ---------------------------------------------------------------- 2. writing: the sweep builds the record
def with_site(tmp_path, monkeypatch, code: str) -> None:
    """Every python started from here imports ``code`` first (sitecustomize): a run's child as a plug-in
    would have it."""
    (tmp_path / "sitecustomize.py").write_text(textwrap.dedent(code))
    monkeypatch.setenv("PYTHONPATH", f"{tmp_path}{os.pathsep}{os.environ.get('PYTHONPATH', '')}")
    monkeypatch.setenv("PCABENCH_FORKSERVER", "0")  # a server started with this sitecustomize would outlive the test


def pcabench(*args, module: str = "pcabench.cli", site=None, timeout: float = 120):
    """``python -m pcabench.cli ARGS`` (or ``module``) in a fresh interpreter, with the plug-ins of ``site`` on its
    path: the finished process (text output)."""
    env = dict(os.environ)
    if site is not None:
        env["PYTHONPATH"] = os.pathsep.join([str(site), os.environ.get("PYTHONPATH", "")])
    cmd = [sys.executable, "-m", module, *args]
    return subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=timeout)


LIAR = """
from pcabench import store

_to_row = store.to_row

def forged(record):
    row = _to_row(record)
    row.update(solver="allpair-cpu", profile_id="h100-80gb-hbm3__intel-xeon", host="forged", commit="deadbeef",
               mse=1e-12, me=1e-12, errors={"wall_rms": 0.0}, versions={"numba": "99"}, preset="paper",
               scene=dict(row["scene"], dx=0.01), dx=0.01)
    return row

store.to_row = forged
"""


def test_the_sweep_takes_only_measurements_from_its_child_and_scores_the_fields_itself(tmp_path, monkeypatch):
    spec = RunSpec("linkedlist-cpu", Scene(dx=1.0, steps=3)).resolved()
    honest = run(spec, "m")
    with_site(tmp_path, monkeypatch, LIAR)
    row = run_child(spec, 120, "abc", "m", stream=None)
    assert row["status"] == "ok", row["message"]
    assert (row["solver"], row["profile_id"], row["commit"], row["preset"]) == ("linkedlist-cpu", "m", "abc", "")
    assert row["host"] == provenance.host_id() and row["versions"] == provenance.package_versions()
    assert row["dx"] == row["scene"]["dx"] == 1.0 and row["n_particles"] == spec.scene.n_particles
    assert row["mse"] == honest.mse and row["me"] == honest.me  # computed from its fields, not taken
    assert row["errors"] == honest.errors


NAN_FIELDS = """
import numpy as np
from solvers.linkedlist_cpu import LinkedListCPU

_output = LinkedListCPU.output

def output(self):
    f = _output(self)
    f.u[3] = np.nan
    return f

LinkedListCPU.output = output
"""

SHORT_FIELDS = NAN_FIELDS.replace("f.u[3] = np.nan", "f.drho = f.drho[:-1]")


@pytest.mark.parametrize("site, field", [(NAN_FIELDS, "u"), (SHORT_FIELDS, "drho")], ids=["nan", "short"])
def test_a_run_whose_fields_are_nan_or_short_is_an_error_not_ok(site, field, tmp_path, monkeypatch):
    with_site(tmp_path, monkeypatch, site)
    spec = RunSpec("linkedlist-cpu", Scene(dx=1.0, steps=2)).resolved()
    row = run_child(spec, 120, "abc", "m", stream=None)
    assert row["status"] == "error" and f"field {field}" in row["message"], row
    assert row["mse"] is None and store.validate(row) == ""


SPAWNS = """
import os, subprocess, time
from solvers.linkedlist_cpu import LinkedListCPU

_init = LinkedListCPU.init

def init(self):
    left = subprocess.Popen(["sleep", "600"])
    with open(os.environ["PIDS"], "a") as f:
        f.write(f"{left.pid}\\n")
    if os.environ.get("HANG"):
        time.sleep(600)
    return _init(self)

LinkedListCPU.init = init
"""


def alive(pid: int) -> bool:
    try:
        state = open(f"/proc/{pid}/stat").read().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


@pytest.mark.parametrize("hang", [True, False], ids=["past-its-budget", "finished"])
def test_what_a_run_starts_ends_with_it(hang, tmp_path, monkeypatch):
    with_site(tmp_path, monkeypatch, SPAWNS)
    monkeypatch.setenv("PIDS", str(tmp_path / "pids"))
    if hang:
        monkeypatch.setenv("HANG", "1")
    spec = RunSpec("linkedlist-cpu", Scene(dx=1.0, steps=2)).resolved()
    if hang:
        with pytest.raises(subprocess.TimeoutExpired):
            run_child(spec, 5, "abc", "m", stream=None)
    else:
        assert run_child(spec, 120, "abc", "m", stream=None)["status"] == "ok"
    pids = [int(p) for p in (tmp_path / "pids").read_text().split()]
    deadline = time.monotonic() + 10
    while any(map(alive, pids)) and time.monotonic() < deadline:
        time.sleep(0.1)
    assert pids and not any(map(alive, pids))


DEAF = """
import signal, time
from solvers.linkedlist_cpu import LinkedListCPU

def init(self):  # never returns to Python's signal handlers: blocks the alarm and SIGTERM, then waits
    signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGALRM, signal.SIGTERM, signal.SIGINT})
    time.sleep(600)

LinkedListCPU.init = init
"""


def test_run_budget_holds_for_a_solver_that_never_returns_to_python(tmp_path, monkeypatch):
    with_site(tmp_path, monkeypatch, DEAF)
    t0 = time.monotonic()
    out = pcabench("run", "--solver", "linkedlist-cpu", "--dx", "1", "--steps", "2", "--run-budget", "4", "--json")
    assert out.returncode == 1 and json.loads(out.stdout)["status"] == "timeout", (out.stdout, out.stderr)
    assert time.monotonic() - t0 < 60


def test_while_a_sweep_holds_its_store_no_other_writer_appends(tmp_path, monkeypatch):
    path = tmp_path / "results" / "m--h.jsonl"
    monkeypatch.setattr(store, "APPEND_WAIT", 0.2)
    refused = []

    def runner(spec, timeout, commit, machine, stream=None):  # a run whose own process writes the store
        try:
            store.append(advisable(run_id="forged", mse=1e-12), path)
        except store.StoreError as exc:
            refused.append(str(exc))
        return store.to_row(advisable())

    spec = RunSpec("linkedlist-cpu", Scene(dx=1.0, steps=2))
    rows = sweep([spec], path, run_budget=60, sweep_budget=60, runner=runner)
    assert len(rows) == 1 and refused and "held by a sweep" in refused[0]
    assert [r["run_id"] for r in store.read_rows(path)] == [rows[0]["run_id"]]
    store.append(advisable(run_id="after"), path)  # once the sweep is done, the store is anyone's again


@pytest.mark.parametrize("suffix", [".reserve", ".torn"])
def test_a_reserve_or_torn_link_is_refused_before_any_run(suffix, tmp_path):
    path = tmp_path / "results" / "m--h.jsonl"
    path.parent.mkdir()
    target = tmp_path / "elsewhere"
    target.write_text("keep")
    (path.parent / (path.name + suffix)).symlink_to(target)

    def runner(*args, **kw):
        raise AssertionError("a run started")

    spec = RunSpec("linkedlist-cpu", Scene(dx=1.0, steps=2))
    with pytest.raises(store.StoreError, match=f"{suffix}.*symbolic link"):
        sweep([spec], path, run_budget=60, sweep_budget=60, runner=runner)
    assert target.read_text() == "keep"


# ---------------------------------------------------------------- 5. the spec: commands from the whole spec
SCENES = {
    "paper": dict(dx=0.5, steps=3),
    "wall at 12 m, pulse at 2 m": dict(dx=0.5, name="plane-wall", x_max=12.0, t_end=10.0, pulse_center=2.0),
    "a 60 m square": dict(dx=1.0, name="acoustic-pulse", domain=60.0, t_end=10.0, mach=0.01, pulse_width=2.5),
    "a method": dict(
        dx=0.1,
        kernel="wendland-c2",
        cfl=1.5,
        model="linear",
        steps=5,
        strip_height=2.0,
        precision="float32",
        integrator="kdk1",
        h_factor=1.7,
    ),
    "a Gaussian's cutoff": dict(dx=0.5, cutoff_factor=2.5, h_factor=1.3, t_end=4.0),
    "open edges": dict(dx=0.5, steps=3, open="x", layer_width=4.5, absorber_strength=2.5),
    "the sphere in a smaller cube": dict(  # the 3D long runs' (pcabench study --three-d long)
        dx=0.125,
        name="sphere",
        domain=3.2,
        pulse_center=1.0,
        t_end=30.0,
        model="linear",
        kernel="laguerre-gauss",
        h_factor=1.5,
        cutoff_factor=4.0,
        correction="gradient",
        cfl=1.7,
        boundary_method="cut",
    ),  # fmt: skip
}


@pytest.mark.parametrize("name", SCENES)
def test_a_printed_run_command_makes_the_same_run(name):
    from pcabench import cli
    from pcabench.commands import run_words
    from pcabench.spec import scene_parameters
    from solvers import scene_kind

    given = dict(SCENES[name])
    if "domain" in given:
        given.update(scene_kind(given["name"]).sized_domain(given.pop("domain")))
    spec = RunSpec("linkedlist-cpu", Scene(**given), 2, pair_loop="gather").resolved()
    words, unset = run_words(spec)
    assert words[:2] == ["pcabench", "run"] and not unset
    args = cli.build_parser().parse_args(words[1:])
    again = cli.scene_from_args(args)
    assert scene_parameters(again) == scene_parameters(spec.scene), words
    from solvers import resolve_pair_loop

    assert (args.solver, args.threads) == ("linkedlist-cpu", 2)  # the loop written where auto would not take it
    assert resolve_pair_loop("linkedlist-cpu", again, args.pair_loop or "auto") == "gather"


def test_advise_writes_the_wall_and_the_pulse_it_found(tmp_path, capsys):
    results = tmp_path / "results"
    spec = RunSpec(
        "linkedlist-cpu", Scene(dx=0.5, name="plane-wall", x_max=12.0, pulse_center=2.0, t_end=10.0, model="linear")
    ).resolved()
    rec = RunRecord.from_spec(spec, "m", status="ok")
    rec.steps, rec.mse, rec.me, rec.host = spec.scene.n_steps, 0.01, 0.001, "h"
    rec.stages.update(snp=0.001, pi=0.01, su=0.0005)
    store.append(rec, results / "m--h.jsonl")
    code, out, err = cli_main(
        "advise",
        "--results",
        str(results),
        "--error",
        "0.5",
        "--scene",
        "plane-wall",
        "--t-end",
        "10",
        "--model",
        "linear",
        "--machine",
        "m",
        "--json",
        capsys=capsys,
    )
    assert code == 0, err
    words = json.loads(out)["command"].split()
    assert words[words.index("--wall-x") + 1] == "12" and words[words.index("--pulse-center") + 1] == "2", words


def test_run_json_carries_the_whole_scene(capsys):
    code, out, err = cli_main(
        "run",
        "--solver",
        "linkedlist-cpu",
        "--scene",
        "plane-wall",
        "--dx",
        "0.5",
        "--steps",
        "2",
        "--wall-x",
        "12",
        "--pulse-center",
        "2",
        "--mach",
        "0.01",
        "--json",
        "--quiet",
        capsys=capsys,
    )
    row = json.loads(out)
    assert code == 0 and store.validate(row) == ""
    scene = row["scene"]
    assert (scene["name"], scene["x_max"], scene["pulse_center"], scene["mach"]) == ("plane-wall", 12.0, 2.0, 0.01)
    assert scene["pulse_width"] == Scene.default("pulse_width") and row["solver"] == "linkedlist-cpu"


# ---------------------------------------------------------------- 3. files: one writer, no link followed
def _results(tmp_path):
    results = tmp_path / "results"
    store.append(advisable(), results / "m--h.jsonl")
    return results


@pytest.mark.parametrize("where", ["out", "home"])
def test_a_report_folder_that_is_a_link_is_refused_and_nothing_there_touched(where, tmp_path, capsys, monkeypatch):
    results, outside = _results(tmp_path), tmp_path / "outside"
    (outside / "m").mkdir(parents=True)
    (outside / "m" / "keep.png").write_text("mine")
    (outside / "README.md").write_text("mine")
    if where == "out":
        link = tmp_path / "out"
        args = ("--out", str(link))
    else:
        home = tmp_path / "home"
        home.mkdir()
        link = home / "reports"
        monkeypatch.setenv("PCABENCH_HOME", str(home))
        args = ()
    link.symlink_to(outside)
    code, _, err = cli_main("report", "--results", str(results), *args, capsys=capsys)
    assert code == 2 and "symbolic link" in err and str(link) in err, err
    assert (outside / "m" / "keep.png").read_text() == "mine" and (outside / "README.md").read_text() == "mine"
    assert sorted(p.name for p in outside.rglob("*")) == ["README.md", "keep.png", "m"]


@pytest.mark.parametrize("kind", ["link", "dangling"])
def test_run_fields_replaces_a_link_and_never_writes_where_it_points(kind, tmp_path, capsys):
    target = tmp_path / "precious.npz"
    if kind == "link":
        target.write_bytes(b"mine")
    fields = tmp_path / "f.npz"
    fields.symlink_to(target)
    code, _, err = cli_main(
        "run",
        "--solver",
        "linkedlist-cpu",
        "--dx",
        "1",
        "--steps",
        "2",
        "--fields",
        str(fields),
        "--quiet",
        capsys=capsys,
    )
    assert code == 0, err
    assert not fields.is_symlink() and np.load(fields)["u"].shape == (1000,)
    assert (target.read_bytes() == b"mine") if kind == "link" else not target.exists()


@pytest.mark.parametrize("name", ["", " ", "nodir/"])  # an existing folder: a file named by the run in it
def test_run_fields_that_name_no_file_are_one_line(name, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "dir").mkdir()
    code, _, err = cli_main(
        "run", "--solver", "linkedlist-cpu", "--dx", "1", "--steps", "2", "--fields", name, capsys=capsys
    )
    assert code == 2 and "--fields" in err and len(err.strip().splitlines()) == 1, err
    assert not Path("/.npz").exists() and sorted(p.name for p in tmp_path.iterdir()) == ["dir"]


def test_a_full_disk_writing_fields_names_the_path_and_leaves_no_partial_file(tmp_path, capsys, monkeypatch):
    from pcabench.store import safeio

    real = safeio._write_all

    def full(fd, data):
        real(fd, data[: len(data) // 2])
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(safeio, "_write_all", full)
    fields = tmp_path / "f.npz"
    code, _, err = cli_main(
        "run",
        "--solver",
        "linkedlist-cpu",
        "--dx",
        "1",
        "--steps",
        "2",
        "--fields",
        str(fields),
        "--quiet",
        capsys=capsys,
    )
    assert code != 0 and str(fields) in err and "full" in err, err
    assert list(tmp_path.iterdir()) == []


# ---------------------------------------------------------------- 4. text: one name rule, inert messages
@pytest.mark.parametrize("name", ["../../evil|scene <b>x</b>", "q'uote;id", "a" * 33, "-dash", ""])
def test_a_scene_plugin_with_a_name_outside_the_rule_is_left_out(name):
    from solvers.plugins import name_problem
    from solvers.scenes import SCENES
    from solvers.scenes.plane_pulse import PlanePulse

    odd = type("Odd", (PlanePulse,), {"name": name})
    assert name_problem(name, "scene") and SCENES.why_not(odd, set())
    with pytest.raises(ValueError, match="not a plain name|no name of its own"):
        SCENES.register(odd)


def test_a_stored_message_cannot_add_cells_tags_or_images_to_a_report(tmp_path, capsys):
    results = tmp_path / "results"
    store.append(advisable(), results / "m--h.jsonl")
    evil = "x | y | z <script>alert(1)</script> ![remote](http://example.com/t.png) **bold**"
    failed = advisable(status="error", mse=None, me=None, message=evil, run_id="bad1")
    store.append(failed, results / "m--h.jsonl")
    code, _, err = cli_main("report", "--results", str(results), "--out", str(tmp_path / "out"), capsys=capsys)
    assert code == 0, err
    text = (tmp_path / "out" / "m" / "report.md").read_text()
    assert "<script>" not in text and "![remote]" not in text
    assert not re.search(r"(?<!\\)\]\(http://example\.com", text)  # no link or image syntax left live
    lines = text.splitlines()
    (at,) = [i for i, ln in enumerate(lines) if "alert" in ln]
    top = at
    while top > 0 and lines[top - 1].startswith("|"):
        top -= 1  # the table's header

    def cells(line):
        return len(re.findall(r"(?<!\\)\|", line))

    assert cells(lines[at]) == cells(lines[top]), (lines[top], lines[at])


@pytest.mark.parametrize(
    "command, option",
    [
        (("accuracy", "--dx", "0.5", "--t-end", "10", "--pulse-center", "100"), "--pulse-center"),
        (
            ("run", "--solver", "linkedlist-cpu", "--dx", "0.5", "--steps", "2", "--pulse-center", "-50"),
            "--pulse-center",
        ),
        (
            ("accuracy", "--scene", "acoustic-pulse", "--dx", "0.5", "--t-end", "10", "--domain-size", "40000"),
            "available",
        ),
        (("accuracy", "--scene", "plane-wall", "--dx", "0.5", "--t-end", "10", "--wall-x", "1e7"), "available"),
        (("run", "--solver", "linkedlist-cpu", "--dx", "1", "--t-end", "1", "--cfl", "1e-12"), "--cfl"),
    ],
    ids=["accuracy-pulse-outside", "run-pulse-outside", "accuracy-domain-40 km", "accuracy-wall-1e7", "run-cfl-1e-12"],
)
def test_every_command_checks_the_scenes_ranges_and_memory_before_any_work(command, option, capsys):
    code, out, err = cli_main(*command, capsys=capsys)
    assert code == 2 and option in err and len(err.strip().splitlines()) == 1 and out == "", (out, err)


# ---------------------------------------------------------------- also found: signals, pipes, plug-ins
def _study_until_running(tmp_path):
    """A study (in a session of its own, as a terminal's foreground job would be) one run of which has started:
    (its process, the store it writes)."""
    from .conftest import run_children

    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "pcabench.cli",
            "study",
            "--dx",
            "1",
            "0.25",
            "--steps",
            "3",
            "100000",
            "--model",
            "linear",
            "--no-report",
            "--results",
            str(tmp_path),
        ],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
        # a terminal's foreground job takes Ctrl-C (a test runner's worker may have left SIGINT ignored, which a
        # process inherits and Python then keeps, as it should for a job started in the background)
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    deadline = time.time() + 120
    while time.time() < deadline:
        stored = list(tmp_path.glob("*.jsonl"))
        if stored and stored[0].read_text().count("\n") >= 1 and run_children(proc.pid):
            return proc, stored[0]
        time.sleep(0.1)
    proc.kill()
    raise AssertionError("the study never stored its first run")


@pytest.mark.parametrize("how, code, word", [("SIGINT", 130, "interrupted"), ("SIGTERM", 143, "terminated")])
def test_a_study_stopped_by_ctrl_c_or_sigterm_says_one_line_and_keeps_its_runs(how, code, word, tmp_path):
    proc, path = _study_until_running(tmp_path)
    ignored = int(next(ln for ln in open(f"/proc/{proc.pid}/status") if ln.startswith("SigIgn:")).split()[1], 16)
    os.killpg(proc.pid, getattr(signal, how))  # the whole foreground group, as a terminal's Ctrl-C does
    try:
        _, err = proc.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        _, err = proc.communicate()
        raise AssertionError(
            f"the study did not end within 60 s of {how} (its ignored signals: {ignored:#x}): {err[-3000:]}"
        ) from None
    assert proc.returncode == code and f"pcabench study: {word}" in err, err[-3000:]
    assert "Traceback" not in err, err[-3000:]
    assert not list(tmp_path.glob("*.reserve")) and len(store.read_rows(path)) >= 1


def test_output_cut_by_its_reader_is_not_bad_input(tmp_path):
    rows = [dict(store.to_row(advisable()), run_id=f"r{i}") for i in range(1500)]  # more than a pipe holds
    (tmp_path / "m--h.jsonl").write_text("".join(json.dumps(r) + "\n" for r in rows))
    proc = subprocess.Popen(
        [sys.executable, "-m", "pcabench.cli", "runs", "--results", str(tmp_path), "--limit", "100000"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    proc.stdout.readline()
    proc.stdout.close()  # `| head -1`
    err = proc.stderr.read().decode()
    assert proc.wait(timeout=60) == 141 and err == "", err


def test_a_plugin_that_exits_at_import_is_left_out_not_obeyed(tmp_path):
    site = install(tmp_path / "site", "quitter", "import sys\nsys.exit(0)\n", {"quitter": "quitter:Solver"})
    out = pcabench("run", "--solver", "linkedlist-cpu", "--dx", "1", "--steps", "2", "--json", "--quiet", site=site)
    assert out.returncode == 0 and json.loads(out.stdout)["status"] == "ok", (out.stdout, out.stderr)
    assert "quitter" in out.stderr and "left out" in out.stderr


def test_the_study_help_counts_each_presets_runs_from_its_plan():
    from pcabench import cli, studies
    from pcabench.studies.front.plan import front

    text = " ".join(cli.build_parser()._subparsers._group_actions[0].choices["study"].format_help().split())
    for name in ("quick", "paper", "stability", "stability-long", "walls"):
        assert f"({len(studies.preset(name))} runs" in text, name
    fixed = len(front("quick", fast=False))
    made = len(studies.preset("front"))
    extra = int(re.search(rf"quick: .*?\({fixed} runs and up to (\d+) predicted fastest", text).group(1))
    assert fixed < made <= fixed + extra


def test_the_time_predictor_does_not_extrapolate_a_steep_fit_from_two_small_sizes():
    from pcabench.predict import predicted_seconds, step_model

    def row(dx, step):
        spec = RunSpec("linkedlist-cpu", Scene(dx=dx, steps=10)).resolved()
        rec = RunRecord.from_spec(spec, "m", status="ok")
        rec.steps = 10
        rec.stages.update(snp=0.0, pi=10 * step, su=0.0)
        return store.to_row(rec)

    rows = [row(1.0, 1e-3), row(0.5, 40e-3)]  # 1,000 and 4,000 particles: a slope of 2.7 (a noisy neighbour)
    big = RunSpec("linkedlist-cpu", Scene(dx=0.05, steps=100)).resolved()  # 400K particles
    a, b, _ = step_model(big, rows)
    assert b <= 1.5
    seconds, why = predicted_seconds(big, rows)
    assert seconds < 100 * 40e-3 * (400_000 / 4_000) ** 1.5 + 60, why


SLOW_CLAIM = LIAR.replace('scene=dict(row["scene"], dx=0.01), dx=0.01)', 'stages={**row["stages"], "pi": 1000.0})')


def test_a_child_claiming_more_time_than_its_process_took_is_an_error(tmp_path, monkeypatch):
    with_site(tmp_path, monkeypatch, SLOW_CLAIM)
    spec = RunSpec("linkedlist-cpu", Scene(dx=1.0, steps=2)).resolved()
    row = run_child(spec, 120, "abc", "m", stream=None)
    assert row["status"] == "error" and "more than its process's" in row["message"], row["message"]


def test_a_ctrl_c_while_the_plugins_load_is_one_line(tmp_path):
    site = install(tmp_path / "site", "slow", "raise KeyboardInterrupt\n", {"slow": "slow:Solver"})  # a Ctrl-C
    out = pcabench("run", "--solver", "linkedlist-cpu", "--dx", "1", module="pcabench.console", site=site)
    assert out.returncode == 130 and out.stderr.strip().splitlines() == ["pcabench: interrupted"], out.stderr
