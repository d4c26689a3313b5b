"""Issue 31: the store holds against any row, any plug-in and any link.

Each probe is a hostile user's: a store merged from another machine, a solver that prints, a link left in a
folder, a full disk. Everything is built in tmp dirs; the tests signal only processes they started.
"""

from __future__ import annotations

import errno
import json
import os
import shlex
import subprocess
import sys
import warnings

import pytest

from pcabench import cli, store
from pcabench.execute import sweep as sweep_module
from pcabench.execute.sweep import sweep
from pcabench.machine import profiles
from pcabench.spec import RunSpec
from pcabench.store import provenance, schema
from pcabench.store.record import RunRecord
from solvers import Scene

from .conftest import cli_main, default_sigint, run_children, study_process


def record(**kw):
    rec = RunRecord.from_spec(RunSpec("linkedlist-cpu", Scene(dx=1.0, steps=3)).resolved(), "m", status="ok")
    rec.steps, rec.mse, rec.me = 3, 0.1, 0.001
    rec.stages.update(snp=0.001, pi=0.01, su=0.0005)
    for k, v in kw.items():
        setattr(rec, k, v)
    return rec


def good_row():
    return store.to_row(record())


def _scene_without_steps():
    scene = dict(good_row()["scene"])
    del scene["steps"]
    return scene


HOSTILE_ROWS = {  # the odd rows of issue 31, each a line of its own
    "run_id list": '{"run_id": ["a"]}',
    "host int": '{"host": 5}',
    "commit null": '{"commit": null}',
    "pair_loop list": '{"pair_loop": ["list"]}',
    "pair_loop int": '{"pair_loop": 3}',
    "device list": '{"device": ["cpu"]}',
    "timestamp int": '{"timestamp": 123}',
    "scene without steps": json.dumps({"scene": _scene_without_steps()}),
    "lone surrogate in solver": '{"solver": "linkedlist-cpu\\ud800"}',
    "profile_id README.md": '{"profile_id": "README.md"}',
    "profile_id cards.md": '{"profile_id": "cards.md"}',
    "300-char profile": json.dumps({"profile_id": "p" * 300}),
    "300-char host": json.dumps({"host": "h" * 300}),
    "dx 1e308": '{"dx": 1e308}',
    "scene dx 1e308": json.dumps({"scene": dict(good_row()["scene"], dx=1e308)}),
    "solver ../../forged": '{"solver": "../../forged"}',
    "escape in commit": '{"commit": "abc\\u001b[2J"}',
    "list in an extra key": '{"extra": [1, 2]}',
}


def hostile_line(name: str, run_id: str) -> str:
    row = dict(good_row(), run_id=run_id)
    row.update(json.loads(HOSTILE_ROWS[name]))
    return json.dumps(row, sort_keys=True)


NESTED = "[" * 5000 + "]" * 5000


@pytest.mark.parametrize("name", [*HOSTILE_ROWS, "5000-deep nesting"])
def test_every_hostile_row_is_skipped_with_one_warning_naming_line_and_field(name, tmp_path):
    path = tmp_path / "s.jsonl"
    good = store.append(record(), path)
    with open(path, "a") as f:
        f.write((NESTED if name.startswith("5000") else hostile_line(name, f"odd-{len(name)}")) + "\n")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rows = store.read_rows(path)
    assert [r["run_id"] for r in rows] == [good["run_id"]]
    messages = [str(w.message) for w in caught]
    assert len(messages) == 1 and f"{path}:2:" in messages[0], messages
    if not name.startswith("5000"):
        field = name.split()[0].replace("300-char", "").replace("lone", "solver").replace("escape", "commit")
        field = {"": "profile_id", "list": "extra", "dx": "dx", "scene": "scene"}.get(field, field)
        assert field in messages[0] or "host" in messages[0], messages


