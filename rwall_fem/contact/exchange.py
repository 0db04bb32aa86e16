"""The nodes a rank reads from other ranks for its contact passes (its ghosts), and the
forces it hands back to their owners (``docs/theory.md``, "Contact between parts", MPI).

A rank owns the nodes of a contiguous range of global numbers (DOLFINx's index map):
:class:`Owners` finds the owner of any global number from the ranges' starts.
:class:`Ghosts` is one rank's list of ghost nodes (global numbers): built once (two
``Alltoall(v)``: the counts, then the numbers each owner is asked for), it then moves rows
of values (positions, velocities, masses) from the owners to the ranks that read them
(:meth:`Ghosts.forward`), and rows of forces back, summed into the owners' rows
(:meth:`Ghosts.reverse`), each with one ``Alltoallv`` whose counts are 0 for every rank
that is not a neighbour. On one rank there are no ghosts and nothing is exchanged.
"""

from __future__ import annotations

import numpy as np
from mpi4py import MPI

__all__ = ["Ghosts", "Owners", "send_rows"]


class Owners:
    """The owner ranks of global node numbers: ``owned_global`` (this rank's owned nodes'
    global numbers, a contiguous range) from every rank of ``comm`` (collective)."""

    def __init__(self, comm, owned_global: np.ndarray):
        self.comm = comm
        first = int(owned_global[0]) if len(owned_global) else -1
        ranges = comm.allgather((first, len(owned_global)))
        self.starts = np.array([s if n else -1 for s, n in ranges], dtype=np.int64)
        self.counts = np.array([n for _, n in ranges], dtype=np.int64)
        self.start = int(self.starts[comm.rank])
        live = self.counts > 0
        # Ranks without nodes own nothing: they are skipped by the search.
        self._ranks = np.flatnonzero(live)
        self._starts = self.starts[live]
        if np.any(np.diff(self._starts) <= 0):
            order = np.argsort(self._starts)
            self._ranks, self._starts = self._ranks[order], self._starts[order]

    def of(self, ids: np.ndarray) -> np.ndarray:
        """The rank owning each global number of ``ids``."""
        if self.comm.size == 1:
            return np.zeros(len(ids), dtype=np.int64)
        return self._ranks[np.searchsorted(self._starts, ids, side="right") - 1]

    def mine(self, ids: np.ndarray) -> np.ndarray:
        """Whether this rank owns each global number of ``ids``."""
        n = self.counts[self.comm.rank]
        return (ids >= self.start) & (ids < self.start + n)


class Ghosts:
    """The ghost nodes ``ids`` (global numbers, sorted, owned by other ranks) of this rank,
    read from the rows of arrays over the owned nodes ``owned`` (global numbers, sorted)
    of their owners (collective: every rank builds its own at the same time).
    :attr:`rows` are the rows this rank sends, rank after rank; :attr:`sent` counts the
    bytes it sent so far."""

    def __init__(self, owners: Owners, ids: np.ndarray, owned: np.ndarray):
        comm = owners.comm
        self.comm, self.ids = comm, ids
        self.receive_counts = np.bincount(owners.of(ids), minlength=comm.size).astype(np.int64)
        self.send_counts = np.zeros(comm.size, dtype=np.int64)
        asked = np.zeros(0, dtype=np.int64)
        if comm.size > 1:
            comm.Alltoall(self.receive_counts, self.send_counts)
            asked = np.zeros(int(self.send_counts.sum()), dtype=np.int64)
            comm.Alltoallv([np.ascontiguousarray(ids, dtype=np.int64), self.receive_counts],
                           [asked, self.send_counts])  # fmt: skip
        self.rows = np.searchsorted(owned, asked)
        self.sent = 8 * len(ids)

    def forward(self, owned: np.ndarray, ghosts: np.ndarray) -> None:
        """Rows of ``owned`` (values of this rank's owned nodes, float64) into ``ghosts``
        (the rows of :attr:`ids`, C-contiguous, the same number of columns)."""
        if self.comm.size > 1:
            send = np.ascontiguousarray(owned[self.rows])
            _alltoallv(self.comm, send, self.send_counts, ghosts, self.receive_counts)
            self.sent += send.nbytes

    def reverse(self, ghosts: np.ndarray) -> np.ndarray:
        """The rows ``ghosts`` (values on the ghost nodes, C-contiguous float64) at their
        owners: rows matching :attr:`rows` (to be summed into them, rank after rank)."""
        back = np.zeros((len(self.rows), *ghosts.shape[1:]))
        if self.comm.size > 1:
            _alltoallv(self.comm, ghosts, self.receive_counts, back, self.send_counts)
            self.sent += ghosts.nbytes
        return back


def send_rows(comm, rows: np.ndarray, ranks: np.ndarray) -> np.ndarray:
    """The rows ``rows`` (float64, 2-D) sent to ``ranks`` (one per row); the rows this rank
    received, ordered by the sending rank and, from each, in its order (collective)."""
    order = np.argsort(ranks, kind="stable")
    send = np.ascontiguousarray(rows[order])
    send_counts = np.bincount(ranks, minlength=comm.size).astype(np.int64)
    if comm.size == 1:
        return send
    receive_counts = np.zeros(comm.size, dtype=np.int64)
    comm.Alltoall(send_counts, receive_counts)
    received = np.zeros((int(receive_counts.sum()), rows.shape[1]))
    _alltoallv(comm, send, send_counts, received, receive_counts)
    return received


def _alltoallv(comm, send, send_counts, receive, receive_counts) -> None:
    """One ``Alltoallv`` of rows of float64 (counts in rows)."""
    k = int(np.prod(send.shape[1:])) if send.ndim > 1 else 1

    def spec(counts):
        counts = counts * k
        return (counts, np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(np.int64))

    comm.Alltoallv([send, spec(send_counts), MPI.DOUBLE], [receive, spec(receive_counts),
                                                           MPI.DOUBLE])  # fmt: skip
