"""Units of the solvers that break first: the constant layout, the stencil at the periodic seam,
the counting sort, and the step programs. In-process and small."""

from __future__ import annotations

import math

import numpy as np
import pytest

from solvers import Scene
from solvers.kernels import constants as kernel
from solvers.physics.backend import cpu_pairs, cpu_sorting
from solvers.physics.integrators import step_program


def test_each_named_slot_holds_what_the_pair_code_reads():
    scene = Scene(dx=0.5, model="lagrangian")
    k = kernel.constants(scene, np.float64)
    assert len(k) == kernel.SLOTS
    h = scene.h
    assert k[kernel.SPACING] == scene.dx and k[kernel.NY] == scene.ny
    assert k[kernel.INV_H2] == pytest.approx(1 / h**2) and k[kernel.RC2] == pytest.approx(scene.cutoff**2)
    assert k[kernel.GRAD0] == pytest.approx(-2 / (math.pi * h**4))
    assert (k[kernel.RHO0], k[kernel.C0SQ], k[kernel.NONLIN], k[kernel.ZERO]) == (1.0, 1.0, 1.0, 0.0)
    assert kernel.constants(scene.replace(model="linear"), np.float64)[kernel.NONLIN] == 0.0
    assert all(type(v) is np.float32 for v in kernel.constants(scene, np.float32))


def test_the_pair_code_reads_the_slots_it_names():
    """One pair at distance r: the continuity term is vol_j (u_i - u_j) . r G(r) with G from the named slots."""
    scene = Scene(dx=1.0)
    k = kernel.constants(scene, np.float64)
    P = cpu_pairs("float64")
    lx, ly = np.array([0.0, 1.0]), np.array([0.0, 0.0])
    sx, sy = np.array([0.0, 0.25]), np.zeros(2)
    u, v, vol = np.array([0.3, 0.1]), np.zeros(2), np.array([2.0, 3.0])
    rx = -1.25  # x_0 - x_1
    g = -2 / (math.pi * scene.h**4) * math.exp(-(rx**2) / scene.h**2)
    got = P.continuity_range(1, 2, lx[0], ly[0], sx[0], sy[0], u[0], v[0], lx, ly, sx, sy, u, v, vol, k)
    assert got == pytest.approx(vol[1] * g * (u[0] - u[1]) * rx, rel=1e-13)
    far = np.array([0.0, 100.0])  # beyond the cutoff: nothing
    assert P.continuity_range(1, 2, lx[0], ly[0], sx[0], sy[0], u[0], v[0], far, ly, sx, sy, u, v, vol, k) == 0.0


def test_the_stencil_row_across_the_periodic_seam_shifts_i_by_ny_rows():
    scene = Scene(dx=1.0)
    k = kernel.constants(scene, np.float64)
    P = cpu_pairs("float64")
    ncx, ncy = 5, 4
    begin = np.arange(ncx * ncy + 1, dtype=np.uint32) * 2  # two particles per cell
    cell = np.array([0 * ncx + 2], np.int32)  # a particle in the bottom row, middle column
    ly, lx = np.array([3.0]), np.array([7.0])
    j0, j1, lyi, q0, q1, _ = P.stencil_row(0, -1, cell, begin, ncx, ncy, ly, lx, k)  # the row below: the top
    assert (j0, j1) == (begin[3 * ncx + 1], begin[3 * ncx + 4]) and lyi == 3.0 + scene.ny and q0 == q1
    j0, j1, lyi, q0, q1, _ = P.stencil_row(0, 1, cell, begin, ncx, ncy, ly, lx, k)
    assert (j0, j1) == (begin[1 * ncx + 1], begin[1 * ncx + 4]) and lyi == 3.0 and q0 == q1
    top = np.array([(ncy - 1) * ncx + 0], np.int32)  # top row, left edge: the row above is row 0, no column -1
    j0, j1, lyi, q0, q1, _ = P.stencil_row(0, 1, top, begin, ncx, ncy, ly, lx, k)
    assert (j0, j1) == (begin[0], begin[2]) and lyi == 3.0 - scene.ny and q0 == q1  # free x edges: no wrap


