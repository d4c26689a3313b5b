"""A sweep: a list of run specs, each run in its own child process, stored as it finishes.

Each run is a child process with a time budget (forked from a server that has
imported the harness and the solvers once, pcabench/execute/forkserver.py, or a fresh
``python -m pcabench.execute.child``):
a crash, hang or out-of-memory in one run is recorded (status error /
timeout / out-of-memory, naming the signal or exit code) and the sweep goes
on. A child dies with its parent (Linux: PR_SET_PDEATHSIG), so a killed sweep
leaves no run going on unsupervised. The sweep holds the store's lock and is
its only writer; every finished run is appended at once, and a rerun skips
the runs the store already holds for this machine (hardware profile and
host), commit and preset (:func:`pcabench.spec.identity`), so an interrupted
sweep resumes where it stopped (a run given twice is run once); ``retry_failed``
reruns timeouts, skips and errors. A run predicted to take longer than the run budget is stored as
``skipped`` with the prediction.
"""

from __future__ import annotations

import abc
import io
import json
import math
import os
import re
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

from pcabench import store
from pcabench.execute import containment, forkserver
from pcabench.execute.ahead import compile_ahead
from pcabench.machine.memory import cgroup_memory_folders
from pcabench.machine.profiles import MACHINE_ID_ENV, machine_id
from pcabench.predict import predicted_seconds, row_variant, spec_variant
from pcabench.spec import RunSpec, row_identity
from pcabench.store import schema
from pcabench.store.provenance import code_key, git_commit, host_id
from pcabench.store.record import RunRecord, step_seconds

RETRIED = ("timeout", "skipped", "error")  # statuses --retry-failed runs again


def failed_record(spec: RunSpec, status: str, message: str, profile: str, seconds: float | None = None) -> RunRecord:
    """The record of a run that made no result of its own (skipped, timed out, crashed)."""
    if seconds is not None:
        message = f"{message} (after {seconds:.0f} s)"
    return RunRecord.from_spec(spec, profile, status=status, message=message)


def oom_kills() -> int | None:
    """The kernel's count of OOM kills so far in this process's cgroup and its ancestors (v2
    ``memory.events``, v1 ``memory.oom_control``), or None where the kernel does not say."""
    counts = []
    for *_, events in cgroup_memory_folders():
        try:
            with open(events) as f:
                counts += [int(line.split()[1]) for line in f if line.startswith("oom_kill ")]
        except (OSError, ValueError, IndexError):
            pass
    return sum(counts) if counts else None


def exit_status(returncode: int, oom_before: int | None, oom_after: int | None) -> tuple[str, str]:
    """(status, what happened) of a child that ended without a record."""
    if returncode < 0:
        name = signal.Signals(-returncode).name if -returncode in signal.valid_signals() else f"signal {-returncode}"
        if (
            -returncode == signal.SIGKILL
            and oom_before is not None
            and oom_after is not None
            and oom_after > oom_before
        ):
            return "out-of-memory", f"killed by {name}: the kernel's OOM killer (cgroup oom_kill count rose)"
        return "error", f"killed by {name}"
    return "error", f"exit code {returncode}"


RECORD_LIMIT = 1 << 20  # the most bytes a child's record may take on its channel
OUTPUT_KEPT = 2000  # characters of a solver's stdout and stderr kept in its record's message
DRAIN_S = 5.0  # after a run ends, how long its pipes may still be read (a process holding them past it is left)
PROGRESS = re.compile(r"\r[^\r\n]*: step \d+/\d+ [^\r\n]*\n?")  # pcabench.execute.progress's lines


def _drain(stream, keep: list, relay=None) -> None:
    """Read ``stream`` to its end, keeping the last :data:`OUTPUT_KEPT` characters in ``keep`` (and passing
    every chunk to ``relay``)."""
    for raw in iter(lambda: stream.read1(4096), b""):
        text = raw.decode("utf-8", "replace")
        if relay is not None:
            relay(text)
        keep.append(text)
        while len(keep) > 1 and sum(map(len, keep[1:])) > OUTPUT_KEPT:
            del keep[0]


def _cut(chunks: list) -> str:
    text = "".join(chunks).strip()
    return text if len(text) <= OUTPUT_KEPT else "..." + text[-OUTPUT_KEPT:]


