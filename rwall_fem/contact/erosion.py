"""Contact surfaces that follow erosion: the faces of eroded cells leave the main surface,
the faces they bare join it, and the nodes left on no face leave the secondary set
(``docs/theory.md``, "Contact between parts", erosion). On shells, an eroded shell's
segment leaves, and the nodes left with no live shell leave the secondary set
(:class:`ErodingShells`: a shell bares no face).

:class:`ErodingSurface` keeps the boundary faces of one solid part whose cells may erode:
every face of the rank's cells (:func:`~rwall_fem.contact.surface.cell_faces`, from the
start, as the surface of the start) and the cells alive at its latest update. An update
runs only in the steps after some rank eroded cells (the eroded cells'
:attr:`~rwall_fem.erosion.ErodedCells.detachments`, the same on every rank), vectorised:

1. every rank lists the faces (keys) of its cells that eroded since, to every rank;
2. every rank lists its live cells' faces among them, oriented outward of the live cell
   with that cell's k0 and depth: the faces erosion bared, to every rank;
3. the surface drops the faces of the eroded cells and adds the bared ones, sorted by
   their keys as :func:`~rwall_fem.contact.surface.boundary_faces` sorts them, so that it
   equals the surface of the live cells built from scratch (what a resume does).

:class:`ErodingContact` is a contact interface whose passes are built again after an
update: a pass's secondary nodes are the nodes of its secondary side's faces (a node whose
cells all eroded is on no face), its segments the main side's faces; the friction force of
a node that stays secondary is kept. Its surface nodes are every node of the eroding
parts, so that bared nodes are among them (each rank still reads only the nodes near its
own secondary nodes: :mod:`~rwall_fem.contact.interface`).

The contact acts one step after the erosion (the step's kernel pass erodes; the ranks
learn it when the step is chosen, after the contact forces): Radioss too updates its
interfaces at the cycle after the deletion. A node that sat in a removed face's spring
leaves it with the energy the spring held, which stays in ``contact_energy`` (the work
the contact forces did): the books close to round-off.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from rwall_fem.contact.interface import ContactInterface, Pass
from rwall_fem.contact.surface import (
    Surface,
    boundary_faces,
    cell_faces,
    held_plane_faces,
    once,
    shell_segments,
)

__all__ = ["ErodingContact", "ErodingShells", "ErodingSurface", "may_erode"]


def may_erode(scene, part) -> bool:
    """Whether the cells of ``part`` (a part of the body) may erode in ``scene``: a failure
    criterion, or ``run.dt_min_action = "erode"``."""
    return scene.run.dt_min_action == "erode" or bool(getattr(part.material, "failure", None))


def _rows(key: np.ndarray) -> np.ndarray:
    """The rows of 4 int64 as single values, to compare whole faces."""
    key = np.ascontiguousarray(key, dtype=np.int64)
    return key.view(np.dtype((np.void, 32))).ravel()


def _gather(comm, *arrays: np.ndarray) -> list[np.ndarray]:
    """Each of ``arrays`` from every rank, in the order of the ranks (collective)."""
    pieces = comm.allgather(arrays)
    return [np.concatenate([p[i] for p in pieces]) for i in range(len(arrays))]


class ErodingSurface:
    """The boundary faces of part ``k`` of ``body`` (a :class:`~rwall_fem.body.Body`) as the
    cells of ``force`` (the part's element force in the step, the same cells) erode;
    :attr:`surface`, the same on every rank (collective construction)."""

    def __init__(self, body, k: int, comm, force, held=None):
        self.force, self.comm, self.held = force, comm, held
        self.ids, self.key, self.values = cell_faces(body, k)
        cells = self.force.cells
        self.per = len(self.ids) // max(len(cells), 1)  # faces per cell
        self.alive = np.ones(len(cells), dtype=bool)  # as of the latest update
        self.surface = self._uncut(boundary_faces(self.ids, self.key, self.values, comm))
        to_global = body.V.dofmap.index_map.local_to_global
        mine = np.unique(cells).astype(np.int32)
        self.nodes = np.unique(_gather(comm, to_global(mine).astype(np.int64))[0])

    def _alive_now(self) -> np.ndarray:
        """Per cell, whether it was alive when the ranks last counted the eroded cells
        (not what the latest kernel pass eroded since: the same on every number of ranks
        and after a resume)."""
        e = self.force.erosion
        return self.alive if e is None else e.settled

    def update(self) -> bool:
        """Follow the cells eroded since the latest update; whether the surface changed
        (collective, the same on every rank)."""
        alive = self._alive_now()
        gone = np.repeat(self.alive & ~alive, self.per)
        (eroded,) = _gather(self.comm, self.key[gone])
        if not len(eroded):
            return False
        self.alive = alive.copy()
        eroded = _rows(eroded.reshape(-1, 4))
        live = np.repeat(alive, self.per)
        bare = live & np.isin(_rows(self.key), eroded)
        ids, key, values = _gather(self.comm, self.ids[bare], self.key[bare], self.values[bare])
        s = self.surface
        keep = ~np.isin(_rows(np.sort(s.segments, axis=1)), eroded)
        ids = np.concatenate([s.segments[keep], ids.reshape(-1, 4)])
        values = np.concatenate(
            [np.column_stack([s.stiffness, s.depth, s.edge])[keep], values.reshape(-1, 3)]
        )
        _, first = np.unique(np.sort(ids, axis=1), axis=0, return_index=True)
        self.surface = Surface(ids[first], *values[first].T.copy())
        return True

    def rebuild(self) -> None:
        """The surface of the live cells from scratch (collective): after a resume."""
        self.alive = self._alive_now().copy()
        live = np.repeat(self.alive, self.per)
        self.surface = self._uncut(boundary_faces(self.ids[live], self.key[live],
                                                  self.values[live], self.comm))  # fmt: skip

    def _uncut(self, surface: Surface) -> Surface:
        """``surface`` without its faces on symmetry planes (``held``: the nodes held at
        rest, :func:`~rwall_fem.contact.surface.held_plane_faces`); those of the start are
        :attr:`cut`, the axes of their planes :attr:`axes`. (Erosion bares no such face:
        a face on the plane belongs to one cell from the start.)"""
        if self.held is None:
            return surface
        axis = held_plane_faces(surface, *self.held)
        if not hasattr(self, "cut"):
            self.cut, self.axes = surface.select(axis >= 0), axis[axis >= 0]
        return surface.select(axis < 0)

    @property
    def detachments(self) -> int:
        """The steps in which some rank eroded cells of the part's force, so far."""
        e = self.force.erosion
        return 0 if e is None else e.detachments


class ErodingShells(ErodingSurface):
    """The shells of part ``k`` of ``body`` (a :class:`~rwall_fem.shells.body.ShellBody`)
    as segments (:func:`~rwall_fem.contact.surface.shell_surface`) as the cells of
    ``force`` (the part's shell force in the step) erode: an eroded shell's segment leaves
    the surface, which stays sorted by the segments' keys, equal to the surface of the live
    shells built from scratch."""

    def __init__(self, body, k: int, comm, force):
        self.force, self.comm = force, comm
        self.ids, self.values = shell_segments(body, k)
        self.alive = np.ones(len(self.ids), dtype=bool)  # as of the latest update
        self.surface = once(self.ids, self.values, comm)
        self.nodes = self.surface.nodes

    def update(self) -> bool:
        """Drop the segments of the shells eroded since the latest update; whether the
        surface changed (collective, the same on every rank)."""
        alive = self._alive_now()
        (eroded,) = _gather(self.comm, np.sort(self.ids[self.alive & ~alive], axis=1))
        if not len(eroded):
            return False
        self.alive = alive.copy()
        s = self.surface
        keep = ~np.isin(_rows(np.sort(s.segments, axis=1)), _rows(eroded.reshape(-1, 4)))
        self.surface = Surface(s.segments[keep], s.stiffness[keep], s.depth[keep], s.edge[keep])
        return True

    def rebuild(self) -> None:
        """The segments of the live shells from scratch (collective): after a resume."""
        self.alive = self._alive_now().copy()
        self.surface = once(self.ids[self.alive], self.values[self.alive], self.comm)


class ErodingContact(ContactInterface):
    """A :class:`~rwall_fem.contact.interface.ContactInterface` whose ``surfaces`` (the
    :class:`ErodingSurface` of its eroding parts) follow erosion; ``passes()`` builds its
    passes from the surfaces as they are (the other keyword arguments: the interface's)."""

    def __init__(self, name, nodes, surfaces: list[ErodingSurface],
                 passes: Callable[[], list[Pass]], **interface):  # fmt: skip
        self.surfaces, self._build = surfaces, passes
        self._nodes = nodes
        super().__init__(name, nodes, passes(), **interface)
        self._seen = self._detachments()
        self.updates = 0  # the updates that changed a surface

    def _detachments(self) -> int:
        return max((s.detachments for s in self.surfaces), default=0)

    def _follow(self, rebuild: bool = False) -> None:
        """Build the passes again from the surfaces (updated, or ``rebuild`` from scratch),
        keeping the friction force of each node that stays secondary (collective)."""
        if rebuild:
            for s in self.surfaces:
                s.rebuild()
        elif not any([s.update() for s in self.surfaces]):
            return
        self.use(self._build(), self._nodes)  # sorts again at this step
        self.updates += 1

    def accelerate(self, s) -> None:
        """Follow the erosion of the latest steps, then add the contact forces of step n."""
        seen = self._detachments()
        if seen != self._seen:
            self._seen = seen
            self._follow()
        super().accelerate(s)

    def checkpoint_state(self) -> dict[str, np.ndarray]:
        """The interface's (each pass's friction forces and own gaps per owned surface
        node, whose number erosion does not change), and the updates so far."""
        return super().checkpoint_state() | {"updates": np.array([self.updates])}

    def restore_state(self, arrays: dict[str, np.ndarray]) -> None:
        """The surfaces of the cells alive at the checkpoint, then the interface's state."""
        self._follow(rebuild=True)
        self._seen = self._detachments()
        self.updates = int(arrays["updates"][0])
        super().restore_state(arrays)

    def summary(self) -> dict:
        """The interface's summary, and how often erosion changed its surfaces."""
        return super().summary() | {"surface_updates": self.updates}