def test_report_runs_advise_and_study_survive_every_hostile_row_at_once(tmp_path, capsys, monkeypatch):
    results = tmp_path / "results"
    path = results / "m--h.jsonl"
    spec = RunSpec("linkedlist-cpu", Scene(dx=1.0, t_end=10.0, model="linear")).resolved()
    rec = RunRecord.from_spec(spec, "m", status="ok")  # a run advise finds: no search for a suggestion
    rec.steps, rec.mse, rec.me, rec.host = spec.scene.n_steps, 0.1, 0.001, "h"
    rec.stages.update(snp=0.001, pi=0.01, su=0.0005)
    good = store.append(rec, path)
    with open(path, "a") as f:
        for i, name in enumerate(HOSTILE_ROWS):
            f.write(hostile_line(name, f"odd{i}") + "\n")
        f.write(NESTED + "\n")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", store.StoreWarning)
        code, out, err = cli_main("runs", "--results", str(results), capsys=capsys)
        assert code == 0 and "Traceback" not in err and len(out.splitlines()) == 2, (out, err)
        code, out, err = cli_main("report", "--results", str(results), "--out", str(tmp_path / "out"), capsys=capsys)
        assert code == 0, err
        assert sorted(p.name for p in (tmp_path / "out").iterdir() if p.is_dir()) == ["m"]
        code, out, err = cli_main(
            "advise", "--results", str(results), "--error", "0.5", "--machine", "m", capsys=capsys
        )
        assert code == 0 and "pcabench run --solver linkedlist-cpu" in out, (out, err)
        monkeypatch.setattr(sweep_module, "machine_id", lambda: "m")
        monkeypatch.setattr(sweep_module, "host_id", lambda: "h")
        made = []

        def child(spec, timeout, commit, machine, stream=None):
            made.append(spec)
            return store.to_row(record(host="h"))

        sweep([RunSpec("linkedlist-cpu", Scene(dx=1.0, steps=2))], path, run_budget=60, sweep_budget=60, runner=child)
    assert len(made) == 1 and good["run_id"]


def test_a_newer_schema_last_line_is_kept_and_skipped_not_moved_out_as_torn(tmp_path):
    path = tmp_path / "s.jsonl"
    store.append(record(), path)
    newer = json.dumps(dict(good_row(), schema=schema.SCHEMA + 1, run_id="future", new_field={"a": 1}))
    with open(path, "a") as f:
        f.write(newer)  # a complete record of a newer pcabench, last, without its newline
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        store.append(record(), path)
    assert not any("torn" in str(w.message) for w in caught)
    assert not (tmp_path / "s.jsonl.torn").exists()
    assert newer in path.read_text().splitlines()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert len(store.read_rows(path)) == 2
    assert len(caught) == 1 and "newer" in str(caught[0].message)


def test_a_record_that_would_not_read_back_is_never_written(tmp_path):
    path = tmp_path / "s.jsonl"
    for bad in (
        {"solver": "name\nwith a newline"},
        {"commit": "abc\x1b"},
        {"profile_id": "README.md"},
        {"host": "h" * 300},
        {"dx": 1e308},
    ):
        with pytest.raises(store.InvalidRecord, match="would not read back"):
            store.append(dict(good_row(), **bad), path)
    assert not path.exists() or path.read_bytes() == b""


def test_a_sweep_stores_a_record_that_would_not_read_back_as_an_error(tmp_path, monkeypatch):
    path = tmp_path / "m--h.jsonl"
    monkeypatch.setattr(sweep_module, "machine_id", lambda: "m")
    monkeypatch.setattr(sweep_module, "host_id", lambda: "h")

    def forging_child(spec, timeout, commit, machine, stream=None):
        return dict(store.to_row(record(host="h")), solver="../../forged")

    stored = sweep(
        [RunSpec("linkedlist-cpu", Scene(dx=1.0, steps=2))], path, run_budget=60, sweep_budget=60, runner=forging_child
    )
    rows = store.read_rows(path)
    assert [r["status"] for r in stored] == ["error"] and [r["solver"] for r in rows] == ["linkedlist-cpu"]
    assert "would not read back" in rows[0]["message"] and "solver" in rows[0]["message"]


