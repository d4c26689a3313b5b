"""numba's thread count is set where a solver decides it (input), not on every launch, and a launch
still runs on its solver's count when solvers with different counts alternate in one process."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import textwrap

import numba
import pytest

from solvers import Scene
from solvers.linkedlist_cpu import LinkedListCPU

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def steps(solver, n=2):
    for _ in range(n):
        solver.snp()
        solver.rates(True, True)
        solver.kick(0.5)
        solver.advance(1.0)


@pytest.mark.parametrize("pair_loop", ["list", "gather"])
def test_numba_threads_are_set_at_input_not_on_every_launch(pair_loop, monkeypatch):
    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("numba has one thread here")
    calls = []
    real = numba.set_num_threads
    monkeypatch.setattr(numba, "set_num_threads", lambda n: (calls.append(n), real(n)))
    solver = LinkedListCPU(threads=2, pair_loop=pair_loop)
    solver.input(Scene(dx=1.0, steps=2))
    assert calls == [2]  # where the count is decided
    solver.init()
    steps(solver, 3)
    solver.mean_neighbours()
    assert calls == [2] and numba.get_num_threads() == 2  # dozens of launches, no further call


SCRIPT = textwrap.dedent("""
    import json
    import numba, numpy as np
    from solvers import Scene
    from solvers.boundaries import across
    from solvers.linkedlist_cpu import LinkedListCPU, sweeps

    @numba.njit(parallel=True)
    def probe(out):  # each iteration records the thread count of the parallel region it runs in
        for i in numba.prange(out.shape[0]):
            out[i] = numba.get_num_threads()

    calls = []
    real = numba.set_num_threads
    numba.set_num_threads = lambda n: (calls.append(n), real(n))
    scene = Scene(dx=1.0, steps=2)
    solvers = {n: LinkedListCPU(threads=n, pair_loop=loop) for n, loop in ((2, "list"), (3, "gather"))}
    for s in solvers.values():
        s.input(scene)
        s.init()
        sweeps(scene.precision, scene.kernel, True, across(scene), scene.dims, s.displaced)["probe"] = probe
    seen = []
    for _ in range(3):
        for n, s in solvers.items():
            s.snp(); s.rates(True, True); s.kick(0.5); s.advance(1.0)  # the solver's own launches
            out = np.zeros(256, np.int64)
            s.launch("probe", out)
            seen.append((n, sorted(set(out.tolist()))))
    print(json.dumps({"seen": seen, "calls": calls}))
""")


def test_alternating_solvers_each_launch_on_their_own_thread_count():
    env = dict(os.environ, NUMBA_NUM_THREADS="4", PYTHONPATH=ROOT)
    proc = subprocess.run(
        [sys.executable, "-c", SCRIPT], capture_output=True, text=True, env=env, timeout=600, cwd=ROOT
    )
    assert proc.returncode == 0, proc.stderr
    out = json.loads(proc.stdout.strip().splitlines()[-1])
    seen, calls = out["seen"], out["calls"]
    assert all(counts == [n] for n, counts in seen), seen  # every launch on its solver's count
    # set at each input, then once per switch between the two solvers: not once per launch
    assert calls == [2, 3] + [2, 3] * 3, calls
