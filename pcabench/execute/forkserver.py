"""A sweep's runs start warm: each run's child is forked from a server that has imported the harness,
the solvers, numpy and numba and initialised numba's CPU target once (multiprocessing's forkserver,
preloading :mod:`pcabench.execute.preload`), instead of being a fresh interpreter that pays all that again.

Each run keeps its own process, its budget and its kill -9 safety: the child is killed at its budget
like a fresh one, its stdout, stderr and record come back on pipes of its own (passed to it by the
forkserver), it dies with the server (PR_SET_PDEATHSIG) and the server ends when the sweep does. What a
fresh interpreter would read at start-up must agree with what the server read: a run whose environment
differs from the server's in anything but the variables the harness reads at run time (:data:`RUN_TIME`)
and those that say nothing of it (:data:`VOLATILE`), or a process that may not fork children (a daemonic
one, such as a Dask worker), starts a fresh interpreter instead (``python -m pcabench.execute.child``), as does
every run with ``PCABENCH_FORKSERVER=0``.
"""

from __future__ import annotations

import ctypes
import multiprocessing
import os
import signal
import subprocess
import sys
import threading
import types
from multiprocessing import reduction

ENV = "PCABENCH_FORKSERVER"  # "0": every run's child is a fresh interpreter
# read by the harness when a run starts, not at import: a child applies the sweep's own values
RUN_TIME = ("PCABENCH_COMMIT", "PCABENCH_MACHINE_ID", "PCABENCH_HOME", "PCABENCH_CACHE")
_server = {}  # "context", "env": the forkserver's context and the environment it started with
_lock = threading.Lock()


# what changes from one call to the next without changing what an interpreter imports
VOLATILE = ("PYTEST_CURRENT_TEST", "PWD", "OLDPWD", "_", "COLUMNS", "LINES")


WARM = (
    "PCABENCH_WARM"  # the server's own: the sweep's specs whose compiled loops it loads (pcabench/execute/preload.py)
)


def _fingerprint(env: dict) -> dict:
    return {k: v for k, v in env.items() if k not in RUN_TIME and k not in VOLATILE and k not in (ENV, WARM)}


def usable(env: dict) -> bool:
    """Whether a run with environment ``env`` can be forked from the server (starting it if need be)."""
    if env.get(ENV, os.environ.get(ENV)) == "0" or not sys.platform.startswith("linux"):
        return False
    if multiprocessing.current_process().daemon:  # may not have children of its own (a Dask worker)
        return False
    with _lock:
        if "context" not in _server:
            try:
                ctx = multiprocessing.get_context("forkserver")
            except ValueError:
                return False
            ctx.set_forkserver_preload(["pcabench.execute.preload"])
            _server.update(context=ctx, env=_fingerprint(dict(os.environ)))
    return _fingerprint(env) == _server["env"]


def prepare(specs: list) -> None:
    """Start the server for a sweep of ``specs``, warmed with their compiled loops where the disk cache has
    them (:func:`pcabench.execute.preload.warm`); a server this process started before stays as it is."""

    if not usable(dict(os.environ)) or _server.get("started"):
        return
    variants = {}  # one spec per set of loops: the scene decides seams and walls, the model what moves
    for spec in specs:
        sc = spec.scene
        variants.setdefault(
            (spec.solver, spec.threads, spec.pair_loop, sc.name, sc.model, sc.precision, sc.kernel), spec
        )
    os.environ[WARM] = "[" + ",".join(s.to_json() for s in variants.values()) + "]"
    try:
        start_server()
        _server["started"] = True
    finally:
        del os.environ[WARM]


