"""Erosion: the cells of an element force that have failed, and the nodes they leave behind.

The kernels decide which cells fail, in their pass over the cells (``kernels/failure.h``:
damage D = 1 at a point, or with ``run.dt_min_action = "erode"`` a step estimate below
the floor or an inverted cell), book what the cells leave the energy books with, and list
them. :class:`ErodedCells` keeps the result for one
:class:`~rwall_fem.elements.ElementForce` (its own cells): which cells are still alive,
the list of them that the kernels compute from then on (increasing indices: the batches
of consecutive cells keep loading their values as vectors), what every cell has done so
far (plastic and hourglass work, booked when it erodes) and how many live cells hold
each node. A node that no live cell holds any more is *detached*: it keeps its mass and
momentum, flies freely and still meets the walls; its kinetic energy is the eroded
kinetic energy of LS-DYNA's GLSTAT, a part of the kinetic energy.

MPI: each rank erodes its owned cells; the count of live cells per node is summed over the
ranks (the owners hold it) in the steps where some rank eroded a cell.
"""

from __future__ import annotations

import numpy as np
from dolfinx import la

from rwall_fem import _compat

__all__ = ["ErodedCells", "ErodedParts"]


class ErodedCells:
    """The eroded cells of an element force whose owned ``cells`` (rows of local node
    indices, owned and ghost nodes of the space ``V``) the kernels compute."""

    def __init__(self, V, cells: np.ndarray):
        self.cells = cells
        num_cells = len(cells)
        self.alive = np.ones(num_cells, dtype=bool)
        self.live: np.ndarray | None = None  # the live cells, once one has eroded
        self.listed = np.zeros(num_cells, dtype=np.int32)  # the kernels list eroded cells here
        # per cell: plastic work (row 0) and hourglass work (row 1) so far, J
        self.work = np.zeros((2, num_cells))
        self._owned = V.dofmap.index_map.size_local
        self._nodal = la.vector(V.dofmap.index_map, 1)
        self.holding = self._count(np.arange(num_cells))  # live cells of each owned node
        self._pending: list[np.ndarray] = []  # eroded here since the last count
        # The steps in which some rank eroded cells, so far: the same on every rank; and per
        # cell, whether it was alive at the latest count (the contact surfaces follow these,
        # rwall_fem.contact.erosion, whatever the latest kernel pass eroded since).
        self.detachments = 0
        self.settled = np.ones(num_cells, dtype=bool)

    @property
    def count(self) -> int:
        """How many of the owned cells have eroded."""
        return int(len(self.alive) - np.count_nonzero(self.alive))

    @property
    def computed(self) -> int:
        """How many cells the kernels compute: the live ones."""
        return len(self.alive) if self.live is None else len(self.live)

    def _count(self, cells: np.ndarray) -> np.ndarray:
        """How many of ``cells`` (indices of owned cells, on every rank) hold each owned node
        (collective)."""
        nodal = self._nodal.array
        nodal[:] = 0.0
        np.add.at(nodal, self.cells[cells].ravel(), 1.0)
        _compat.scatter_reverse_add(self._nodal)
        return nodal[: self._owned].copy()

    def remove(self, number: int) -> None:
        """Take the ``number`` cells the latest kernel pass listed out of the live ones."""
        eroded = self.listed[:number].copy()
        self.alive[eroded] = False
        self.live = np.flatnonzero(self.alive).astype(np.int32)
        self._pending.append(eroded)

    def detach(self) -> None:
        """Count again the live cells of the nodes, after a step in which some rank eroded
        cells (collective)."""
        eroded = np.concatenate(self._pending) if self._pending else np.zeros(0, np.int32)
        self._pending.clear()
        self.holding -= self._count(eroded)
        self.settled[eroded] = False
        self.detachments += 1

    def checkpoint_state(self) -> dict[str, np.ndarray]:
        """Which cells are alive, their work so far and the live cells of each node."""
        return {"alive": self.alive, "work": self.work, "holding": self.holding}

    def restore_state(self, arrays: dict[str, np.ndarray]) -> None:
        self.alive[:] = arrays["alive"]
        self.work[...] = arrays["work"]
        self.holding[:] = arrays["holding"]
        self.settled[:] = self.alive
        self._pending.clear()
        self.live = None if self.alive.all() else np.flatnonzero(self.alive).astype(np.int32)


class ErodedParts:
    """The eroded cells of a body of parts, over its owned cells: each part's
    :class:`ErodedCells` (the ``forces`` of the parts whose cells may erode have one), read
    through the parts' ``cells`` (local indices of owned cells). ``held`` is, per owned
    node and part, how many of the part's cells hold it (the cells of a part that cannot
    erode hold their nodes for good). A node is detached when no live cell of any part
    holds it."""

    def __init__(self, parts, forces, held: np.ndarray, owned_cells: int):
        self._parts = list(zip((part.cells for part in parts), forces, strict=True))
        self._held = held
        self._owned_cells = owned_cells

    def _eroding(self):
        return [(cells, force.erosion) for cells, force in self._parts if force.erosion]

    @property
    def count(self) -> int:
        """How many of the owned cells have eroded."""
        return sum(e.count for _, e in self._eroding())

    @property
    def alive(self) -> np.ndarray:
        """Per owned cell, whether it is alive."""
        alive = np.ones(self._owned_cells, dtype=bool)
        for cells, e in self._eroding():
            alive[cells] = e.alive
        return alive

    @property
    def detached(self) -> np.ndarray:
        """The owned nodes that no live cell holds any more."""
        holding = np.zeros(len(self._held))
        for k, (_, force) in enumerate(self._parts):
            holding += self._held[:, k] if force.erosion is None else force.erosion.holding
        return np.flatnonzero(holding <= 0.0)

    def kinetic_energy(self, state) -> float:
        """1/2 m |v|^2 (J) of this rank's detached nodes at the velocity of the latest update
        (``state``'s): the eroded kinetic energy, a part of the kinetic energy."""
        nodes = self.detached
        v = state.v[nodes]
        return 0.5 * float(np.sum(state.mass[nodes] * np.einsum("ij,ij->i", v, v)))

    def largest_damage(self) -> float | None:
        """The largest damage of a live cell's point (this rank), None when no part has a
        failure criterion."""
        damaged = [(f.damage, f.erosion) for _, f in self._parts if f.failure is not None]
        if not damaged:
            return None
        return max(
            float(damage[:, e.alive].max(initial=0.0) if e else damage.max(initial=0.0))
            for damage, e in damaged
        )


class ErodingBody:
    """The erosion controls a body shares (:class:`~rwall_fem.body.Body`, shell bodies):
    over its ``elements`` (the parts' element forces), renaming its energies
    (``_name_energies``) when what may erode changes."""

    def erode_below(self, floor: float) -> None:
        """From now on, erode the cells of every part whose step estimate falls below
        ``floor`` (s), and inverted ones (``run.dt_min_action = "erode"``; collective)."""
        for force in self.elements:
            force.erode_below(floor)
        self._name_energies()

    def detach_nodes(self) -> None:
        """Count the live cells of the nodes again after a step in which some rank eroded
        cells (collective)."""
        for force in self.elements:
            if force.erosion is not None:
                force.detach_nodes()