def start_child(spec: RunSpec, env: dict, fields_path) -> tuple:
    """Start the child that runs ``spec`` with environment ``env``, its fields to ``fields_path``, in a process
    group of its own: forked from the warm server where it can be (pcabench/execute/forkserver.py), else a fresh
    interpreter (``python -m pcabench.execute.child``). (process, its stdout and stderr as binary streams, the read
    end of its record's pipe)."""
    read_end, write_end = os.pipe()
    args = ["--fields", str(fields_path), spec.to_json()]
    if forkserver.usable(env):
        ends = [os.pipe(), os.pipe()]
        try:
            proc = forkserver.ForkedChild(args, ends[0][1], ends[1][1], write_end, env)
        except BaseException:
            for fd in (read_end, ends[0][0], ends[1][0]):
                os.close(fd)
            raise
        finally:
            for fd in (write_end, ends[0][1], ends[1][1]):  # the child holds them now
                os.close(fd)
        return proc, os.fdopen(ends[0][0], "rb"), os.fdopen(ends[1][0], "rb"), read_end
    cmd = [sys.executable, "-m", "pcabench.execute.child", "--record-fd", str(write_end), *args]
    try:
        proc = subprocess.Popen(
            cmd,
            stdin=subprocess.DEVNULL,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            env=env,
            pass_fds=(write_end,),
            start_new_session=True,  # its own process group: what the run starts, the sweep ends with it
            preexec_fn=forkserver.die_with_parent if sys.platform.startswith("linux") else None,
        )
    except BaseException:
        os.close(read_end)
        raise
    finally:
        os.close(write_end)  # the child holds it now: the pipe ends when the child does
    return proc, proc.stdout, proc.stderr, read_end


MEASURED = (
    "steps",
    "t_end",
    "stages",
    "jit_seconds",
    "jit_cached",
    "mean_neighbours",
    "status",
    "failed_step",
    "message",
)
CHILD_STATUSES = ("ok", "unstable", "out-of-memory", "error")  # what a run can end in; the sweep says the rest


def _measurement_problem(spec: RunSpec, row: dict, wall: float | None = None) -> str:
    """Why the measurements in a child's ``row`` do not fit its ``spec`` ('' if they do), nor the child's
    ``wall`` time (s) as the sweep measured it: its stages and JIT cannot add up to more."""
    from solvers import STAGES

    scene = spec.scene
    if row.get("n_particles") != scene.n_particles:
        return f"it ran {row.get('n_particles')!r:.40} particles, not the spec's {scene.n_particles}"
    steps = row.get("steps")
    if not isinstance(steps, int) or isinstance(steps, bool) or not 0 <= steps <= scene.n_steps:
        return f"its steps {steps!r:.40} are not a count from 0 to the spec's {scene.n_steps}"
    stages = row.get("stages")
    if not isinstance(stages, dict) or sorted(stages) != sorted(STAGES):
        return f"its stages are not the clock's six ({', '.join(STAGES)})"
    for name, seconds in stages.items():
        why = schema.check_value(f"stage {name}", schema.STAGE_TIME, seconds)  # as a stored record's
        if why:
            return why
    if row.get("status") not in CHILD_STATUSES:
        return f"its status {row.get('status')!r:.40} is not one a run ends in ({', '.join(CHILD_STATUSES)})"
    jit = row.get("jit_seconds") if isinstance(row.get("jit_seconds"), (int, float)) else 0.0
    if wall is not None and sum(stages.values()) + jit > wall + 0.01:
        return f"its stages and JIT add up to {sum(stages.values()) + jit:.3g} s, more than its process's {wall:.3g} s"
    for key in MEASURED:
        why = schema.check_value(key, schema.FIELDS[key], row[key]) if key in row else ""
        if why:
            return why
    if row.get("status") in ("ok", "error") and row.get("message", "") == "" and steps != scene.n_steps:
        return f"it finished after {steps} of the spec's {scene.n_steps} steps"
    return ""