def test_the_schema_tolerates_a_named_scene_and_extra_plain_keys():
    row = good_row()
    row["scene"] = dict(
        row["scene"],
        name="acoustic-pulse",
        x_min=-20.0,
        x_max=20.0,
        y_min=-20.0,
        y_max=20.0,
        strip_height=None,
        tube_length=12.5,
        wall="rigid",
    )
    row["scene_name"] = "acoustic-pulse"
    row["scene_parameters"] = {"tube_length": 12.5, "wall": "rigid"}
    # the particle count of that scene (the reader checks it against it)
    n = Scene(**{k: v for k, v in row["scene"].items() if k in Scene.PARAMETERS}).n_particles
    row["n_particles"] = row["scene"]["n_particles"] = n
    assert store.validate(row) == ""
    # a scene this installation does not have (a plug-in's, from another machine): skipped, named
    assert "tube" in store.validate(dict(row, scene=dict(row["scene"], name="tube")))
    assert "scene_parameters" in store.validate(dict(row, scene_parameters={"deep": {"er": 1}}))
    row["scene"]["bad"] = {"nested": 1}
    assert "scene" in store.validate(row)


def test_environment_values_that_become_paths_are_checked_like_store_rows(monkeypatch, tmp_path, capsys):
    monkeypatch.setenv("PCABENCH_HOME", str(tmp_path / "home"))
    try:
        for value in ("../../x", "README.md", "a" * 300, "x\x1by"):
            profiles.machine_id.cache_clear()
            monkeypatch.setenv(profiles.MACHINE_ID_ENV, value)
            code, out, err = cli_main("profile", "--save", capsys=capsys)
            assert code == 2 and "PCABENCH_MACHINE_ID" in err, err
    finally:
        monkeypatch.delenv(profiles.MACHINE_ID_ENV)
        profiles.machine_id.cache_clear()
    assert sorted(p.name for p in tmp_path.rglob("*")) in ([], ["home"], ["hardware_profiles", "home"])
    provenance.git_commit.cache_clear()
    monkeypatch.setenv("PCABENCH_COMMIT", "abc\x1b[2J")
    try:
        with pytest.raises(store.StoreError, match="PCABENCH_COMMIT"):
            provenance.git_commit()
    finally:
        provenance.git_commit.cache_clear()


BAD_NAMES = """
from solvers.linkedlist_cpu import LinkedListCPU

class Newline(LinkedListCPU):
    name = "two\\nlines"

class Path(LinkedListCPU):
    name = "../../forged"
"""


def test_a_plugin_whose_name_would_not_read_back_is_left_out(tmp_path, monkeypatch):
    from solvers import registry
    from solvers.registry import SOLVERS

    from .test_registry import install

    site = install(
        tmp_path / "site",
        "badname_solver",
        BAD_NAMES,
        {"newline": "badname_solver:Newline", "path": "badname_solver:Path"},
    )
    monkeypatch.syspath_prepend(str(site))
    SOLVERS.cache_clear()
    try:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            found = registry()
    finally:
        SOLVERS.cache_clear()
        sys.modules.pop("badname_solver", None)
    assert "two\nlines" not in found and "../../forged" not in found
    assert sum("not a plain name" in str(w.message) for w in caught) == 2


