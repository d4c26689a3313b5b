"""Shared fixtures: small scenes and a helper that runs a scene and returns record + fields."""

from __future__ import annotations

import subprocess

import numpy as np
import pytest

from benchmarks.common import gpu_available
from pcabench import cli
from pcabench.run import run
from pcabench.spec import RunSpec
from solvers import Scene

strip_for = Scene.thinnest_strip  # the thinnest y-periodic strip the cell list accepts at dx, m


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
    """The run children among the descendants of ``pid``: forked by the sweep's forkserver (named
    pcabench-run, pcabench/forkserver.py) or fresh interpreters (``python -m pcabench.child``)."""
    found, todo = [], [pid]
    while todo:
        out = subprocess.run(["pgrep", "-P", str(todo.pop())], capture_output=True, text=True).stdout.split()
        for child in map(int, out):
            todo.append(child)
            try:
                comm = open(f"/proc/{child}/comm", "rb").read().strip()
                cmdline = open(f"/proc/{child}/cmdline", "rb").read()
            except OSError:
                continue
            if comm == b"pcabench-run" or b"pcabench.child" in cmdline:
                found.append(child)
    return found


def cli_main(*args, capsys):
    """``pcabench ARGS`` in this process: (exit code, stdout, stderr)."""
    try:
        code = cli.main(list(args))
    except SystemExit as exc:
        code = exc.code
    out, err = capsys.readouterr()
    return code, out, err