def accept(spec: RunSpec, row: dict, fields_path, commit: str, machine: str, wall: float | None = None) -> RunRecord:
    """The record of a run whose child sent ``row`` and wrote its fields to ``fields_path``.

    The sweep builds the record's identity itself (:meth:`RunRecord.from_spec`: the spec, the solver and its
    device, this machine and host, ``commit``, the package versions) and takes from the child only what it
    measured (:data:`MEASURED`), checked against the spec: its particle count, steps within the spec's,
    the clock's six stages as finite times adding up to no more than the child's ``wall`` time (s, measured
    here; how short a stage was is the child's word), a status a run ends in. The errors are computed here from the
    fields the child wrote (:func:`pcabench.execute.run.score`), never taken from the child. A record that fails
    these checks is an ``error`` naming why."""
    from pcabench.execute.run import load_fields, score

    record = RunRecord.from_spec(spec, machine, status="error")
    record.commit = commit
    why = _measurement_problem(spec, row, wall)
    if why:
        record.message = f"the run's record does not fit its spec: {why}"
        return record
    for key in MEASURED:
        if key in row:
            setattr(record, key, row[key])
    record.message = schema.clean_text(str(record.message or ""))
    finished = row["status"] == "ok" or row["status"] == "error" and not record.message
    if not finished:  # unstable (at its step), out-of-memory or a failed run: as it ended, nothing to score
        return record
    record.status, record.failed_step = "error", None
    try:  # a regular file of a bounded size (not a link, not a FIFO): what one value a particle takes
        data = store.read_regular(fields_path, limit=(1 << 20) + 64 * spec.scene.n_particles)
        fields = load_fields(io.BytesIO(data))
    except (OSError, ValueError, KeyError, TypeError, EOFError) as exc:
        record.message = f"the run wrote no usable fields ({type(exc).__name__}: {str(exc)[:200]})"
        return record
    return score(record, spec.scene, fields)  # its time, errors and status from the fields


def end_group(proc) -> None:
    """Kill the run's whole process group (its child and whatever the run started), then the child."""
    try:
        os.killpg(proc.pid, signal.SIGKILL)
    except (ProcessLookupError, PermissionError):
        pass
    proc.kill()


