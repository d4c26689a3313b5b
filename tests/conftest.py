"""Shared fixtures: small scenes and a helper that runs a scene and returns record + fields."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from benchmarks.common import gpu_available
from pcabench import cli
from pcabench.execute.run import run
from pcabench.spec import RunSpec
from solvers import Scene

strip_for = Scene.thinnest_strip  # the thinnest y-periodic strip the cell list accepts at dx, m
ROOT = Path(__file__).resolve().parents[1]


def in_simulator(script: str, *args, timeout: float = 900) -> dict:
    """Run the Python ``script`` (with ``args``) in a fresh interpreter under numba-cuda's CUDA simulator
    (NUMBA_ENABLE_CUDASIM=1: the GPU kernels run on the CPU, NumPy in place of CuPy); the JSON object its last
    line prints. The one way the tests reach the GPU solver without a GPU."""
    path = os.pathsep.join([str(ROOT), *(p for p in os.environ.get("PYTHONPATH", "").split(os.pathsep) if p)])
    env = dict(os.environ, NUMBA_ENABLE_CUDASIM="1", PYTHONPATH=path)
    proc = subprocess.run(
        [sys.executable, "-c", script, *map(str, args)],
        capture_output=True,
        text=True,
        env=env,
        timeout=timeout,
        cwd=ROOT,
    )
    assert proc.returncode == 0, proc.stderr[-3000:]
    return json.loads(proc.stdout.strip().splitlines()[-1])


def run_fields(scene: Scene, solver: str, tmp_path, threads=1):
    path = tmp_path / f"{solver}-{threads}-{scene.precision}-{scene.model}.npz"
    record = run(RunSpec(solver, scene, threads), fields_path=path)
    fields = dict(np.load(path)) if path.exists() else None
    return record, fields


@pytest.fixture
def requires_gpu():
    if not gpu_available():
        pytest.skip("no CUDA GPU on this machine (the simulator tests cover the kernels)")


def run_children(pid: int) -> list[int]:
    """The running run children among the descendants of ``pid``: forked by the sweep's forkserver (named
    pcabench-run, pcabench/execute/forkserver.py) or fresh interpreters (``python -m pcabench.execute.child``)."""
    found, todo = [], [pid]
    while todo:
        out = subprocess.run(["pgrep", "-P", str(todo.pop())], capture_output=True, text=True).stdout.split()
        for child in map(int, out):
            todo.append(child)
            try:
                comm = open(f"/proc/{child}/comm", "rb").read().strip()
                cmdline = open(f"/proc/{child}/cmdline", "rb").read()
                state = open(f"/proc/{child}/stat", "rb").read().rsplit(b")", 1)[1].split()[0]
            except (OSError, IndexError):
                continue
            if state == b"Z":  # ended (not yet reaped by its parent): not running
                continue
            if comm == b"pcabench-run" or b"pcabench.execute.child" in cmdline:
                found.append(child)
    return found


def study_process(results, *args) -> subprocess.Popen:
    """``pcabench study ARGS --no-report --results RESULTS`` in a process group of its own (its stderr piped, as
    text): a test may signal the whole group as a terminal would."""
    return subprocess.Popen(
        [sys.executable, "-m", "pcabench.cli", "study", *args, "--no-report", "--results", str(results)],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
        preexec_fn=default_sigint,  # as a terminal starts it, whatever the test worker inherited
    )


def default_sigint() -> None:
    """SIGINT at its default in a child about to exec (an ignored disposition is inherited through exec: a
    test worker that ignores SIGINT would make a child deaf to the Ctrl-C a test sends it)."""
    import signal

    signal.signal(signal.SIGINT, signal.SIG_DFL)


def cli_main(*args, capsys):
    """``pcabench ARGS`` in this process: (exit code, stdout, stderr)."""
    try:
        code = cli.main(list(args))
    except SystemExit as exc:
        code = exc.code
    out, err = capsys.readouterr()
    return code, out, err
