"""3D particles searched on the sites' grid (solvers/search/sites.py): one cell a site and one table of rows for
every particle. The table holds exactly the sites within the cutoff; the runs on it give the all-pair solver's
fields (the cube's seams, open faces, the sphere's body and its PML); moving particles widen the table by twice
their largest displacement and miss no pair."""

from __future__ import annotations

import math

import numpy as np
import pytest

from solvers import Scene
from solvers.physics.integrators import evolve
from solvers.registry import make_solver
from solvers.search.celllist import SiteGrid3D
from solvers.search.sites import TRIM_SLACK, site_rows

CUBE = dict(x_min=-4.0, x_max=4.0, y_min=-4.0, y_max=4.0, z_min=-4.0, z_max=4.0, pulse_width=1.5, pulse_center=1.0)
CUBE.update(kernel="wendland-c2", h_factor=1.3, cfl=0.5, t_end=1.5, model="linear")


@pytest.mark.parametrize("reach", [2.6, 3.0, 6.0, 2.0 * math.sqrt(2.0)])
def test_the_rows_hold_every_site_within_the_cutoff_and_none_beyond_the_slack(reach):
    """Whole-number and irrational reaches (in dx): a site on the sphere itself is in (the sums' own strict test
    drops it); one further than the slack is not; no line is listed twice."""
    dx = 0.25
    rows = site_rows(reach * dx, dx)
    offsets = {(a, int(dy), int(dz)) for dy, dz, m in rows for a in range(-int(m), int(m) + 1)}
    n = int(math.ceil(reach)) + 1
    lattice = [(a, b, c) for a in range(-n, n + 1) for b in range(-n, n + 1) for c in range(-n, n + 1)]
    within = {o for o in lattice if sum(v * v for v in o) <= reach * reach}
    assert within <= offsets
    assert all(sum(v * v for v in o) <= (reach * (1 + TRIM_SLACK)) ** 2 for o in offsets)
    assert len({(dy, dz) for dy, dz, _ in rows}) == len(rows)


def fields_of(solver):
    f = solver.output()
    return {c: getattr(f, c) for c in ("drho", "u", "v", "w")}


@pytest.mark.parametrize("open_faces", [None, "xyz"])
def test_a_linear_run_on_the_sites_grid_gives_the_all_pair_fields(open_faces):
    """The cube with the pulse across every seam, and with open faces (a free x's spare cells, free y and z):
    the same fields as every pair tested (to round-off) and the same neighbour count."""
    faces = {"open": open_faces, "layer_width": 1.0} if open_faces else {}
    scene = Scene(0.5, "acoustic-pulse-3d", **{**CUBE, "t_end": None, "steps": 8}, **faces)
    sites = evolve(make_solver("linkedlist-cpu"), scene)
    assert isinstance(sites.nnps.grid, SiteGrid3D)
    reference = evolve(make_solver("allpair-cpu"), scene)
    assert sites.mean_neighbours() == pytest.approx(reference.mean_neighbours(), abs=0)
    got, ref = fields_of(sites), fields_of(reference)
    assert np.abs(ref["w"]).max() > 1e-4
    for c, values in ref.items():
        assert np.abs(got[c] - values).max() < 1e-10 * np.abs(values).max(), c


@pytest.mark.tier2  # the all-pair solver on 18,432 particles: about 20 s
@pytest.mark.parametrize("model", ["linear", "lagrangian"])
def test_the_sphere_on_the_sites_grid_gives_the_all_pair_fields(model):
    """The sphere's body with cut cells and the PML on six faces, corrected, its particles fixed and moving (Mach
    0.3: displacements of a tenth of dx within three steps): the all-pair solver's fields and neighbours."""
    kw = dict(x_min=-1.0, x_max=2.0, y_min=-1.0, y_max=1.0, z_min=-1.0, z_max=1.0, pulse_center=1.2, layer_width=0.5)
    method = dict(kernel="wendland-c2", h_factor=1.3, correction="gradient", cfl=0.5, boundary_method="cut")
    scene = Scene(0.125, "sphere", steps=3, model=model, mach=0.3, absorber="pml", **method, **kw)
    sites, reference = (evolve(make_solver(name), scene) for name in ("linkedlist-cpu", "allpair-cpu"))
    assert isinstance(sites.nnps.grid, SiteGrid3D)
    assert sites.mean_neighbours() == pytest.approx(reference.mean_neighbours(), abs=0)
    got, ref = fields_of(sites), fields_of(reference)
    assert np.abs(ref["drho"]).max() > 1e-3
    for c, values in ref.items():
        assert np.abs(got[c] - values).max() < 1e-12 * np.abs(values).max(), c


@pytest.mark.parametrize("open_faces", [None, pytest.param("xyz", marks=pytest.mark.tier2)])  # xyz: 8,000 all-pair
def test_moving_particles_widen_the_sites_table_and_give_the_all_pair_fields(open_faces):
    """The Lagrangian cube at Mach 0.3 (particles a third of dx off their sites by the tenth step, the pulse
    across the seams): the table grows with the largest displacement (solvers.search.celllist.CellList.widen)
    and the run keeps the all-pair solver's neighbours and fields (scattered particles, which a table held at the
    cutoff misses pairs of: tests/test_three_d.py)."""
    faces = {"open": open_faces, "layer_width": 1.0} if open_faces else {}
    scene = Scene(0.5, "acoustic-pulse-3d", **{**CUBE, "t_end": None, "steps": 10, "model": "lagrangian"}, mach=0.3,
                  **faces)  # fmt: skip
    sites = evolve(make_solver("linkedlist-cpu"), scene)
    reference = evolve(make_solver("allpair-cpu"), scene)
    a = sites.arrays
    largest = float(np.sqrt(a["sx"] ** 2 + a["sy"] ** 2 + a["sz"] ** 2).max())
    assert largest > 0.25 * scene.dx and sites.nnps.allowance >= largest
    assert sites.mean_neighbours() == pytest.approx(reference.mean_neighbours(), abs=0)
    got, ref = fields_of(sites), fields_of(reference)
    for c, values in ref.items():
        assert np.abs(got[c] - values).max() < 1e-10 * np.abs(values).max(), c