def run_child(
    spec: RunSpec, timeout: float, commit: str, machine: str, stream=sys.stderr, fields_to=None, env=None
) -> dict:
    """Run ``spec`` in a child process, relaying its progress to ``stream``; its record as a row.

    The child sends its record on a pipe of its own (``--record-fd``), never on stdout: whatever the solver
    prints on stdout or stderr is kept (cut) in the record's message and never parsed. The record is built
    here (:func:`accept`): identity from ``spec``, ``commit`` and ``machine`` (the parent's
    :func:`~pcabench.machine.profiles.machine_id`), the child's measurements checked, the errors computed from its
    fields. The child's process group is ended when it does, and at once past ``timeout``. With ``fields_to``
    the run's fields are kept there (an .npz, written as :mod:`pcabench.store.safeio` writes). ``env``: variables
    the child's environment adds. A run whose forkserver ended under it is run again in a fresh interpreter.

    Raises subprocess.TimeoutExpired (the child's group is killed first) past ``timeout`` seconds.
    """
    import tempfile

    env = {**os.environ, **(env or {}), "PCABENCH_COMMIT": commit, MACHINE_ID_ENV: machine}  # the sweep's
    oom_before = oom_kills()
    containment.become_subreaper()  # what the run starts and orphans is adopted here, and ended with the run
    with tempfile.TemporaryDirectory(prefix="pcabench-run-") as scratch:
        fields_path = Path(scratch) / "fields.npz"
        started = time.perf_counter()
        proc, stdout, stderr, read_end = start_child(spec, env, fields_path)
        known = containment.children() | {proc.pid}  # this process's own (the forkserver's started by now)
        out, err, record = [], [], []

        def relay(text):  # the child's progress lines go on to the user
            if stream is not None:
                stream.write(text)
                stream.flush()

        def read_record():
            with os.fdopen(read_end, "rb") as f:
                data = f.read(RECORD_LIMIT + 1)
                while f.read(1 << 16):  # a record past the limit: drain the rest, keep none of it
                    pass
            record.append(data if len(data) <= RECORD_LIMIT else b"")

        readers = [
            threading.Thread(target=_drain, args=(stdout, out), daemon=True),
            threading.Thread(target=_drain, args=(stderr, err, relay), daemon=True),
            threading.Thread(target=read_record, daemon=True),
        ]
        try:  # from the child's start: a Ctrl-C at any moment from here ends the child's group with the sweep
            for reader in readers:
                reader.start()
            proc.wait(timeout=timeout)
            wall = time.perf_counter() - started
        except BaseException:
            end_group(proc)
            proc.wait()
            raise
        finally:
            end_group(proc)  # what the run left running (a plug-in's own processes) ends with it
            containment.end_adopted(known)  # and what left its group (setsid): adopted here, ended
            containment.stop_subreaper()
            until = time.monotonic() + DRAIN_S
            for reader in readers:
                if reader.ident is not None:
                    reader.join(timeout=max(until - time.monotonic(), 0.0))
            for f, reader in zip((stdout, stderr), readers):
                if not reader.is_alive():  # one still reading (a pipe held past the deadline) is left to end
                    f.close()
            if stream is not None and err and not err[-1].endswith("\n"):
                stream.write("\n")  # end the child's last progress line
        said = PROGRESS.sub("", "".join(err)).strip()  # stderr less the child's own progress lines
        printed = "".join(
            f"\nthe solver's {name} (cut): {_cut([text])}"
            for name, text in (("stdout", "".join(out).strip()), ("stderr", said))
            if text
        )
        data = record[0] if record else b""
        if proc.returncode == 0 and data:
            try:
                row = json.loads(data.decode("utf-8"))
            except (ValueError, RecursionError) as exc:
                row = None
                what = f"its record could not be read ({type(exc).__name__})"
            else:
                what = ""
            if isinstance(row, dict):
                accepted = accept(spec, row, fields_path, commit, machine, wall)
                if printed:
                    accepted.message = schema.clean_text((accepted.message + printed).strip())
                if fields_to is not None:
                    from pcabench.store.safeio import write_file

                    try:
                        write_file(fields_to, store.read_regular(fields_path))
                    except FileNotFoundError:
                        pass
                return store.to_row(accepted)
            what = what or "its record is not a JSON object"
        else:
            if isinstance(proc, forkserver.ForkedChild) and proc.returncode == forkserver.LOST and not data:
                # the server it was forked from ended under it (killed): not the run's doing, so run it again in
                # a fresh interpreter with what is left of its budget (the next runs start a new server)
                if stream is not None:
                    print(f"{spec.label}: its forkserver ended under it; run again in a fresh interpreter", file=stream)
                left = timeout - (time.perf_counter() - started)
                env_fresh = {forkserver.ENV: "0"}
                return run_child(spec, left, commit, machine, stream, fields_to, env=env_fresh)
            status, what = exit_status(proc.returncode, oom_before, oom_kills())
            if proc.returncode == 0:
                what = "it sent no record"
        status = "error" if proc.returncode == 0 else status
        return store.to_row(failed_record(spec, status, what + printed, machine))


def run_here(spec: RunSpec, timeout: float, commit: str, machine: str, stream=sys.stderr) -> dict:
    """Run ``spec`` in this process: no crash isolation and no per-run time limit (``timeout`` is not
    enforced), but compiled kernels are kept from run to run. For the GPU check, whose budget is minutes."""
    from pcabench.execute.child import run_spec

    return run_spec(spec)


def error_words(row: dict) -> str:
    """The run's headline error for a progress line: ``MSE x``, or, for a run with open edges, what they left
    (``left x of the amplitude``: its MSE is against a pulse that may have left the domain)."""
    left = (row.get("errors") or {}).get("left_amplitude")
    if (row.get("scene") or {}).get("open") and left is not None:
        return f"left {left:.3g} of the amplitude"
    mse = row.get("mse")
    return f"MSE {'-' if mse is None else f'{mse:.4g}'}"


def eta_text(
    remaining: list[RunSpec],
    mine: list[dict],
    seconds_per_run: float | None,
    whose: str = "this host's",
    run_budget: float = math.inf,
) -> str:
    """The sweep's ETA and how sure it is: runs predicted from ``whose`` timings, the rest at the mean so far;
    a run predicted past ``run_budget`` counts nothing (the sweep will skip it, as it skips it then)."""
    if not remaining:
        return "done"
    compiled = {row_variant(r) for r in mine}  # configurations whose loops the cache holds by then
    predicted = []
    for s in remaining:
        predicted.append(predicted_seconds(s, mine, cached=spec_variant(s) in compiled)[0])
        compiled.add(spec_variant(s))
    skipped = sum(1 for p in predicted if p is not None and p > run_budget)
    known = [p for p in predicted if p is not None and p <= run_budget]
    unknown = len(predicted) - len(known) - skipped
    to_run = len(remaining) - skipped
    if unknown and seconds_per_run is None:
        return f"eta unknown ({to_run} runs left, {len(known)} predicted)"
    total = sum(known) + unknown * min(seconds_per_run or 0.0, run_budget)
    how = f"{len(known)} of {to_run} runs predicted from {whose} timings" + (
        f", {unknown} at the mean so far" if unknown else ""
    )
    how += f"; {skipped} to be skipped past the run budget" if skipped else ""
    return f"eta {total / 60:.1f} min ({how})"


