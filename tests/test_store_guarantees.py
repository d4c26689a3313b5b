"""The store's guarantees, each probe of a demanding user: torn tails, two writers, killed parents,
unwritable and full stores, corrupt rows, killed children, retries, and the memory actually available."""

from __future__ import annotations

import errno
import json
import os
import signal
import subprocess
import sys
import time
import warnings
from pathlib import Path

import pytest

from pcabench import cli, store
from pcabench.cli import study
from pcabench.execute import sweep as sweep_module
from pcabench.execute.sweep import exit_status, sweep
from pcabench.machine import memory
from pcabench.machine.profiles import machine_id
from pcabench.spec import RunSpec
from pcabench.store.record import RunRecord
from solvers import Scene, SceneError
from tests.conftest import run_children


def record(dx=1.0, status="ok", **kw):
    rec = RunRecord.from_spec(RunSpec("linkedlist-cpu", Scene(dx=dx, steps=3)).resolved(), "m", status=status)
    rec.steps, rec.mse, rec.me = 3, 0.1, 0.001
    rec.stages.update(snp=0.001, pi=0.01, su=0.0005)
    for k, v in kw.items():
        setattr(rec, k, v)
    return rec


def rows_quietly(path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", store.StoreWarning)
        return store.read_rows(path)


# ---------------------------------------------------------------- torn tails and full disks
def test_a_torn_tail_never_takes_the_next_record_with_it(tmp_path):
    path = tmp_path / "s.jsonl"
    store.append(record(dx=1.0), path)
    with open(path, "a") as f:
        f.write('{"solver": "linkedlist-cpu", "sta')  # a crash mid-write: no newline
    with pytest.warns(store.StoreWarning, match="torn"):
        store.append(record(dx=0.5), path)
    assert [r["dx"] for r in store.read_rows(path)] == [1.0, 0.5]  # the next record is whole
    assert '"sta' in (tmp_path / "s.jsonl.torn").read_text()  # the torn bytes are kept, not lost


def test_a_full_disk_leaves_no_torn_line(tmp_path, monkeypatch):
    path = tmp_path / "s.jsonl"
    store.append(record(dx=1.0), path)
    real_fsync = os.fsync

    def full(fd):  # the write reached the file, the disk filled before it was safe
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "fsync", full)
    with pytest.raises(store.StoreError, match="disk is full"):
        store.append(record(dx=0.5), path)
    monkeypatch.setattr(os, "fsync", real_fsync)
    assert path.read_text().endswith("\n") and len(store.read_rows(path)) == 1


def test_an_unwritable_store_is_refused_before_any_run(tmp_path, capsys):
    locked = tmp_path / "ro"
    locked.mkdir()
    locked.chmod(0o500)
    try:
        if os.access(locked, os.W_OK):
            pytest.skip("running as a user who can write anywhere (root)")
        with pytest.raises(SystemExit) as exc:
            cli.main(["study", "--dx", "1", "--steps", "2", "--results", str(locked / "x"), "--no-report"])
        err = capsys.readouterr().err
        assert exc.value.code == 2 and str(locked) in err and "Traceback" not in err
        assert len(err.strip().splitlines()) == 1
    finally:
        locked.chmod(0o700)


def test_a_store_path_that_cannot_exist_is_refused_before_any_run(tmp_path, capsys):
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    t0 = time.perf_counter()
    with pytest.raises(SystemExit) as exc:
        cli.main(["study", "--dx", "1", "--steps", "2", "--results", str(blocker / "x"), "--no-report"])
    err = capsys.readouterr().err
    assert exc.value.code == 2 and "not writable" in err and str(blocker) in err
    assert time.perf_counter() - t0 < 5  # refused before any run was made


# ---------------------------------------------------------------- corrupt rows
def test_corrupt_rows_are_skipped_one_warning_each_naming_file_and_line(tmp_path):
    path = tmp_path / "s.jsonl"
    good = store.append(record(), path)
    with open(path, "ab") as f:
        f.write(b"\xff\xfe not utf-8\n")
        f.write(b"null\n")
        f.write(b"[1, 2]\n")
        f.write(b'{"solver": "linkedlist-cpu"}\n')  # missing keys
        f.write(b"\n")
        f.write(json.dumps(dict(good, schema=store.SCHEMA + 1, run_id="future")).encode() + b"\n")
        f.write(b"garbage\n")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rows = store.read_rows(path)
    assert [r["run_id"] for r in rows] == [good["run_id"]]
    messages = [str(w.message) for w in caught if issubclass(w.category, store.StoreWarning)]
    assert len(messages) == 7
    assert all(str(path) in m for m in messages)
    assert [m.split(":")[1] for m in messages] == ["2", "3", "4", "5", "6", "7", "8"]
    assert any("newer pcabench" in m for m in messages) and any("UTF-8" in m for m in messages)


