"""The store's guarantees, each probe of a demanding user: torn tails, two writers, killed parents,
unwritable and full stores, corrupt rows, killed children, retries, and the memory actually available."""
from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
import warnings

import pytest

from pcabench import cli, store, sweep as sweep_module
from pcabench.profiles import machine_id
from pcabench.record import RunRecord
from pcabench.spec import RunSpec
from pcabench.sweep import exit_status, sweep
from solvers import Scene, SceneError
from solvers import scene as scene_module


def record(dx=1.0, status="ok", **kw):
    rec = RunRecord.before_run(Scene(dx=dx, steps=3), "linkedlist-cpu", 1, status=status, profile_id="m")
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
        f.write(b"null\n{\"solver\": 3}\n")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", store.StoreWarning)
        assert cli.main(["report", "--results", str(results), "--out", str(tmp_path / "out")]) == 0
    assert (tmp_path / "out" / "README.md").exists()


# ---------------------------------------------------------------- two writers and killed parents
def _study(results, *args):
    return subprocess.Popen([sys.executable, "-m", "pcabench.cli", "study", "--dx", "1", "0.5", "--steps", "3",
                             "--no-report", "--results", str(results), *args],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, start_new_session=True)


def test_two_sweeps_on_one_store_never_duplicate(tmp_path):
    first = _study(tmp_path)
    deadline = time.time() + 120
    while time.time() < deadline and not list(tmp_path.glob("*.lock")):
        time.sleep(0.05)
    second = _study(tmp_path)
    _, err2 = second.communicate(timeout=300)
    _, err1 = first.communicate(timeout=300)
    assert first.returncode == 0, err1
    assert second.returncode == 2 and "in use by another sweep" in err2 and "Traceback" not in err2
    rows = rows_quietly(next(tmp_path.glob("*.jsonl")))
    assert len(rows) == 2 and len({(r["dx"], r["solver"]) for r in rows}) == 2


def test_a_killed_parent_takes_its_running_child_with_it(tmp_path):
    proc = subprocess.Popen([sys.executable, "-m", "pcabench.cli", "study", "--dx", "0.25", "--steps", "100000",
                             "--no-report", "--results", str(tmp_path)],
                            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    child = None
    deadline = time.time() + 120
    while time.time() < deadline and child is None:
        out = subprocess.run(["pgrep", "-P", str(proc.pid), "-f", "pcabench.child"], capture_output=True, text=True)
        child = int(out.stdout.split()[0]) if out.stdout.strip() else None
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


def test_retry_failed_runs_timeouts_skips_and_errors_again(tmp_path, monkeypatch):
    path = tmp_path / "s.jsonl"
    spec = RunSpec("linkedlist-cpu", Scene(dx=1.0, steps=2)).resolved()
    made = []

    def fake_child(spec, timeout, commit, machine, stream=None):
        made.append(spec)
        rec = sweep_module.failed_record(spec, "ok", "", machine)
        rec.steps = 2
        return store.to_row(rec)

    monkeypatch.setattr(sweep_module, "run_child", fake_child)
    store.append(sweep_module.failed_record(spec, "timeout", "past the run budget", machine_id()),
                 path)
    sweep([spec], path, run_budget=60, sweep_budget=60)
    assert made == []  # stored (as a timeout): a plain rerun skips it
    sweep([spec], path, run_budget=60, sweep_budget=60, retry_failed=True)
    assert len(made) == 1 and [r["status"] for r in store.read_rows(path)] == ["timeout", "ok"]
    sweep([spec], path, run_budget=60, sweep_budget=60, retry_failed=True)
    assert len(made) == 1  # an ok run is never rerun


# ---------------------------------------------------------------- memory and numeric options
def test_the_memory_check_uses_the_cgroup_limit(tmp_path, monkeypatch):
    limit, usage = tmp_path / "memory.max", tmp_path / "memory.current"
    limit.write_text(f"{1 << 30}\n")
    usage.write_text(f"{256 << 20}\n")
    monkeypatch.setattr(scene_module, "CGROUP_FILES", ((str(limit), str(usage)),))
    assert scene_module.available_memory_bytes() == (1 << 30) - (256 << 20)
    with pytest.raises(SceneError, match="smallest dx that fits"):
        Scene(dx=0.01)  # 10M particles: about 2.4 GB of arrays, more than the 0.75 GiB left in the cgroup
    limit.write_text("max\n")
    assert scene_module.available_memory_bytes() > (1 << 30)  # no limit: the host's available memory


@pytest.mark.parametrize("command,args,words", [
    ("run", ["--solver", "linkedlist-cpu", "--dx", "1e-300"], ["dx", "smallest dx that fits"]),
    ("study", ["--dx", "1e-300"], ["dx", "smallest dx that fits"]),
    ("run", ["--solver", "linkedlist-cpu", "--dx", "1", "--t-end", "0"], ["t_end", "> 0"]),
    ("study", ["--dx", "1", "--t-end", "0"], ["t_end", "> 0"]),
    ("study", ["--dx", "1", "--t-end", "1e300"], ["t_end", "1e7 steps"]),
    ("study", ["--dx", "1", "--cfl", "1e-300", "--t-end", "1"], ["t_end", "1e7 steps"]),
    ("study", ["--quick", "--sweep-budget", "-1"], ["--sweep-budget", "> 0"]),
])
def test_numeric_options_refuse_meaningless_values_in_run_and_study(command, args, words, capsys, tmp_path):
    extra = ["--results", str(tmp_path)] if command == "study" else []
    with pytest.raises(SystemExit) as exc:
        cli.main([command, *args, *extra])
    err = capsys.readouterr().err
    assert exc.value.code == 2 and "Traceback" not in err and len(err.strip().splitlines()) == 1, err
    assert all(w in err for w in words), err
    assert not list(tmp_path.glob("*.jsonl"))