class Executor(abc.ABC):
    """Where a sweep's runs happen. The sweep loop (:func:`run_specs`) asks it to :meth:`start` up to
    ``slots`` runs at a time and to :meth:`wait` for the next one to finish; resume, skip-by-prediction,
    storing and progress are the loop's, the same for every executor."""

    slots = 1  # runs in flight at once
    whose = "this host's"  # whose timings the predictions come from, for the progress line

    @abc.abstractmethod
    def key(self, spec: RunSpec, code: str) -> str:
        """The spec's store key (:func:`~pcabench.spec.identity`) by ``code`` as this executor places runs."""

    def prepare(self, queue: list[RunSpec]) -> None:
        """Before the first of the runs ``queue`` holds (those not stored yet): nothing here."""

    @abc.abstractmethod
    def row_key(self, row: dict) -> str:
        """:meth:`key` of a stored row."""

    @abc.abstractmethod
    def informs(self, row: dict) -> bool:
        """Whether a stored row's timing predicts this executor's runs."""

    @abc.abstractmethod
    def start(self, spec: RunSpec, timeout: float, budget_cut: bool) -> None:
        """Begin running ``spec`` with ``timeout`` seconds (the sweep's remaining budget if ``budget_cut``)."""

    @abc.abstractmethod
    def wait(self) -> tuple[RunSpec, dict | None]:
        """The next finished run and its row; None when the sweep's budget ended it (nothing to store)."""


class LocalExecutor(Executor):
    """One run at a time on this machine, each by ``runner`` (a child process by default; ``run_here`` runs
    in this process, keeping compiled kernels, for the GPU check)."""

    def __init__(self, machine: str, host: str, commit: str, runner=None, stream=sys.stderr):
        self.machine, self.host, self.commit, self.stream = machine, host, commit, stream
        self.runner, self.pending = runner or run_child, []

    def prepare(self, queue):
        """Runs in child processes: the loops they need compiled ahead, side by side (pcabench/execute/ahead.py),
        then the children's server started with them loaded (pcabench/execute/forkserver.py)."""
        if self.runner is run_child and queue:
            compile_ahead(queue, self.stream)
            forkserver.prepare(queue)

    def key(self, spec, code):
        return spec.key(self.machine, code, self.host)

    def row_key(self, row):
        return row_identity(row)

    def informs(self, row):
        return row.get("profile_id") == self.machine and row.get("host") == self.host

    def start(self, spec, timeout, budget_cut):
        self.pending.append((spec, timeout, budget_cut))

    def wait(self):
        spec, timeout, budget_cut = self.pending.pop(0)
        t0 = time.perf_counter()
        try:
            return spec, self.runner(spec, timeout, self.commit, self.machine, self.stream)
        except subprocess.TimeoutExpired:
            if budget_cut:  # the sweep's budget ran out, not the run's: nothing to record
                return spec, None
            return spec, store.to_row(
                failed_record(
                    spec, "timeout", f"past the run budget of {timeout:.0f} s", self.machine, time.perf_counter() - t0
                )
            )


class StoreFile:
    """The one store a local sweep writes, held by its lock (:meth:`pcabench.store.SweepLock.hold`)."""

    def __init__(self, path: Path, lock: store.SweepLock):
        self.path, self.lock = path, lock

    def append(self, row: dict) -> dict:
        return self.lock.append(row, self.path)