def test_reports_and_runs_survive_corrupt_rows(tmp_path, capsys):
    results = tmp_path / "results"
    path = results / "m.jsonl"
    store.append(record(), path)
    with open(path, "ab") as f:
        f.write(b'null\n{"solver": 3}\n')
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", store.StoreWarning)
        assert cli.main(["report", "--results", str(results), "--out", str(tmp_path / "out")]) == 0
    assert (tmp_path / "out" / "README.md").exists()


# ---------------------------------------------------------------- two writers and killed parents
def _study(results, *args):
    return subprocess.Popen(
        [
            sys.executable,
            "-m",
            "pcabench.cli",
            "study",
            "--dx",
            "1",
            "0.5",
            "--steps",
            "3",
            "--no-report",
            "--results",
            str(results),
            *args,
        ],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )


def test_two_sweeps_on_one_store_never_duplicate(tmp_path):
    first = _study(tmp_path, "--steps", "2000", "--model", "linear")  # a few seconds: longer than the second's start
    deadline = time.time() + 120
    while time.time() < deadline and not list(tmp_path.glob("*.lock")):
        time.sleep(0.05)
    second = _study(tmp_path, "--steps", "2000", "--model", "linear")
    _, err2 = second.communicate(timeout=300)
    _, err1 = first.communicate(timeout=300)
    assert first.returncode == 0, err1
    assert second.returncode == 2 and "in use by another sweep" in err2 and "Traceback" not in err2
    rows = rows_quietly(next(tmp_path.glob("*.jsonl")))
    assert len(rows) == 2 and len({(r["dx"], r["solver"]) for r in rows}) == 2


def test_a_killed_parent_takes_its_running_child_with_it(tmp_path):
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "pcabench.cli",
            "study",
            "--dx",
            "0.25",
            "--steps",
            "100000",
            "--model",
            "linear",  # (a lagrangian run this long would pass the pulse's breaking time)
            "--no-report",
            "--results",
            str(tmp_path),
        ],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
    )
    child = None
    deadline = time.time() + 120
    while time.time() < deadline and child is None:
        found = run_children(proc.pid)
        child = found[0] if found else None
        time.sleep(0.1)
    assert child is not None, "the sweep never started its child"
    os.kill(proc.pid, signal.SIGKILL)  # the parent only, as kill -9 <pid> does
    proc.wait()
    deadline = time.time() + 10
    while time.time() < deadline and os.path.exists(f"/proc/{child}"):
        time.sleep(0.05)
    gone = not os.path.exists(f"/proc/{child}") or open(f"/proc/{child}/stat").read().split()[2] == "Z"
    assert gone, "the child outlived its killed parent"
    assert rows_quietly(next(tmp_path.glob("*.jsonl"))) == []  # the unfinished run is not stored


# ---------------------------------------------------------------- failed children and retries
def test_a_killed_child_names_its_signal_and_oom_only_when_it_was():
    assert exit_status(-signal.SIGKILL, 0, 0) == ("error", "killed by SIGKILL")
    assert exit_status(-signal.SIGKILL, 3, 4)[0] == "out-of-memory"
    assert exit_status(-signal.SIGTERM, None, None) == ("error", "killed by SIGTERM")
    assert exit_status(-signal.SIGSEGV, None, None) == ("error", "killed by SIGSEGV")
    assert exit_status(3, None, None) == ("error", "exit code 3")


def fake_child(made: list):
    """A run child that runs nothing: it notes the spec in ``made`` and returns an ok record of 2 steps."""

    def child(spec, timeout, commit, machine, stream=None):
        made.append(spec)
        rec = sweep_module.failed_record(spec, "ok", "", machine)
        rec.steps = 2
        return store.to_row(rec)

    return child


