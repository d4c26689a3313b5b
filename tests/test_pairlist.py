"""The CPU pair list: the same physics as the paper's gather loop, each pair once, and a fallback that fits."""

from __future__ import annotations

import numba
import numpy as np
import pytest

from solvers import Scene, make_solver, resolve_pair_loop
from solvers.physics import denormals
from solvers.physics.integrators import evolve
from solvers.search import compress, pairlist

from .conftest import strip_for


def max_rel(a, b):
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))


def stepped(scene, pair_loop, threads=1, steps=None):
    """A linkedlist-cpu solver after ``steps`` Verlet steps (all of the scene's by default)."""
    return evolve(make_solver("linkedlist-cpu", threads=threads, pair_loop=pair_loop), scene, steps or None)


@pytest.mark.parametrize("model,threads", [("lagrangian", 1), ("lagrangian", 2), ("linear", 1)])
def test_list_agrees_with_gather_to_roundoff(tmp_path, model, threads):
    scene = Scene(dx=0.25, x_min=-10, x_max=20, steps=30, model=model, strip_height=strip_for(0.25))
    gather = stepped(scene, "gather").output()
    listed = stepped(scene, "list", threads=threads).output()
    for name in ("u", "drho", "x"):
        assert max_rel(getattr(listed, name), getattr(gather, name)) < 1e-12, name


def test_each_pair_listed_once_with_its_kernel_factor():
    scene = Scene(dx=0.5, x_min=-10, x_max=10, steps=1, strip_height=strip_for(0.5))
    s = stepped(scene, "list", steps=1)
    a, pl = s.arrays, s.pairs
    x = (a["lx"] + 0.5) * scene.dx + a["sx"]
    y = (a["ly"] + 0.5) * scene.dx + a["sy"]
    n, height = scene.n_particles, scene.height
    # every pair within the cutoff by brute force (minimum image in y)
    dx_ = x[:, None] - x[None, :]
    dy_ = y[:, None] - y[None, :]
    dy_ -= height * np.round(dy_ / height)
    r2 = dx_**2 + dy_**2
    inside = (r2 < scene.cutoff**2) & ~np.eye(n, dtype=bool)
    listed = np.zeros((n, n), int)
    for i in range(n):
        for j, fx, fy in zip(*pl.row(i)):
            listed[i, j] += 1
            listed[j, i] += 1
            g = -2 / (np.pi * scene.h**4) * np.exp(-r2[i, j] / scene.h**2)
            assert fx == pytest.approx(g * dx_[i, j], rel=1e-12, abs=1e-18)
            assert fy == pytest.approx(g * dy_[i, j], rel=1e-12, abs=1e-18)
    assert np.array_equal(listed, inside.astype(int))  # each pair once, from one side, and no other


def test_list_grows_when_a_stretch_has_more_pairs_than_room(monkeypatch):
    scene = Scene(dx=0.5, x_min=-10, x_max=10, steps=12, strip_height=strip_for(0.5))
    reference = stepped(scene, "list").output()
    monkeypatch.setattr(pairlist, "capacity", lambda scene: 4)  # far too few: the first build overflows
    small = stepped(scene, "list")
    assert small.pairs.budget > 4
    assert max_rel(small.output().u, reference.u) < 1e-14


def test_cells_sorted_by_x_after_the_search():
    scene = Scene(dx=0.5, x_min=-10, x_max=10, steps=10, strip_height=strip_for(0.5))
    s = stepped(scene, "list")
    a = s.arrays
    x = (a["lx"] + 0.5) * scene.dx + a["sx"]
    for c in range(len(s.nnps.begin) - 1):
        seg = x[s.nnps.begin[c] : s.nnps.begin[c + 1]]
        assert np.all(np.diff(seg) >= 0), c