def test_the_stencil_row_across_the_x_seam_shifts_i_by_nx_columns():
    """A scene periodic in x: the left column's stencil reaches the row's last cell, i shifted right by nx."""
    scene = Scene(dx=1.0, name="acoustic-pulse")
    k = kernel.constants(scene, np.float64)
    assert k[kernel.NX] == scene.nx
    P = cpu_pairs("float64")
    ncx, ncy = 5, 4
    begin = np.arange(ncx * ncy + 1, dtype=np.uint32) * 2
    ly, lx = np.array([3.0]), np.array([0.0])
    left = np.array([1 * ncx + 0], np.int32)
    j0, j1, lyi, q0, q1, lxq = P.stencil_row(0, 0, left, begin, ncx, ncy, ly, lx, k)
    assert (j0, j1) == (begin[ncx], begin[ncx + 2]) and (q0, q1) == (begin[2 * ncx - 1], begin[2 * ncx])
    assert lxq == 0.0 + scene.nx and lyi == 3.0
    right = np.array([1 * ncx + ncx - 1], np.int32)
    j0, j1, lyi, q0, q1, lxq = P.stencil_row(0, 0, right, begin, ncx, ncy, ly, lx, k)
    assert (j0, j1) == (begin[2 * ncx - 2], begin[2 * ncx]) and (q0, q1) == (begin[ncx], begin[ncx + 1])
    assert lxq == 0.0 - scene.nx


def test_counting_sort_is_a_stable_sort_with_cell_begin():
    rng = np.random.default_rng(1)
    ncells = 7
    cell = rng.integers(0, ncells, 200).astype(np.int32)
    begin = np.zeros(ncells + 1, np.uint32)
    order = np.empty(200, np.int64)
    sorted_cell = np.empty(200, np.int32)
    cpu_sorting().counting_sort(cell, ncells, begin, order, sorted_cell)
    assert np.array_equal(order, np.argsort(cell, kind="stable"))
    assert np.array_equal(sorted_cell, np.sort(cell))
    assert np.array_equal(begin, np.concatenate([[0], np.cumsum(np.bincount(cell, minlength=ncells))]))


class Recorder:
    """A stand-in solver that records which primitives a step program calls."""

    def __init__(self):
        self.calls = []

    def snp(self):
        self.calls.append("snp")

    def rates(self, continuity, momentum):
        self.calls.append({(True, False): "cont", (False, True): "mom", (True, True): "both"}[(continuity, momentum)])

    def kick(self, f):
        self.calls.append(f"kick{f:g}")

    def advance(self, f):
        self.calls.append(f"advance{f:g}")

    def save(self):
        self.calls.append("save")

    def restore(self, names):
        self.calls.append("restore")


def run_program(integrator, first):
    s = Recorder()
    program = step_program(integrator, s, first)
    for _, op in program:
        op()
    return [stage for stage, _ in program], s.calls


def test_verlet_primes_only_on_the_first_step_and_sweeps_once_each_way():
    stages, first = run_program("verlet", True)
    _, later = run_program("verlet", False)
    assert first[:2] == ["snp", "mom"] and first[2:] == later
    assert later == ["kick0.5", "cont", "advance1", "snp", "mom", "kick0.5"]
    assert stages.count("pi") == 3 and stages.count("snp") == 2


@pytest.mark.parametrize("integrator,sweeps", [("kdk1", ["both"]), ("euler", ["both"]), ("rk2", ["both", "both"])])
def test_other_programs_sweep_both_rates(integrator, sweeps):
    _, later = run_program(integrator, False)
    assert [c for c in later if c in ("cont", "mom", "both")] == sweeps
    assert later.count("snp") == len(sweeps)  # a search before every sweep at new positions