def run_specs(
    specs: list[RunSpec],
    executor: Executor,
    stores,
    rows: list[dict],
    run_budget: float,
    sweep_budget: float = math.inf,
    stream=sys.stderr,
    retry_failed: bool = False,
) -> list[dict]:
    """The sweep loop of every executor: ``specs`` not already in ``rows`` run by ``executor``, each row
    appended to ``stores`` as it arrives; the rows stored.

    A run given twice is run once; rows with ``retry_failed`` statuses in :data:`RETRIED` do not count as
    done. Before a run starts its time is predicted from the finished runs that inform the executor
    (``predict.py``, updated as runs finish); one predicted past ``run_budget`` is stored as ``skipped``.
    No run starts after ``sweep_budget`` seconds; one the budget cuts short is not stored.
    """
    code, machine = code_key(), machine_id()  # the code this sweep's runs are made by: another's are not done
    done = {executor.row_key(r) for r in rows if not (retry_failed and r.get("status") in RETRIED)}
    known = [r for r in rows if executor.informs(r)]
    specs = list(dict.fromkeys(s.resolved() for s in specs))
    labels = {s: f"[{i}/{len(specs)}] {s.label}" for i, s in enumerate(specs, 1)}
    queue = []
    for spec in specs:
        if executor.key(spec, code) in done:
            print(f"{labels[spec]}: already stored", file=stream, flush=True)
        else:
            queue.append(spec)
    executor.prepare(queue)
    t_start, stored, failed, running, n_todo = time.perf_counter(), [], 0, 0, len(queue)
    while queue or running:
        while queue and running < executor.slots:
            spec, left = queue[0], sweep_budget - (time.perf_counter() - t_start)
            if left <= 0:
                print(f"{labels[spec]}: sweep budget spent, stopping (rerun to resume)", file=stream, flush=True)
                queue.clear()
                break
            queue.pop(0)
            seconds, why = predicted_seconds(spec, known)
            if seconds is not None and seconds > run_budget:
                stored.append(
                    stores.append(
                        store.to_row(failed_record(spec, "skipped", f"{why} > run budget {run_budget:.0f} s", machine))
                    )
                )
                print(f"{labels[spec]}: skipped, {why}", file=stream, flush=True)
                continue
            print(
                f"{labels[spec]}: running" + (f" (predicted {seconds:.0f} s)" if seconds is not None else ""),
                file=stream,
                flush=True,
            )
            executor.start(spec, min(run_budget, left), left < run_budget)
            running += 1
        if not running:
            break
        spec, row = executor.wait()
        running -= 1
        if row is None:
            print(
                f"{labels[spec]}: sweep budget spent during the run, not stored (rerun to resume)",
                file=stream,
                flush=True,
            )
            queue.clear()
            continue
        why = store.validate(store.to_row(row))
        if why:  # a record that would not read back is never written: the run is stored as an error
            row = store.to_row(failed_record(spec, "error", f"the run's record would not read back ({why})", machine))
        row = stores.append(row)
        stored.append(row)
        known.append(row)
        failed += row["status"] != "ok"
        made = [r for r in stored if r["status"] != "skipped"]
        per_run = (time.perf_counter() - t_start) / len(made) / executor.slots if made else None
        where = f" on {row.get('profile_id')}/{row.get('host')}" if executor.slots > 1 else ""
        print(
            f"{labels[spec]}{where}: {row['status']}, step {1e3 * step_seconds(row['stages'], row['steps']):.2f} "
            f"ms, {error_words(row)} | sweep: {len(stored)}/{n_todo} done, "
            f"{running} running, {failed} not ok, {eta_text(queue, known, per_run, executor.whose, run_budget)}",
            file=stream,
            flush=True,
        )
    return stored


def sweep(
    specs: list[RunSpec],
    store_path: Path,
    run_budget: float,
    sweep_budget: float,
    stream=sys.stderr,
    retry_failed: bool = False,
    runner=None,
) -> list[dict]:
    """Run ``specs`` on this machine (skipping those already stored), one child process each (``runner``),
    into the store at ``store_path``; the rows stored (:func:`run_specs`)."""
    store.check_writable(store_path)
    with store.SweepLock(store_path) as lock:
        store_path = Path(store_path)
        rows = store.read_rows(store.store_files(store_path))  # its segments too: their runs are stored
        executor = LocalExecutor(machine_id(), host_id(), git_commit(), runner, stream)
        return run_specs(
            specs, executor, StoreFile(store_path, lock), rows, run_budget, sweep_budget, stream, retry_failed
        )
