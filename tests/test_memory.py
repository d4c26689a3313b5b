"""The memory check lives in the harness (pcabench/machine/memory.py); a Scene is a pure value; an
out-of-memory is recognised by the exception's type, not its text."""

from __future__ import annotations

import builtins
import os
import sys
import types

import pytest

from pcabench import cli
from pcabench.execute.run import run
from pcabench.machine import memory
from pcabench.spec import RunSpec
from solvers import Scene, SceneError


def test_a_scene_reads_nothing_of_the_machine(monkeypatch):
    def refuse(*args, **kwargs):
        raise AssertionError(f"a Scene read the machine: {args}")

    monkeypatch.setattr(builtins, "open", refuse)
    monkeypatch.setattr(os, "sysconf", refuse)
    monkeypatch.setattr(memory, "available_memory_bytes", refuse)
    scene = Scene(dx=0.01)  # 10M particles: checked against nothing but its own fields
    assert scene.memory_limit() is None and scene.n_particles == 10_000_000
    scene.describe(), scene.as_dict(), scene.replace(dx=0.02)
    with pytest.raises(SceneError, match="2\\^31-1 supported; the smallest dx that fits"):
        Scene(dx=1e-4)  # too many particles for any machine: no memory read to say so
    with pytest.raises(SceneError, match="smallest dx that fits"):
        Scene(dx=0.01, memory_limit_bytes=2**30)  # a stated limit is checked, still without reading


def test_bounded_gives_a_scene_the_memory_available_and_refuses_what_does_not_fit(monkeypatch):
    monkeypatch.setattr(memory, "available_memory_bytes", lambda: 1 << 30)
    assert memory.bounded(Scene(dx=0.1)).memory_limit_bytes == 1 << 30
    assert memory.bounded(Scene(dx=0.1, memory_limit_bytes=2**40)).memory_limit_bytes == 2**40  # its own kept
    with pytest.raises(SceneError, match="dx = 0.01 m needs 10,000,000 particles.*smallest dx that fits"):
        memory.bounded(Scene(dx=0.01))


@pytest.mark.parametrize("command", ["run", "study"])
def test_a_run_that_does_not_fit_is_one_line_before_any_work(command, monkeypatch, capsys, tmp_path):
    monkeypatch.setattr(memory, "available_memory_bytes", lambda: 1 << 30)
    argv = (
        ["run", "--solver", "linkedlist-cpu", "--dx", "0.01"]
        if command == "run"
        else ["study", "--dx", "0.01", "--results", str(tmp_path), "--no-report"]
    )
    with pytest.raises(SystemExit) as exc:
        cli.main(argv)
    err = capsys.readouterr().err
    assert exc.value.code == 2 and len(err.strip().splitlines()) == 1 and "Traceback" not in err, err
    assert "dx = 0.01 m" in err and "smallest dx that fits" in err
    assert not list(tmp_path.iterdir())


# ---------------------------------------------------------------- out-of-memory by type
class FakeCudaAPIError(Exception):
    def __init__(self, code, msg):
        super().__init__(code, msg)
        self.code, self.msg = code, msg


def test_an_out_of_memory_is_recognised_by_type_and_code_not_text(monkeypatch):
    assert memory.is_out_of_memory(MemoryError())
    assert not memory.is_out_of_memory(RuntimeError("CUDA out of memory"))  # the words alone are not enough
    assert not memory.is_out_of_memory(ValueError("outofmemory cudaErrorMemoryAllocation"))
    try:
        try:
            raise MemoryError
        except MemoryError as exc:
            raise RuntimeError("while allocating") from exc
    except RuntimeError as exc:
        assert memory.is_out_of_memory(exc)  # raised from an out-of-memory
    # numba-cuda's driver error, by its code (the module as loaded, never imported here)
    driver = types.ModuleType("numba.cuda.cudadrv.driver")
    driver.CudaAPIError = FakeCudaAPIError
    monkeypatch.setitem(sys.modules, "numba.cuda.cudadrv.driver", driver)
    assert memory.is_out_of_memory(FakeCudaAPIError(2, "CUDA_ERROR_OUT_OF_MEMORY"))
    assert not memory.is_out_of_memory(FakeCudaAPIError(700, "out of memory, in the message only"))
    # CuPy's pool error, by type
    cupy_memory = types.ModuleType("cupy.cuda.memory")
    cupy_memory.OutOfMemoryError = type("OutOfMemoryError", (Exception,), {})
    monkeypatch.setitem(sys.modules, "cupy.cuda.memory", cupy_memory)
    assert memory.is_out_of_memory(cupy_memory.OutOfMemoryError("x"))


def test_no_gpu_module_is_imported_to_recognise_an_out_of_memory(monkeypatch):
    for name in ("cupy.cuda.memory", "cupy_backends.cuda.api.runtime", "numba.cuda.cudadrv.driver"):
        monkeypatch.delitem(sys.modules, name, raising=False)
    real_import = builtins.__import__

    def no_import(name, *args, **kwargs):
        if name.startswith(("cupy", "numba")):
            raise AssertionError(f"imported {name}")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_import)
    assert not memory.is_out_of_memory(RuntimeError("out of memory"))
    assert memory.is_out_of_memory(MemoryError())


def test_a_run_that_runs_out_of_memory_is_recorded_as_such(monkeypatch):
    from solvers.linkedlist_cpu import LinkedListCPU

    def no_memory(self):
        raise MemoryError("Unable to allocate")

    monkeypatch.setattr(LinkedListCPU, "allocate_cells", no_memory)
    record = run(RunSpec("linkedlist-cpu", Scene(dx=1.0, steps=2)))
    assert record.status == "out-of-memory" and "MemoryError" in record.message