def start_server() -> None:
    """multiprocessing's forkserver started if it is not running, with SIGINT ignored from its first instant: ignored
    (and held back from this process, not lost) only while it is spawned (a disposition set to ignore survives fork
    and exec, a blocked mask does not survive multiprocessing's spawn), a few milliseconds, not while it imports
    (its start does not wait for that). A terminal's Ctrl-C reaches the whole foreground group: the sweep, not its
    server, answers it (the server, still importing, printed a traceback). The runs' children are in sessions of
    their own."""
    from multiprocessing import forkserver, resource_tracker

    if threading.current_thread() is not threading.main_thread():
        forkserver.ensure_running()
        return
    # blocked first: a Ctrl-C in those milliseconds stays pending (Linux never discards a blocked signal, even an
    # ignored one) and reaches the restored handler when unblocked, instead of being lost to the ignore; the
    # resource tracker is started before, as its own start unblocks SIGINT (multiprocessing/resource_tracker.py)
    resource_tracker.ensure_running()
    signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    before = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        forkserver.ensure_running()
    finally:
        signal.signal(signal.SIGINT, before)
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})


class InheritedFd:
    """A file descriptor handed to the forked child (the forkserver passes it over its socket)."""

    def __init__(self, fd: int):
        self.fd = fd

    def __reduce__(self):
        return _detach, (reduction.DupFd(self.fd),)


def _detach(dup) -> int:
    return dup.detach()


LOST = 255  # a forked run's exit code when its server ended under it (multiprocessing's popen_forkserver: EOF)
NAME = b"pcabench-run"  # a forked run's process name (/proc/PID/comm; ps and pgrep show it)


def _prctl(option: int, arg) -> None:
    try:
        ctypes.CDLL("libc.so.6", use_errno=True).prctl(option, arg)
    except (OSError, AttributeError):  # not Linux
        pass


def die_with_parent() -> None:
    """Receive SIGKILL when the parent dies (Linux: PR_SET_PDEATHSIG; else nothing)."""
    _prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG = 1


def child_main(args: list, stdout: int, stderr: int, record: int, env: dict, cwd: str) -> None:
    """In the forked child: a process group of its own (the sweep ends it whole), the pipes as stdout and
    stderr, the sweep's environment and folder, then one run (:func:`pcabench.execute.child.main` with ``args``), its
    record on ``record``."""
    os.setsid()  # its own session and process group: what the run starts, the sweep ends with it
    die_with_parent()  # the forkserver, which ends when the sweep does
    _prctl(15, ctypes.c_char_p(NAME))  # PR_SET_NAME = 15
    sys.stdout.flush()
    sys.stderr.flush()
    os.dup2(stdout, 1)
    os.dup2(stderr, 2)
    os.close(stdout)
    os.close(stderr)
    os.environ.clear()
    os.environ.update(env)
    os.chdir(cwd)
    from pcabench.execute.child import main

    sys.exit(main(["--record-fd", str(record), *args]))


class ForkedChild:
    """A run's child forked from the server, with the part of :class:`subprocess.Popen` a sweep uses."""

    def __init__(self, args: list, stdout: int, stderr: int, record: int, env: dict):
        fds = (InheritedFd(stdout), InheritedFd(stderr), InheritedFd(record))
        self.process = _server["context"].Process(
            target=child_main, args=(list(args), *fds, dict(env), os.getcwd()), name="pcabench-run"
        )
        main = sys.modules["__main__"]
        sys.modules["__main__"] = types.ModuleType("__main__")  # the child has no main module to import again
        try:
            start_server()  # if not running: SIGINT ignored from its start (the start below would spawn it plain)
            self.process.start()
            _server["started"] = True
        finally:
            sys.modules["__main__"] = main
        self.pid = self.process.pid
        self.args = ["forkserver", "pcabench.execute.child", *args]

    @property
    def returncode(self):
        return self.process.exitcode

    def wait(self, timeout=None) -> int:
        self.process.join(timeout)
        if self.process.exitcode is None:
            raise subprocess.TimeoutExpired(self.args, timeout)
        return self.process.exitcode

    def kill(self) -> None:
        if self.process.exitcode is None:
            try:
                os.kill(self.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