def test_retry_failed_runs_timeouts_skips_and_errors_again(tmp_path, monkeypatch):
    path = tmp_path / "s.jsonl"
    spec = RunSpec("linkedlist-cpu", Scene(dx=1.0, steps=2)).resolved()
    made = []
    monkeypatch.setattr(sweep_module, "run_child", fake_child(made))
    store.append(sweep_module.failed_record(spec, "timeout", "past the run budget", machine_id()), path)
    sweep([spec], path, run_budget=60, sweep_budget=60)
    assert made == []  # stored (as a timeout): a plain rerun skips it
    sweep([spec], path, run_budget=60, sweep_budget=60, retry_failed=True)
    assert len(made) == 1 and [r["status"] for r in store.read_rows(path)] == ["timeout", "ok"]
    sweep([spec], path, run_budget=60, sweep_budget=60, retry_failed=True)
    assert len(made) == 1  # an ok run is never rerun


# ---------------------------------------------------------------- memory and numeric options
def fake_cgroups(tmp_path, monkeypatch, proc_cgroup: str, files: dict) -> None:
    """A cgroup mount under tmp_path: ``proc_cgroup`` is this process's /proc/self/cgroup, ``files`` maps
    a path under the mount to its text."""
    (tmp_path / "proc_cgroup").write_text(proc_cgroup)
    for rel, text in files.items():
        (tmp_path / "cg" / rel).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / "cg" / rel).write_text(text)
    monkeypatch.setattr(memory, "CGROUP_MOUNT", str(tmp_path / "cg"))
    monkeypatch.setattr(memory, "PROC_CGROUP", str(tmp_path / "proc_cgroup"))


def test_the_memory_check_uses_the_cgroup_limit(tmp_path, monkeypatch):
    fake_cgroups(tmp_path, monkeypatch, "0::/\n", {"memory.max": f"{1 << 30}\n", "memory.current": f"{256 << 20}\n"})
    limit = tmp_path / "cg" / "memory.max"
    assert memory.available_memory_bytes() == (1 << 30) - (256 << 20)
    with pytest.raises(SceneError, match="smallest dx that fits"):
        memory.bounded(Scene(dx=0.01))  # 10M particles: about 2.4 GB of arrays, more than the 0.75 GiB left
    limit.write_text("max\n")
    assert memory.available_memory_bytes() > (1 << 30)  # no limit: the host's available memory


@pytest.mark.parametrize(
    "command,args,words",
    [
        ("run", ["--solver", "linkedlist-cpu", "--dx", "1e-300"], ["dx", "smallest dx that fits"]),
        ("study", ["--dx", "1e-300"], ["dx", "smallest dx that fits"]),
        ("run", ["--solver", "linkedlist-cpu", "--dx", "1", "--t-end", "0"], ["--t-end", "> 0"]),
        ("study", ["--dx", "1", "--t-end", "0"], ["--t-end", "> 0"]),
        ("study", ["--dx", "1", "--t-end", "1e300"], ["--t-end", "1e7 steps"]),
        ("study", ["--dx", "1", "--cfl", "1e-300", "--t-end", "1"], ["--cfl", "[0.001, 50]"]),
        ("study", ["--quick", "--sweep-budget", "-1"], ["--sweep-budget", "> 0"]),
    ],
)
def test_numeric_options_refuse_meaningless_values_in_run_and_study(command, args, words, capsys, tmp_path):
    extra = ["--results", str(tmp_path)] if command == "study" else []
    with pytest.raises(SystemExit) as exc:
        cli.main([command, *args, *extra])
    err = capsys.readouterr().err
    assert exc.value.code == 2 and "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    assert all(w in err for w in words), err
    assert not list(tmp_path.glob("*.jsonl"))


# ---------------------------------------------------------------- hostile input (issue 21)
def test_a_last_record_without_its_newline_is_kept_not_moved_to_torn(tmp_path):
    path = tmp_path / "s.jsonl"
    store.append(record(dx=1.0), path)
    store.append(record(dx=0.5), path)
    with open(path, "r+b") as f:  # `truncate -s -1`: the last record loses its newline only
        f.truncate(path.stat().st_size - 1)
    with warnings.catch_warnings():
        warnings.simplefilter("error", store.StoreWarning)
        store.append(record(dx=0.4), path)
    assert [r["dx"] for r in store.read_rows(path)] == [1.0, 0.5, 0.4]
    assert not (tmp_path / "s.jsonl.torn").exists()


