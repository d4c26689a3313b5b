"""The paper's cell list on the GPU: a counting sort by atomics, with no host round trip.

``cell_count`` finds particleIndex and each particle's rank within its cell
(by atomics), ``cell_begin`` cellBegin (a one-block scan of the counts, which
leaves them at zero again). The solver's ``scatter`` then moves its particle
block into cell order and writes the cells in that order into the other of
the search's two cell arrays, one per particle block. Within a cell the order
is that of the atomics, so sums may differ from run to run in the last bits.
"""

from __future__ import annotations

from solvers.search.celllist import CellList


class DeviceCellList(CellList):
    """particleIndex (``cell``: one array per particle block, ``cells``), ranks, counts and cellBegin on the
    device, built by the solver's kernels (``launch``)."""

    def allocate(self) -> None:
        xp, n = self.xp, self.scene.n_particles
        self.cells = (xp.empty(n, xp.int32), xp.empty(n, xp.int32))
        self.cell = self.cells[0]
        self.rank = xp.empty(n, xp.int32)
        self.order = xp.empty(n, xp.int32)
        self.counts = xp.zeros(self.ncells, xp.int32)  # cell_begin leaves them at zero again
        self.begin = xp.empty(self.ncells + 1, xp.uint32)  # unsigned: no negative-index wraparound per load

    def bin(self, *positions) -> None:
        """particleIndex, ranks and cellBegin in two launches for the particles at ``positions`` (lx, ly, sx, sy;
        in 3D lz and sz too); cellParticleOrder is written by the scatter that follows (:meth:`scatter_arguments`)."""
        from solvers.gpu.cuda_kernels import scan_block

        grid = self.grid.index_arguments(self.scene.dx)
        self.launch("cell_count", *positions, self.cell, self.rank, self.counts, *grid)
        self.launch("cell_begin", self.counts, self.begin, grid=(1, scan_block()))

    def scatter_arguments(self, src, dst, current: int) -> tuple:
        """The ``scatter`` launch's arguments: block ``src`` into cell order in ``dst``, the cells in that
        order into the cell array of block ``1 - current``, cellParticleOrder into ``order``."""
        return self.cell, self.rank, self.begin, src, dst, self.cells[1 - current], self.order

    def use(self, current: int) -> None:
        """The particle block ``current`` is the solver's now: its cells are the search's."""
        self.cell = self.cells[current]

    def count(self, arrays, k) -> int:
        """On a search of its own (the same three launches as SNP), over a copy of the positions scattered
        into its cell order: ``arrays`` and this search untouched."""
        xp, n = self.xp, self.scene.n_particles
        fresh = type(self)(self.scene, self.launch, xp)
        src = xp.stack([arrays[name] for name in self.positions])  # a copy: the kernel may wrap it
        dst = xp.empty_like(src)
        fresh.bin(*src)
        self.launch("scatter", *fresh.scatter_arguments(src, dst, 0))
        fresh.use(1)
        found = xp.zeros(n, xp.int32)
        positions = dict(zip(self.positions, dst))
        self.launch("neighbours", *fresh.arguments(positions), found, k)
        return int(found.astype(xp.int64).sum())