def test_auto_falls_back_to_gather_where_the_list_does_not_fit():
    scene = Scene(dx=0.1)
    roomy = scene.replace(memory_limit_bytes=scene.memory_bytes() + pairlist.list_bytes(scene))
    tight = scene.replace(memory_limit_bytes=scene.memory_bytes() + pairlist.list_bytes(scene) // 2)
    assert resolve_pair_loop("linkedlist-cpu", roomy) == "list"
    assert resolve_pair_loop("linkedlist-cpu", tight) == "gather"  # the largest scene still runs
    assert resolve_pair_loop("linkedlist-cpu", tight, "list") == "list"  # asked for explicitly
    assert resolve_pair_loop("allpair-cpu", scene) == "all-pairs"


@pytest.mark.skipif(not denormals.X86, reason="flush-to-zero is set only on x86")
def test_float32_loops_flush_subnormals_inside_and_leave_the_process_as_it_was():
    @numba.njit
    def halve(x, flush):  # as the pair loops do it: the flag set around a loop
        saved = denormals.flush_on(flush)
        out = np.empty_like(x)
        for i in range(x.shape[0]):
            out[i] = x[i] * np.float32(0.5)
        denormals.flush_off(flush, saved)
        return out

    tiny = np.full(64, 1e-39, np.float32)  # subnormal in float32
    assert np.all(halve(tiny, True) == 0)  # flushed inside the loop
    assert np.all(halve(tiny, False) > 0)
    scene = Scene(dx=0.5, x_min=-10, x_max=10, steps=3, precision="float32", strip_height=strip_for(0.5))
    stepped(scene, "list", threads=2)
    assert np.all(tiny * np.float32(0.5) > 0)  # numpy, after the float32 loops, still keeps subnormals
    assert np.all(halve(tiny, False) > 0)


def test_float32_list_agrees_with_float64_to_float32_roundoff():
    scene = Scene(dx=0.25, x_min=-10, x_max=20, steps=30, strip_height=strip_for(0.25))
    f64 = stepped(scene, "list").output()
    f32 = stepped(scene.replace(precision="float32"), "list", threads=2).output()
    assert max_rel(f32.u, f64.u) < 1e-4


@numba.njit
def _compress_both(js, rxs, rys, r2s, outs_v, outs_s, nq, limit):
    cj, crx, cry, cr2 = outs_v
    kept_v = compress.compress_vector(js, rxs, rys, r2s, cj, crx, cry, cr2, np.uint64(nq), limit)
    cj, crx, cry, cr2 = outs_s
    kept_s = compress.compress_scalar(js, rxs, rys, r2s, cj, crx, cry, cr2, np.uint64(nq), limit)
    return kept_v, kept_s


@pytest.mark.skipif(
    not compress.VECTOR_COMPRESS,
    reason="the vector compress is built only where numba's LLVM has it "
    "(>= 19) and the core has AVX-512; elsewhere LLVM 22 aborts the process expanding it (measured on "
    "an AMD EPYC without AVX-512), and the build uses the scalar loop",
)
@pytest.mark.parametrize("precision", ["float64", "float32"])
def test_vector_compress_keeps_exactly_the_scalar_loops_entries(precision):
    """The build's vector compress (vcompress, on cores with AVX-512) keeps the same candidates in the same
    order as the scalar loop, for any count and any share kept."""
    rng = np.random.default_rng(7)
    dt = np.dtype(precision).type
    length = 130 + compress.PAD
    for nq in (0, 1, 7, 8, 15, 16, 17, 63, 121, 130):
        for share in (0.0, 0.5, 1.0):
            r2s = rng.random(length).astype(dt)
            r2s[nq:] = -1  # past nq: would be kept if the count were ignored
            rows = (
                np.arange(length, dtype=np.uint32),
                rng.random(length).astype(dt),
                rng.random(length).astype(dt),
                r2s,
            )
            outs_v = tuple(np.full(length, 99, r.dtype) for r in rows)
            outs_s = tuple(np.full(length, 99, r.dtype) for r in rows)
            kept_v, kept_s = _compress_both(*rows, outs_v, outs_s, nq, dt(share))
            expected = int(np.sum(r2s[:nq] < dt(share)))
            assert kept_v == kept_s == expected, (nq, share)
            for v, s_ in zip(outs_v, outs_s):
                np.testing.assert_array_equal(v[:expected], s_[:expected])