def test_a_write_cut_short_by_a_full_file_system_leaves_the_store_as_it_was(tmp_path):
    """A real short write: the kernel stops the line at RLIMIT_FSIZE (EFBIG, as ENOSPC would)."""
    path = tmp_path / "s.jsonl"
    store.append(record(dx=1.0), path)
    before = path.read_bytes()
    script = f"""
import resource, signal, sys
from pcabench import store
from pcabench.store.record import RunRecord
from pcabench.spec import RunSpec
from solvers import Scene
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
rec = RunRecord.from_spec(RunSpec("linkedlist-cpu", Scene(dx=0.5, steps=3)).resolved(), "m")
resource.setrlimit(resource.RLIMIT_FSIZE, ({len(before) + 100}, resource.RLIM_INFINITY))
try:
    store.append(rec, {str(path)!r})
except store.StoreError as exc:
    sys.exit(str(exc))
"""
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 1 and "disk is full; the record was not stored" in proc.stderr, proc.stderr
    assert path.read_bytes() == before  # no partial line


def test_a_full_disk_stores_the_run_in_the_reserve_and_stops_the_sweep(tmp_path, monkeypatch):
    path = tmp_path / "s.jsonl"
    specs = [RunSpec("linkedlist-cpu", Scene(dx=dx, steps=2)) for dx in (1.0, 0.5)]
    real_write, full = os.write, []

    def filling(fd, data):  # the disk fills during the store's first write: half the line, then ENOSPC
        if os.readlink(f"/proc/self/fd/{fd}") == str(path) and (tmp_path / "s.jsonl.reserve").exists():
            full.append(real_write(fd, data[: len(data) // 2]))
            raise OSError(errno.ENOSPC, "No space left on device")
        return real_write(fd, data)

    def filling_child(spec, timeout, commit, machine, stream=None):
        monkeypatch.setattr(os, "write", filling)
        return fake_child([])(spec, timeout, commit, machine, stream)

    with pytest.raises(store.StoreError, match="was stored in the space kept for it"):
        sweep(specs, path, run_budget=60, sweep_budget=60, runner=filling_child)
    monkeypatch.setattr(os, "write", real_write)
    assert full and path.read_bytes().endswith(b"\n")
    assert [r["dx"] for r in store.read_rows(path)] == [1.0]  # the run that met the full disk is stored


def test_a_report_writes_nothing_outside_its_folder_whatever_the_store_holds(tmp_path, capsys):
    results, out, outside = tmp_path / "results", tmp_path / "deep" / "out", tmp_path / "outside"
    outside.mkdir()
    (outside / "report.md").write_text("mine")
    (outside / "keep.png").write_bytes(b"png")
    good = store.append(record(), results / "m.jsonl")
    with open(results / "m.jsonl", "a") as f:
        for pid, host in (("../../outside", ""), (str(outside), ""), ("m", "../../../outside"), ("..", "")):
            f.write(json.dumps(dict(good, profile_id=pid, host=host, run_id=pid + host)) + "\n")
    with pytest.warns(store.StoreWarning, match="profile_id|host"):
        assert cli.main(["report", "--results", str(results), "--out", str(out)]) == 0
    assert (outside / "report.md").read_text() == "mine" and (outside / "keep.png").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["deep", "outside", "results"]
    with pytest.raises(store.StoreError, match="not a safe name"):
        store.store_name("../x", "h")


def test_nothing_is_written_through_a_symlink_in_the_results_folder(tmp_path):
    target = tmp_path / "precious.txt"
    target.write_text("line one\nline two")
    results = tmp_path / "results"
    results.mkdir()
    path = results / "s.jsonl"
    (results / "s.jsonl.lock").symlink_to(target)
    with pytest.raises(store.StoreError, match="symbolic link"):
        with store.SweepLock(path):
            pass
    path.symlink_to(target)
    with pytest.raises(store.StoreError, match="symbolic link"):
        store.append(record(), path)
    with pytest.raises(store.StoreError, match="symbolic link"):
        store.check_writable(path)
    assert target.read_text() == "line one\nline two"


ODD_ROWS = {
    "threads 'x'": {"threads": "x"},
    "steps 10**400": {"steps": 10**400},
    "stage 1e300": {"stages": {"input": 0, "init": 0, "snp": 1e300, "pi": 0.1, "su": 0.1, "output": 0}},
    "NaN": {"mse": float("nan")},
    "Infinity": {"dx": float("inf")},
    "scene {}": {"scene": {}},
    "steps -5": {"steps": -5},
    "empty profile_id": {"profile_id": ""},
    "control characters": {"status": "ok\x1b[2J\x1b[31m"},
    "unknown status": {"status": "fine"},
    "schema '2'": {"schema": "2"},
}


@pytest.mark.parametrize("name", ODD_ROWS)
def test_an_odd_but_schema_typed_row_is_skipped_with_one_warning(name, tmp_path):
    path = tmp_path / "s.jsonl"
    good = store.append(record(), path)
    with open(path, "a") as f:
        f.write(json.dumps(dict(good, run_id="odd", **ODD_ROWS[name])) + "\n")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        rows = store.read_rows(path)
    assert [r["run_id"] for r in rows] == [good["run_id"]]
    messages = [str(w.message) for w in caught]
    assert len(messages) == 1 and f"{path}:2:" in messages[0], messages
    if name == "schema '2'":
        assert "newer" not in messages[0] and "integer" in messages[0]


def test_study_report_and_runs_survive_every_odd_row_at_once(tmp_path, capsys, monkeypatch):
    results = tmp_path / "results"
    path = results / "m.jsonl"
    good = store.append(record(), path)
    with open(path, "a") as f:
        for name, change in ODD_ROWS.items():
            f.write(json.dumps(dict(good, run_id=name, **change)) + "\n")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", store.StoreWarning)
        assert cli.main(["runs", "--results", str(results)]) == 0
        out = capsys.readouterr().out
        assert "\x1b" not in out and len(out.splitlines()) == 2  # the header and the good row
        assert cli.main(["report", "--results", str(results), "--out", str(tmp_path / "out")]) == 0
        spec = RunSpec("linkedlist-cpu", Scene(dx=1.0, steps=2))
        monkeypatch.setattr(sweep_module, "machine_id", lambda: good["profile_id"])
        monkeypatch.setattr(sweep_module, "host_id", lambda: good["host"])
        made = []

        sweep([spec], path, run_budget=60, sweep_budget=60, runner=fake_child(made))  # reads them all to predict
    assert len(made) == 1


def test_a_run_given_twice_is_run_and_stored_once(tmp_path):
    made = []
    spec = RunSpec("linkedlist-cpu", Scene(dx=1.0, steps=2))
    sweep([spec, spec], tmp_path / "s.jsonl", run_budget=60, sweep_budget=60, runner=fake_child(made))
    assert len(made) == 1 and len(store.read_rows(tmp_path / "s.jsonl")) == 1


# ---------------------------------------------------------------- locks before any work, every executor
def test_a_cluster_sweep_locks_its_results_folder_before_any_work(tmp_path, monkeypatch):
    from pcabench.execute import cluster

    def no_work(*args, **kw):
        raise AssertionError("the cluster sweep started work without the lock")

    monkeypatch.setattr(cluster, "connect", no_work)
    monkeypatch.setattr(store, "read_rows", no_work)
    spec = RunSpec("linkedlist-cpu", Scene(dx=1.0, steps=2))
    with store.SweepLock(tmp_path / "m--h.jsonl"):  # a plain sweep runs on one store of the folder
        with pytest.raises(store.StoreError, match="in use by another sweep"):
            cluster.cluster_sweep([spec], tmp_path, 60, "local:1")
    with store.SweepLock(tmp_path, whole_folder=True):  # a cluster sweep holds the folder
        with pytest.raises(store.StoreError, match="in use by another sweep"):
            sweep([spec], tmp_path / "m--h.jsonl", run_budget=60, sweep_budget=60, runner=no_work)


# ---------------------------------------------------------------- memory: nested cgroups and the pair list
def test_the_memory_check_sees_a_nested_cgroup_v1_limit_and_its_oom_kills(tmp_path, monkeypatch):
    unlimited = "9223372036854771712\n"
    fake_cgroups(
        tmp_path,
        monkeypatch,
        "5:memory:/jobs/small\n0::/\n",
        {
            "memory/memory.limit_in_bytes": unlimited,
            "memory/memory.usage_in_bytes": "0\n",
            "memory/jobs/memory.limit_in_bytes": unlimited,
            "memory/jobs/memory.usage_in_bytes": "0\n",
            "memory/jobs/small/memory.limit_in_bytes": f"{512 << 20}\n",
            "memory/jobs/small/memory.usage_in_bytes": f"{12 << 20}\n",
            "memory/jobs/small/memory.oom_control": "oom_kill_disable 0\nunder_oom 0\noom_kill 2\n",
        },
    )
    assert memory.available_memory_bytes() == 500 << 20
    with pytest.raises(SceneError, match="smallest dx that fits"):
        memory.bounded(Scene(dx=0.02))  # 2.5M particles, about 0.56 GiB of arrays: more than the 0.49 GiB left
    assert sweep_module.oom_kills() == 2  # so a kill by the nested limit is out-of-memory, not error


def test_pair_loop_list_is_checked_against_the_memory_available(monkeypatch, capsys):
    from solvers.search.pairlist import list_bytes

    scene = Scene(dx=0.1, steps=2)
    monkeypatch.setattr(memory, "available_memory_bytes", lambda: scene.memory_bytes() + list_bytes(scene) // 2)
    with pytest.raises(SystemExit) as exc:
        cli.main(["run", "--solver", "linkedlist-cpu", "--dx", "0.1", "--steps", "2", "--pair-loop", "list"])
    err = capsys.readouterr().err
    assert exc.value.code == 2 and "pair list" in err and "--pair-loop gather" in err, err
    assert len(err.strip().splitlines()) == 1
    assert study.check_specs([RunSpec("linkedlist-cpu", scene)])[0].pair_loop == "gather"  # auto falls back


# ---------------------------------------------------------------- one line, never a traceback
def one_line_error(capsys, *argv, seconds=5.0):
    t0 = time.perf_counter()
    with pytest.raises(SystemExit) as exc:
        cli.main(list(argv))
    err = capsys.readouterr().err
    assert exc.value.code == 2 and "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    assert time.perf_counter() - t0 < seconds  # refused before any run
    return err


def test_unwritable_home_reports_and_out_are_one_line_before_any_work(tmp_path, capsys, monkeypatch):
    blocker = tmp_path / "file"
    blocker.write_text("a file, so nothing can be made under it, not even by root")
    monkeypatch.setenv("PCABENCH_HOME", str(blocker / "home"))
    err = one_line_error(capsys, "study", "--dx", "1", "--steps", "2", "--no-report", "--results", str(tmp_path / "r"))
    assert "PCABENCH_HOME" in err
    assert "PCABENCH_HOME" in one_line_error(capsys, "profile", "--save", "--no-gpu")
    monkeypatch.setenv("PCABENCH_HOME", str(tmp_path / "home"))
    err = one_line_error(
        capsys,
        "study",
        "--dx",
        "1",
        "--steps",
        "2",
        "--results",
        str(tmp_path / "r"),
        "--reports",
        str(blocker / "reports"),
    )
    assert "--reports" in err and not list((tmp_path / "r").glob("*.jsonl"))
    store.append(record(), tmp_path / "r" / "m.jsonl")
    err = one_line_error(capsys, "report", "--results", str(tmp_path / "r"), "--out", str(blocker / "out"))
    assert "--out" in err


def test_a_malformed_hardware_profile_is_one_warning_not_a_traceback(tmp_path, capsys, monkeypatch):
    monkeypatch.setenv("PCABENCH_HOME", str(tmp_path))
    (tmp_path / "hardware_profiles").mkdir()
    (tmp_path / "hardware_profiles" / "m.json").write_text('{"cpu": {"model": "x"')
    (tmp_path / "hardware_profiles" / "n.json").write_text("[1, 2]")
    store.append(record(), tmp_path / "r" / "m.jsonl")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        assert cli.main(["report", "--results", str(tmp_path / "r"), "--out", str(tmp_path / "out")]) == 0
    named = {str(w.message).split(":")[0] for w in caught if "hardware profile" in str(w.message)}
    assert named == {str(tmp_path / "hardware_profiles" / "m.json"), str(tmp_path / "hardware_profiles" / "n.json")}


@pytest.mark.parametrize(
    "command,args,words",
    [
        ("run", ["--solver", "linkedlist-cpu", "--dx", "\uff11"], ["--dx", "number"]),  # a full-width 1
        ("study", ["--dx", "1", "--steps", "\u0662"], ["--steps", "integer"]),  # an Arabic-Indic 2
        ("study", ["--dx", "1", "--threads", "\u0662"], ["--threads", "integer"]),
        ("run", ["--solver", "linkedlist-cpu", "--dx", "1", "--fields", ""], ["--fields", "file name"]),
        ("run", ["--solver", "linkedlist-cpu", "--dx", "1", "--fields", "/proc/x.npz"], ["--fields", "not writable"]),
        (
            "run",
            ["--solver", "linkedlist-cpu", "--dx", "1", "--h-factor", "0.5", "--cutoff", "1"],
            ["--cutoff * --h-factor", "> 1"],
        ),
        ("study", ["--dx", "1", "--results", ""], ["--results", "folder"]),
        ("report", ["--out", ""], ["--out", "folder"]),
    ],
)
def test_smaller_bad_inputs_are_one_line_before_any_work(command, args, words, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("PCABENCH_HOME", str(tmp_path / "home"))
    err = one_line_error(capsys, command, *args)
    assert all(w in err for w in words), err
    assert list(tmp_path.iterdir()) == []  # nothing written, not even into the current folder


def test_a_held_store_written_behind_the_sweeps_back_is_found(tmp_path):
    """While a sweep holds its store: bytes another writer appends (the lock is advisory) are moved to
    ``<store>.foreign`` before the sweep's next append, one warning each time; a rewrite of earlier rows cannot be
    mended and is named; the sweep's own appends are never taken for either."""
    path = tmp_path / "m.jsonl"

    def record(steps: int):
        spec = RunSpec("linkedlist-cpu", Scene(dx=1.0, steps=steps)).resolved()
        return sweep_module.failed_record(spec, "skipped", "a test row", "m")

    with store.SweepLock(path) as lock:
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            lock.append(record(1), path)
            lock.append(record(2), path)  # its own appends: nothing to say
        mine = path.read_bytes()
        with open(path, "a") as f:  # another writer, past the lock
            f.write('{"forged": 1}\n')
        with pytest.warns(store.StoreWarning, match="behind the sweep's back .* moved to"):
            lock.append(record(3), path)
        assert path.read_bytes().startswith(mine) and b"forged" not in path.read_bytes()
        assert Path(f"{path}.foreign").read_text() == '{"forged": 1}\n'
        assert path.read_bytes().startswith(b'{"code"')
        with open(path, "r+b") as f:  # an earlier row rewritten in place
            f.seek(2)
            f.write(b"CODE")  # '{"code": ...' of the first row
        with pytest.warns(store.StoreWarning, match="changed behind the sweep's back"):
            lock.append(record(4), path)
    assert len(path.read_text().splitlines()) == 4


def test_a_full_store_closes_as_a_segment_and_the_next_sweep_still_skips_its_runs(tmp_path, monkeypatch):
    """Past SEGMENT_BYTES a sweep closes the store as ``<store>.001.jsonl`` (its lines unchanged) and appends to a
    fresh file; the sweep and the study still count the segment's runs as stored, and a folder's readers read
    every run of both; a store with a torn last line is not closed until a sweep has mended it."""
    from pcabench import store as S
    from pcabench.cli.study import own_run_ids
    from pcabench.execute.sweep import run_here, sweep
    from pcabench.spec import RunSpec
    from solvers import Scene

    path = tmp_path / "m--h.jsonl"
    specs = [RunSpec("linkedlist-cpu", Scene(dx=dx, steps=2, model="linear")) for dx in (1.0, 0.8)]
    first = sweep(specs[:1], path, 60.0, 300.0, runner=run_here)
    before = path.read_bytes()
    monkeypatch.setattr(S, "SEGMENT_BYTES", len(before))  # the store is now full
    rows = sweep(specs, path, 60.0, 300.0, runner=run_here)
    part = tmp_path / "m--h.001.jsonl"
    assert part.read_bytes() == before and S.segments(path) == [part]
    assert len(rows) == 1 and rows[0]["run_id"] != first[0]["run_id"]  # the first run skipped: it is stored
    assert len(path.read_bytes().splitlines()) == 1  # only the new run in the fresh file
    both = {first[0]["run_id"], rows[0]["run_id"]}
    assert {r["run_id"] for r in S.read_rows(tmp_path)} == both and own_run_ids(path, specs) == both
    path.write_bytes(path.read_bytes() + b'{"torn')
    assert S.roll_over(path, limit=1) == [] and S.segments(path) == [part]
    lines = path.read_bytes().splitlines(keepends=True)[:1] * 3  # three whole lines: one a segment, at a limit
    path.write_bytes(b"".join(lines))  # of one line and a half
    made = S.roll_over(path, limit=len(lines[0]) * 3 // 2)
    assert [m.name for m in made] == ["m--h.002.jsonl", "m--h.003.jsonl", "m--h.004.jsonl"] and not path.exists()
    assert all(m.read_bytes() == lines[0] for m in made)