# ---------------------------------------------------------------- the store folder's entries
def test_a_fifo_or_a_link_to_dev_zero_in_the_store_folder_is_skipped_with_a_warning(tmp_path, capsys):
    results = tmp_path / "results"
    store.append(record(), results / "m.jsonl")
    os.mkfifo(results / "fifo.jsonl")
    (results / "zero.jsonl").symlink_to("/dev/zero")
    (results / "elsewhere.jsonl").symlink_to(results / "m.jsonl")
    code = subprocess.run(
        [sys.executable, "-W", "always", "-m", "pcabench.cli", "runs", "--results", str(results)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert code.returncode == 0, code.stderr
    assert len(code.stdout.splitlines()) == 2
    for name in ("fifo.jsonl", "zero.jsonl", "elsewhere.jsonl"):
        assert name in code.stderr
    with pytest.raises(OSError, match="larger than"):
        store.read_regular(results / "m.jsonl", limit=10)
    with pytest.raises(store.StoreError, match="not a regular file"):  # a study on it: refused, not hung
        store.check_writable(results / "fifo.jsonl")


# ---------------------------------------------------------------- the child protocol
LOUD = """
import atexit, os, sys
from solvers.linkedlist_cpu import LinkedListCPU

_init = LinkedListCPU.init

def loud_init(self):
    print("hello from the solver")
    print('{"solver": "../../forged", "status": "ok"}', flush=True)
    os.write(2, b"a line on stderr\\n")
    return _init(self)

LinkedListCPU.init = loud_init
atexit.register(lambda: print('{"solver": "../../forged-at-exit", "status": "ok"}', flush=True))
"""


def test_a_solver_that_prints_cannot_break_the_child_protocol(tmp_path, monkeypatch):
    # sitecustomize is imported by every python started with it on the path: the child's solver prints at
    # init (a line, then a forged record) and at exit (another forged record)
    (tmp_path / "sitecustomize.py").write_text(LOUD)
    monkeypatch.setenv("PYTHONPATH", f"{tmp_path}{os.pathsep}{os.environ.get('PYTHONPATH', '')}")
    # a fresh interpreter: a forkserver started here, with this test's sitecustomize, would outlive the test
    monkeypatch.setenv("PCABENCH_FORKSERVER", "0")
    spec = RunSpec("linkedlist-cpu", Scene(dx=1.0, steps=2)).resolved()
    row = sweep_module.run_child(spec, 120, "abc", "m", stream=None)
    assert row["status"] == "ok" and row["solver"] == "linkedlist-cpu", row
    assert "hello from the solver" in row["message"] and "forged" in row["message"]  # kept, never parsed
    assert "a line on stderr" in row["message"] and "step " not in row["message"]
    assert store.validate(row) == ""


def test_run_json_prints_exactly_one_object_whatever_the_solver_prints(tmp_path, capsys, monkeypatch):
    from solvers.linkedlist_cpu import LinkedListCPU

    real_init = LinkedListCPU.init

    def loud_init(self):
        print("hello from the solver", flush=True)
        os.write(1, b'{"forged": 1}\n')
        return real_init(self)

    monkeypatch.setattr(LinkedListCPU, "init", loud_init)
    code = cli.main(["run", "--solver", "linkedlist-cpu", "--dx", "1", "--steps", "2", "--json", "--quiet"])
    out = capsys.readouterr().out
    assert code == 0
    lines = [line for line in out.splitlines() if line.strip()]
    assert len(lines) == 1 and json.loads(lines[0])["status"] == "ok", out


def test_run_takes_a_run_budget(capsys):
    code, out, err = cli_main(
        "run",
        "--solver",
        "linkedlist-cpu",
        "--dx",
        "0.05",
        "--steps",
        "100000",
        "--model",
        "linear",
        "--run-budget",
        "3",
        "--json",
        "--quiet",
        capsys=capsys,
    )
    assert code == 1 and json.loads(out)["status"] == "timeout", (out, err)
    code, out, err = cli_main("run", "--solver", "linkedlist-cpu", "--dx", "1", "--run-budget", "0", capsys=capsys)
    assert code == 2 and "--run-budget" in err


# ---------------------------------------------------------------- links
def test_a_profile_link_under_the_home_is_replaced_never_followed(tmp_path, monkeypatch):
    monkeypatch.setenv("PCABENCH_HOME", str(tmp_path / "home"))
    target = tmp_path / "precious.txt"
    target.write_text("mine")
    folder = tmp_path / "home" / "hardware_profiles"
    folder.mkdir(parents=True)
    (folder / "p1.json").symlink_to(target)
    profiles.save({"id": "p1", "source": "measured"})
    assert target.read_text() == "mine" and not (folder / "p1.json").is_symlink()
    with pytest.raises(store.StoreError):
        profiles.save({"id": "../../x"})


def _report_results(tmp_path):
    results = tmp_path / "results"
    store.append(record(), results / "m.jsonl")
    return results


def test_links_in_the_reports_folder_are_replaced_never_followed(tmp_path, capsys):
    results, out, outside = _report_results(tmp_path), tmp_path / "out", tmp_path / "outside"
    outside.mkdir()
    for name in ("README.md", "a.png", "keep.png"):
        (outside / name).write_text("mine")
    out.mkdir()
    (out / "README.md").symlink_to(outside / "README.md")
    code, _, err = cli_main("report", "--results", str(results), "--out", str(out), capsys=capsys)
    assert code == 0, err
    pngs = sorted(p.name for p in (out / "m").glob("*.png"))
    assert pngs
    shutil_rm = [out / "m" / pngs[0], out / "cards.md"]
    for p in shutil_rm:
        p.unlink()
        p.symlink_to(outside / "a.png")
    code, _, err = cli_main("report", "--results", str(results), "--out", str(out), capsys=capsys)
    assert code == 0, err
    assert all((outside / n).read_text() == "mine" for n in ("README.md", "a.png", "keep.png"))
    assert not any(p.is_symlink() for p in out.rglob("*"))


def test_a_machine_folder_link_to_another_folder_is_refused_and_nothing_there_deleted(tmp_path, capsys):
    results, out, outside = _report_results(tmp_path), tmp_path / "out", tmp_path / "outside"
    outside.mkdir()
    (outside / "keep.png").write_text("mine")
    out.mkdir()
    (out / "m").symlink_to(outside)
    code, _, err = cli_main("report", "--results", str(results), "--out", str(out), capsys=capsys)
    assert code == 2 and "symbolic link" in err and str(out / "m") in err, err
    assert (outside / "keep.png").read_text() == "mine"


def test_gpu_check_out_link_is_refused(tmp_path, capsys):
    outside = tmp_path / "outside"
    outside.mkdir()
    (tmp_path / "out").symlink_to(outside)
    code, _, err = cli_main(
        "gpu-check",
        "--out",
        str(tmp_path / "out"),
        "--results",
        str(tmp_path / "r"),
        "--reports",
        str(tmp_path / "rep"),
        capsys=capsys,
    )
    assert code == 2 and "symbolic link" in err, err
    assert list(outside.iterdir()) == []


def test_gpu_check_writes_files_in_its_folder_without_following_links(tmp_path):
    from pcabench.store.safeio import write_file  # what the GPU check writes with

    out, target = tmp_path / "out", tmp_path / "precious.txt"
    out.mkdir()
    target.write_text("mine")
    (out / "gpu_check.md").symlink_to(target)
    write_file(out / "gpu_check.md", "table\n")
    assert target.read_text() == "mine" and (out / "gpu_check.md").read_text() == "table\n"


# ---------------------------------------------------------------- commands to paste
def test_advise_quotes_every_command_for_the_shell():
    from pcabench.commands import line_of, words_of

    line = line_of(*words_of("x; touch /tmp/pwned", Scene(dx=0.5, t_end=10.0), 1, "gather $(id)"))
    words = shlex.split(line)
    assert words[:4] == ["pcabench", "run", "--solver", "x; touch /tmp/pwned"]
    assert words[-2:] == ["--pair-loop", "gather $(id)"]


# ---------------------------------------------------------------- a full disk
def test_a_full_disk_during_report_names_the_path_and_leaves_no_partial_file(tmp_path, capsys, monkeypatch):
    from matplotlib.figure import Figure

    from pcabench.store import safeio

    results, out = _report_results(tmp_path), tmp_path / "out"

    def full_figure(self, fname, *args, **kwargs):  # the disk fills while a figure is written: half a png
        with open(fname, "wb") as f:
            f.write(b"\x89PNG half")
        raise OSError(errno.ENOSPC, "No space left on device")

    with monkeypatch.context() as m:
        m.setattr(Figure, "savefig", full_figure)
        code, _, err = cli_main("report", "--results", str(results), "--out", str(out), capsys=capsys)
    assert code == 2 and "No space left on device" in err and str(out / "m") in err and ".png" in err, err
    assert [p for p in out.rglob("*") if p.is_file()] == []  # no 0-byte or half png, no temporary file

    real = safeio._write_all

    def full_text(fd, data):  # the disk fills while a page is written
        real(fd, data[: len(data) // 2])
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(safeio, "_write_all", full_text)
    code, _, err = cli_main("report", "--results", str(results), "--out", str(out), capsys=capsys)
    assert code == 2 and "No space left on device" in err and str(out / "m") in err, err  # a figure's CSV first
    assert sorted({p.suffix for p in out.rglob("*") if p.is_file()}) == [".png"]  # whole figures, no data, no page


# ---------------------------------------------------------------- issue 57: answers that keep one meaning
def test_a_full_disk_is_its_own_exit_code_not_bad_input(tmp_path, monkeypatch, capsys):
    """Less free space than a sweep's records need: one line and exit 5 (the machine's state), never 2 (bad
    input), before any run."""
    import shutil

    real = shutil.disk_usage
    monkeypatch.setattr(shutil, "disk_usage", lambda p: real(p)._replace(free=1000))
    code, out, err = cli_main(
        "study", "--dx", "1", "--steps", "2", "--no-report", "--results", str(tmp_path), capsys=capsys
    )
    assert code == 5 and "bytes free" in err and "Traceback" not in err, err
    assert not store.read_rows(tmp_path)  # no run made


@pytest.mark.parametrize(
    "words, says",
    [
        (["--absorber", "pml"], "--absorber: the scene's edges are closed (add --open x, y or xy)"),
        (["--layer-width", "3"], "--layer-width: the scene's edges are closed"),
        (["--absorber-strength", "2"], "--absorber-strength: the scene's edges are closed"),
    ],
)
def test_the_layers_options_without_open_edges_are_refused(words, says, capsys):
    code, out, err = cli_main("run", "--solver", "linkedlist-cpu", "--dx", "1", "--steps", "2", *words, capsys=capsys)
    assert code == 2 and says in err and "Traceback" not in err, err


def test_a_probe_is_checked_against_the_scene_that_runs(capsys):
    """On the paper's domain [-10, 40] m a probe at x = 15 is inside (the warm-up's small scene is not the
    run's); with a run budget too; the accuracy command refuses a probe in the body as run does."""
    base = ["run", "--solver", "linkedlist-cpu", "--dx", "1", "--steps", "2", "--quiet", "--probe", "15,0"]
    for extra in ([], ["--run-budget", "60"]):
        code, out, err = cli_main(*base, *extra, capsys=capsys)
        assert code == 0 and "Traceback" not in err and "status           ok" in out, (extra, err)
    code, out, err = cli_main("accuracy", "--scene", "cylinder", "--dx", "0.05", "--probe", "0,0", capsys=capsys)
    assert code == 2 and "--probe 0,0 is inside the body" in err, err


@pytest.mark.parametrize("delay", [0.05, 0.2, 0.6])
def test_a_sigterm_from_the_first_instant_is_terminated_not_interrupted(tmp_path, delay):
    import signal
    import time

    proc = subprocess.Popen(
        [sys.executable, "-m", "pcabench.console", "study", "--dx", "1", "--steps", "2", "--no-report"]
        + ["--results", str(tmp_path)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    time.sleep(delay)
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=120)
    if proc.returncode == 0:
        pytest.skip("the study finished before the signal")
    if proc.returncode == -signal.SIGTERM:  # before Python ran a line of ours: killed by it, as a shell shows 143
        assert err == "", err
        return
    assert proc.returncode == 143 and "terminated" in err and "Traceback" not in err, (proc.returncode, err)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="/proc")
def test_a_sweeps_forkserver_ignores_the_terminals_ctrl_c_from_its_start(tmp_path):
    """A terminal's Ctrl-C goes to the whole foreground group: the sweep answers it, and its server (which
    printed a 25-47 line traceback when hit while importing) has SIGINT ignored from its first instant."""
    import signal
    import time

    from pcabench.execute import containment

    # runs of seconds each (2.5 to 30 s), so that one is surely under way when the Ctrl-C comes
    proc = study_process(tmp_path, "--dx", "1", "0.5", "0.25", "--steps", "3000", "--model", "linear")
    try:
        ignored, deadline = None, time.time() + 120
        while ignored is None and time.time() < deadline and proc.poll() is None:
            for pid in containment.children(proc.pid):  # the server with a run under way (the sweep ignores
                try:  # SIGINT only while it spawns its server): its signal mask, read while it lives
                    with open(f"/proc/{pid}/cmdline", "rb") as f:
                        if b"forkserver" not in f.read() or not run_children(pid):
                            continue
                    with open(f"/proc/{pid}/status") as f:
                        ignored = int(next(line for line in f if line.startswith("SigIgn:")).split()[1], 16)
                    break
                except OSError:  # a process that ended between the listing and the read: look again
                    continue
            time.sleep(0.02)
        assert ignored is not None, f"no forkserver with a run under way seen (sweep exit {proc.poll()})"
        assert ignored & (1 << (signal.SIGINT - 1)), f"the server takes SIGINT (SigIgn {ignored:x})"
        os.killpg(proc.pid, signal.SIGINT)  # the terminal's Ctrl-C: the whole group
        _, err = proc.communicate(timeout=120)
        assert proc.returncode == 130 and "Traceback" not in err, err
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, 9)


def test_ctrl_c_during_a_run_ends_its_progress_line_first():
    """The interrupt line starts a line of its own, not the end of the progress line it cut."""
    import signal
    import threading
    import time

    proc = subprocess.Popen(
        [sys.executable, "-m", "pcabench.console", "run", "--solver", "linkedlist-cpu", "--dx", "0.25"]
        + ["--steps", "1000000", "--model", "linear"],  # steps of milliseconds: the interrupt is seen at once
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        start_new_session=True,
        preexec_fn=default_sigint,  # as a terminal starts it
    )
    err = bytearray()

    def read():
        for chunk in iter(lambda: os.read(proc.stderr.fileno(), 4096), b""):
            err.extend(chunk)

    reader = threading.Thread(target=read, daemon=True)
    reader.start()
    try:
        deadline = time.time() + 240
        while b": step " not in err and time.time() < deadline:
            time.sleep(0.1)
        assert b": step " in err, bytes(err)
        proc.send_signal(signal.SIGINT)
        proc.wait(timeout=60)
        reader.join(timeout=10)
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, 9)
    assert proc.returncode == 130 and bytes(err).endswith(b"\npcabench run: interrupted\n"), bytes(err[-300:])
    assert b" \rpcabench run" not in err and b"s pcabench run" not in err


def test_gpu_check_names_a_missing_tool_before_any_stage(tmp_path, monkeypatch, capsys):
    """Without the bench extra (no asv) the check is one line at once, not a failed asv stage 290 s in."""
    import importlib.util

    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name == "asv" else real(name, *a))
    code, out, err = cli_main("gpu-check", "--rehearse", "--out", str(tmp_path / "out"), capsys=capsys)
    assert code == 2 and "gpu-check needs asv (its 'asv' stage; pip install -e '.[bench]')" in err, err
    assert not list((tmp_path / "out").iterdir())  # nothing run, nothing written


# ---------------------------------------------------------------- issue 59: answers that name the right thing
def test_an_open_runs_error_once_the_pulse_has_left_is_undefined_not_1e26():
    """A relative error against a reference that holds no pulse (its tail: 1e-60) is undefined (null), not
    2.78e26; the measures that mean something then (left, reflected) are there."""
    from pcabench.execute.run import run

    scene = Scene(dx=0.25, strip_height=5.0, open="x", model="linear", t_end=64.0)
    record = run(RunSpec("linkedlist-cpu", scene))
    assert record.status == "ok" and record.mse != record.mse, record.mse  # NaN: stored as null
    assert 0 < record.errors["left_amplitude"] < 0.05 and "reflected_amplitude" in record.errors
    text = record.text(scene)
    assert "MSE (rel. RMS)   - (undefined" in text and "reflected amplitude 0.00" in text, text


@pytest.mark.parametrize(
    "words, says",
    [
        (["runs", "--reference", "--status", "fine"], "--status 'fine' is none of ok, unstable"),
        (["runs", "--reference", "--machine", "nosuch"], "--machine 'nosuch' is no machine of"),
        (["runs", "--reference", "--scene", "nosuch"], "--scene 'nosuch' is none of plane-pulse"),
        (["runs", "--reference", "--results", "/tmp"], "--reference and --results each name a results folder"),
        (["advise", "--reference", "--results", "/tmp", "--error", "0.05"], "--reference and --results each"),
        (["study", "--qiuck"], "pcabench study: error: unrecognized arguments: --qiuck (see pcabench study --help)"),
        (
            ["run", "--solver", "linkedlist-cpu", "--scene", "cylinder", "--dx", "2"],
            "--dx 2 with --cylinder-radius 0.5: the cutoff (12.8 m = 6.39 dx: --h-factor, --cutoff) about the",
        ),
        (
            ["run", "--solver", "linkedlist-cpu", "--dx", "0.5", "--cfl", "50"],
            "--steps 100 x dt (--cfl 50 x --dx 0.5 / c0) = 2500 s: the run passes",
        ),
        (["run", "--solver", "linkedlist-cpu", "--dx", "1", "--results", "/tmp"], "give --store too"),
    ],
)
def test_a_refusal_names_what_the_user_gave(words, says, capsys):
    code, out, err = cli_main(*words, capsys=capsys)
    assert code == 2 and says in err and "Traceback" not in err, err
    assert not out  # refused before anything was printed


def test_a_bad_cluster_address_is_refused_before_the_studys_header(tmp_path, capsys):
    code, out, err = cli_main(
        "study", "--cluster", "foo:bar", "--dx", "1", "--steps", "2", "--results", str(tmp_path), capsys=capsys
    )
    assert code == 2 and "--cluster must be a scheduler address" in err and "runs on the Dask cluster" not in err


def test_run_keeps_its_fields_in_a_folder_and_its_record_in_the_store_and_says_where(tmp_path, capsys):
    folder, results = tmp_path / "fields", tmp_path / "results"
    folder.mkdir()
    code, out, err = cli_main(
        "run", "--solver", "linkedlist-cpu", "--dx", "1", "--steps", "3", "--quiet", "--fields", str(folder),
        "--store", "--results", str(results), capsys=capsys,
    )  # fmt: skip
    (npz,) = folder.glob("*.npz")
    assert code == 0 and f"fields           {npz}" in out and "record           " in out, out
    assert not (tmp_path / "fields.npz").exists()  # not beside the folder
    (row,) = store.read_rows(results)
    assert row["status"] == "ok" and row["solver"] == "linkedlist-cpu"
    code, out, err = cli_main("runs", "--results", str(results), capsys=capsys)
    assert code == 0 and "linkedlist-cpu" in out  # runs sees it
