"""A contact interface between parts of the body, or of a part with itself (Radioss
/INTER/TYPE7; ``docs/theory.md``, "Contact between parts").

:class:`ContactInterface` is a force of the step, after the internal force and before the
step size is chosen (its stiffness enters the stable step). Each rank treats the secondary
nodes it owns, against the segments that can reach them; each step it

1. reads x^n, v^{n-1/2} and the masses of the surface nodes it owns from the state, and
   those of its ghosts (the other ranks' nodes of the segments near its secondary nodes)
   from their owners (:class:`~rwall_fem.contact.exchange.Ghosts`, one ``Alltoallv``
   between neighbours);
2. sorts again when some surface node moved more than half the margin since the last sort
   (one ``Allreduce`` of the largest move): every rank sends the segments it owns (those
   of its lowest-numbered node) whose box, widened by the reach and the margin, meets the
   box of another rank's secondary nodes to that rank, and lists its ghosts again; then it
   sorts its secondary nodes' candidate segments (buckets, ``kernels/contact.c``); and
   lists again, within them, the candidates near enough to be met before some node has
   moved a skin (``_list_near``: at each sort, and when some local node has moved half
   the skin since the last list; the same forces with or without);
3. runs its passes (secondary nodes against main segments; two, each side against the
   other, by default) in compiled code over its own secondary nodes, adds the forces on
   its own nodes to a^n, and sends those on its ghosts back to their owners, who add them
   (the same ``Alltoallv`` the other way).

A rank thus holds and exchanges its share of the surface: its secondary nodes, the
segments near them and their nodes. The segments are ordered by their place in the whole
surface, so that each node's candidates come in the same order on any number of ranks: a
node's force from its segments is the same to the bit; the sums of the forces on a segment
node from several ranks, and the books, agree to round-off (``docs/theory.md``, "MPI" of
the contact).

Books (J), like every force's, at mid-step velocities: the work W of the contact forces,
1/2 f^n . (v^{n-1/2} + v^{n+1/2}) dt^n summed over the steps, is split into the work that
friction dissipated, ``contact_friction`` (D, from the slip of each node: -f_t . du_slip),
and the rest, ``contact_energy`` = -W - D, what the penalty springs hold as the scheme books
it; the energy balance then closes to round-off. ``contacts.csv`` also gives the springs'
potential at step n, ``penalty_energy`` (k0 g^2 ((1 - x) ln(1 - x) + x) summed, x = p / g,
plus ``|f_t|^2 / 2 k0``): the two differ by the error of a penalty spring integrated by
central differences, at most about k0 (w dt)^2 / 2 per node that comes into or out of
contact at a normal speed w within a step (the spring is switched on or off between two
steps), and they agree again once the bodies have separated. Each rank books its own
secondary nodes' share; the rows and the summary sum them over the ranks.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from mpi4py import MPI

from rwall_fem.contact.exchange import Ghosts, Owners, send_rows
from rwall_fem.kernels import load

__all__ = ["CONTACT_COLUMNS", "ContactInterface", "Pass"]

# The penetration ratio p / gap beyond which the penalty stiffness stays at k0 / (1 - CAP).
CAP = 0.99
# The skin of the near lists, as a share of the margin: a pass goes through the candidates
# within the reach and the skin of their node, listed again once some node has moved half
# the skin (kernels/contact.c, contact_near).
SKIN = 0.15

CONTACT_COLUMNS = (
    ["time", "contact"]
    + [f"force_{c}" for c in "xyz"]
    + [f"impulse_{c}" for c in "xyz"]
    + ["normal_force", "contacts", "contact_energy", "contact_friction", "penalty_energy"]
)


@dataclass
class Pass:
    """Secondary nodes (indices into the interface's surface nodes, or a rank's local
    nodes) against segments (rows of 4 indices, -1 as the 4th of a triangle) with their
    stiffness k0 (N/m), depth (m) and size share of a variable gap (m, ``kernels/contact.c``
    pair_gap; default inf: none); ``removed``: the nodes each segment leaves out of its search
    (Radioss Irem_gap 2, ``kernels/contact_remove.c``), as offsets (segments + 1) and node
    indices (sorted per segment), or None.
    """

    secondary: np.ndarray
    segments: np.ndarray
    stiffness: np.ndarray
    depth: np.ndarray
    size: np.ndarray | None = None
    removed: tuple[np.ndarray, np.ndarray] | None = None

    def __post_init__(self):
        if self.size is None:
            self.size = np.full(len(self.segments), np.inf)
        self.offsets = np.zeros(len(self.secondary) + 1, dtype=np.int64)
        self.candidates = np.zeros(max(16, 4 * len(self.secondary)), dtype=np.int64)
        self.used = np.zeros(0, dtype=np.int64)  # the segments that are candidates (a sort's)
        self.boxes = np.zeros((len(self.segments), 6))  # their boxes, m (kernels/contact.c)
        self.near_offsets = np.zeros(len(self.secondary) + 1, dtype=np.int64)  # the near
        self.near = np.zeros(0, dtype=np.int64)  # list (contact_near) and the distances
        self.near_distance = np.zeros(0)  # of its candidates then, m
        self.tangential = np.zeros((len(self.secondary), 3))  # friction force, N
        self.gaps = np.full(len(self.secondary), np.inf)  # own gap (m) of a node that started
        # inside the gap, growing back (kernels/contact.c); inf for the others
        self.out = np.zeros(11)


@dataclass
class _Share:
    """This rank's share of a pass, kept from sort to sort: its secondary nodes (global
    numbers, sorted) with their friction force (N) and own gap (m), and the segments it
    owns (global numbers), with their places in the whole pass, stiffness, depth and size
    share; the nodes each segment of the whole pass leaves out (global numbers, CSR as
    :attr:`Pass.removed`; every rank holds all of them) or None."""

    secondary: np.ndarray
    tangential: np.ndarray
    gaps: np.ndarray
    segments: np.ndarray
    places: np.ndarray
    stiffness: np.ndarray
    depth: np.ndarray
    size: np.ndarray
    removed: tuple[np.ndarray, np.ndarray] | None = None


class ContactInterface:
    """The contact ``name`` (``contact[i]``) over the surface nodes ``nodes`` (global
    numbers, sorted) with its ``passes`` (the whole surface's, the same on every rank: the
    rank keeps its share); ``gap`` (m), Coulomb's ``friction`` and the filter's ``alpha``;
    ``margin`` (m) is how far nodes may move between sorts (half of it each).
    ``owned_global`` are the global numbers of this rank's owned nodes (a contiguous
    range), whose rows ``state`` holds. :attr:`passes` are this rank's passes as of the
    latest sort, over its local nodes (its owned surface nodes, then its ghosts)."""

    def __init__(self, name, nodes, passes, *, gap, friction, alpha, margin, state, comm,
                 owned_global, damping=0.05):  # fmt: skip
        self.name, self.comm, self.state = name, comm, state
        self.gap, self.friction, self.alpha, self.margin = gap, friction, alpha, margin
        self.ffi, self.lib = load()
        self.owners = Owners(comm, np.asarray(owned_global, dtype=np.int64))
        self.size = len(nodes)  # surface nodes, over all ranks
        self.ids = np.ascontiguousarray(nodes[self.owners.mine(nodes)], dtype=np.int64)
        self.n = len(self.ids)  # the rank's owned surface nodes: the first local nodes
        self.mine = self.ids - self.owners.start  # their rows of the state
        self._table = np.zeros((self.n, 7))  # x, v, mass of the local nodes (packed, to send)
        self.x, self.v, self.mass = np.zeros((self.n, 3)), np.zeros((self.n, 3)), np.zeros(self.n)
        self._sorted_at = None  # positions of the owned surface nodes at the latest sort
        self._params = self.ffi.new("contact_params *")
        self._params.gap, self._params.cap = gap, CAP
        self._params.gap_max = math.inf
        self._params.friction, self._params.alpha = friction, alpha
        self._params.damping = damping
        self.damping = damping
        self.half_thickness = None  # m per owned surface node (vary_gap)
        self.node_size = None  # m per owned surface node (vary_gap)
        self.mirrored = None  # the owned surface nodes' shares and planes (mirror)
        self.dt_limit = math.inf  # the nodal stable step of the latest pass on this rank, s
        self._element = self.ffi.NULL  # the cells' nodal term of the step (combine_with)
        self._element_array = None
        self.sorts = 0
        self.sent = 0  # bytes this rank sent for the search (sorts); the ghosts count theirs
        self._ghosts = Ghosts(self.owners, np.zeros(0, dtype=np.int64), self.ids)
        self._box_ghosts = self._ghosts
        self._ghost_bytes = 0  # what earlier ghost lists sent
        # The books, of this rank's secondary nodes: stored energies of the latest pass,
        # the friction's dissipation and the impulses so far (J, J, N s), the latest force
        # on the secondary side and normal force sum (N), and the contacts of the latest
        # pass.
        self.energy, self.dissipated = 0.0, 0.0
        self.impulse = [0.0, 0.0, 0.0]  # (lists: a step's few sums without NumPy's calls)
        self.latest = [0.0, 0.0, 0.0]
        self.normal_force, self.contacts = 0.0, 0
        # The work of the forces on this rank's nodes over the finished steps (J); the
        # latest pass's force on them (N) and f . v^{n-1/2} (W), and dt^{n-1/2} (s).
        self.work = 0.0
        self._owned_force = np.zeros((self.n, 3))
        self._first = 0.0
        self._pending = False
        self._previous_dt = 0.0
        p = self._pointer
        self._state = [p(x) for x in (state.X, state.u, state.v, state.mass, state.a)]
        self._rows = p(self.mine, "int64_t[]")
        # What the sweeps before and after the passes find (kernels/contact.c,
        # contact_read: the power of the latest forces, W, and how far the nodes moved since
        # the sort and the near lists, m^2; contact_apply: the power, W, and the step, s).
        self._read_out, self._apply_out = np.zeros(3), np.zeros(2)
        self._read_pointers = (p(self._read_out), p(self._apply_out))
        self.shares: list[_Share] = []
        self.passes: list[Pass] = []  # this rank's, made at each sort
        self._sort_work = np.zeros(0, np.int64)  # contact_sort's scratch
        self.use(passes, nodes)
        self._local(np.zeros(0, dtype=np.int64))
        self.gap_max = gap  # the largest pair gap (vary_gap)
        self.starting_inside = (0, 0, 0.0)  # nodes within the gap at the start, of them
        # behind the surface, and the deepest initial penetration (m)

    def use(self, passes: list[Pass], nodes: np.ndarray) -> None:
        """Take this rank's share of ``passes`` (the whole surface's, over the surface
        nodes ``nodes``, global numbers), keeping the friction force and own gap of each
        secondary node it had; the next step sorts again (collective)."""
        old = dict(enumerate(self.shares))
        self.shares = shares = [self._share(ps, nodes, old.get(k)) for k, ps in enumerate(passes)]
        # The interface-wide figures (the same on every rank).
        self.segments_total = sum(len(ps.segments) for ps in passes)
        k0 = np.concatenate([ps.stiffness for ps in passes])
        self.k0_range = (float(k0.min(initial=np.inf)), float(k0.max(initial=0.0)))
        self.shell_half = max(-float(ps.depth.min(initial=0.0)) for ps in passes)
        self.size_most = max(float(ps.size.max(initial=0.0)) for ps in passes)
        # The segments within this distance of a node compete for it, whatever their own
        # depth, so that the closest (the best aligned) decides; the sort finds them all.
        self.reach = max([self.gap, *(float(ps.depth.max(initial=0.0)) for ps in passes)])
        if self.half_thickness is not None:
            self.reach = max(self.reach, self.gap_max)
        self._params.reach = self.reach
        # The other ranks' nodes of the segments this rank owns: their boxes at a sort.
        ids = np.concatenate([sh.segments.ravel() for sh in shares])
        ids = np.unique(ids[ids >= 0])
        self.sent += self._box_ghosts.sent
        self._box_ghosts = Ghosts(self.owners, ids[~self.owners.mine(ids)], self.ids)
        self._sorted_at = None

    def _share(self, ps: Pass, nodes: np.ndarray, old: _Share | None) -> _Share:
        """This rank's share of pass ``ps`` over the surface nodes ``nodes``; the friction
        state of the nodes ``old`` had."""
        owners = self.owners
        secondary = nodes[ps.secondary]
        mine = owners.mine(secondary)
        secondary = np.ascontiguousarray(secondary[mine], dtype=np.int64)
        tangential, gaps = np.zeros((len(secondary), 3)), np.full(len(secondary), np.inf)
        if old is not None and len(old.secondary) and len(secondary):
            at = np.minimum(np.searchsorted(old.secondary, secondary), len(old.secondary) - 1)
            kept = old.secondary[at] == secondary
            tangential[kept] = old.tangential[at[kept]]
            gaps[kept] = old.gaps[at[kept]]
        segments = np.where(ps.segments >= 0, nodes[np.maximum(ps.segments, 0)], -1)
        lowest = np.where(segments >= 0, segments, np.iinfo(np.int64).max).min(axis=1)
        owned = owners.mine(lowest)
        removed = None
        if ps.removed is not None:
            removed = (ps.removed[0], nodes[ps.removed[1]].astype(np.int64))
        return _Share(secondary, tangential, gaps, segments[owned].astype(np.int64),
                      np.flatnonzero(owned).astype(np.int64), ps.stiffness[owned].copy(),
                      ps.depth[owned].copy(), ps.size[owned].copy(),
                      removed)  # fmt: skip

    def start(self, s) -> None:
        """The gaps of the nodes that start inside the gap (Radioss TYPE7 Inacti = 6,
        ``kernels/contact.c``): each such node's gap is 0.95 of its distance, and grows
        back as it moves away; from the state ``s`` at the start (collective)."""
        self._read(s)
        self._sort()
        out = np.zeros(3)
        inside, behind, deepest = 0, 0, 0.0
        for ps in self.passes:
            p = self._pointer
            self.lib.contact_initial_gaps(
                len(ps.secondary), p(ps.secondary, "int64_t[]"), p(ps.offsets, "int64_t[]"),
                p(ps.candidates, "int64_t[]"), p(ps.segments, "int64_t[]"), p(ps.stiffness),
                p(ps.depth), p(ps.size), self._surface[0], self._params, p(ps.gaps), p(out),
            )  # fmt: skip
            inside, behind = inside + int(out[0]), behind + int(out[1])
            deepest = max(deepest, float(out[2]))
        inside, behind = self.comm.allreduce(np.array([inside, behind]))
        deepest = self.comm.allreduce(deepest, op=MPI.MAX)
        self.starting_inside = (int(inside), int(behind), deepest)

    def vary_gap(self, half_thickness: np.ndarray, size: np.ndarray, nodes: np.ndarray,
                 most: float = math.inf) -> None:  # fmt: skip
        """A variable gap (Radioss Igap 3, ``i7cor3.F``): node s against a segment gets
        ``half_thickness[s]`` plus the segment's half thickness (a shell's: -depth; 0 for a
        solid's face), at most ``size[s]`` plus the segment's size share (the passes' size)
        and ``most`` (m, Radioss Gap_max), at least :attr:`gap` (the floor);
        ``half_thickness`` and ``size`` (m) per surface node ``nodes`` (half its thickest
        shell, %mesh_size x the shortest side of its shells; the rank keeps its owned
        nodes')."""
        rows = np.searchsorted(nodes, self.ids)
        self.half_thickness = np.ascontiguousarray(half_thickness[rows], dtype=np.float64)
        self.node_size = np.ascontiguousarray(size[rows], dtype=np.float64)
        self._params.gap_max = most
        # The largest pair gap (Radioss's GAP, i7sti3.F: min(GAPS_MX + GAPM_MX, GAPS_L_MX
        # + GAPM_L_MX), within the floor and Gap_max)
        pair = float(half_thickness.max(initial=0.0)) + self.shell_half
        sizes = float(size.max(initial=0.0)) + self.size_most
        self.gap_max = max(self.gap, min(pair, sizes, most))
        self.reach = max(self.reach, self.gap_max)
        self._params.reach = self.reach
        self._sorted_at = None

    def mirror(self, share: np.ndarray, planes: np.ndarray, nodes: np.ndarray) -> None:
        """A model cut by symmetry planes (``kernels/contact.c``, mirror): per surface node
        ``nodes``, the share of the whole node it holds and the bits of its planes; the rank
        keeps its owned nodes' and reads its ghosts' shares at each sort."""
        rows = np.searchsorted(nodes, self.ids)
        self.mirrored = (np.ascontiguousarray(share[rows], dtype=np.float64),
                         np.ascontiguousarray(planes[rows], dtype=np.int8))  # fmt: skip
        self._sorted_at = None

    def extent(self, ids: np.ndarray) -> np.ndarray:
        """The extent (m, per axis) of the surface nodes ``ids`` (global numbers) now, from
        every rank (collective)."""
        x = self.x[: self.n][np.isin(self.ids, ids)]
        low, high = x.min(axis=0, initial=np.inf), -x.max(axis=0, initial=-np.inf)
        self.comm.Allreduce(MPI.IN_PLACE, low, op=MPI.MIN)
        self.comm.Allreduce(MPI.IN_PLACE, high, op=MPI.MIN)
        return -high - low

    def _pointer(self, array, kind="double[]"):
        return self.ffi.from_buffer(kind, array)

    def _pass_pointers(self, ps: Pass) -> tuple:
        """The arguments of contact_forces for pass ``ps`` after its number of nodes: its
        near lists (``_list_near``)."""
        p = self._pointer
        x, v, mass, force, stiffness = self._surface[:5]
        return (
            p(ps.secondary, "int64_t[]"), p(ps.near_offsets, "int64_t[]"),
            p(ps.near, "int64_t[]"), p(ps.near_distance), p(ps.segments, "int64_t[]"),
            p(ps.stiffness), p(ps.depth), p(ps.size), x, v, mass,
            self._params, p(ps.tangential), p(ps.gaps), force,
            stiffness, p(ps.out),
        )  # fmt: skip

    def _read(self, s, books: bool = False) -> np.ndarray:
        """x^n, v^{n-1/2} and masses of the owned surface nodes, from the state (one sweep,
        ``contact_read``), and what that sweep finds: the power of the latest pass's forces
        at these velocities (W; with ``books``), and the largest squared distance (m^2) a
        node moved since the latest sort and near lists (if any)."""
        X, u, v, mass, _ = self._state
        null = self.ffi.NULL
        packed = self._packed if self.comm.size > 1 else null  # the table is sent
        sorted_at = null if self._sorted_at is None else self._sorted_pointer
        near_at = null if self._sorted_at is None else self._near_pointer
        self.lib.contact_read(self.n, self._rows, X, u, v, mass, packed, *self._surface[:3],
                              self._surface[5] if books else null, sorted_at, near_at,
                              self._read_pointers[0])  # fmt: skip
        return self._read_out

    def _read_ghosts(self) -> None:
        """x^n, v^{n-1/2} and masses of the ghosts, from their owners."""
        if self.comm.size == 1:  # no ghosts
            return
        g = len(self._ghosts.ids)
        self._ghosts.forward(self._table[: self.n], self._table[self.n :])
        self.lib.contact_unpack(g, self._pointer(self._ghost_rows, "int64_t[]"),
                                self._pointer(self._table[self.n :]), *self._surface[:3])  # fmt: skip

    def _local(self, ghosts: np.ndarray) -> None:
        """The local nodes: the owned surface nodes, then ``ghosts`` (global numbers,
        sorted); new arrays for their values."""
        self._ghost_bytes += self._ghosts.sent
        self._ghosts = Ghosts(self.owners, ghosts, self.ids)
        n = self.n + len(ghosts)
        table = np.zeros((n, 7))
        table[: self.n] = self._table[: self.n]
        self._table = table
        self._packed = self._pointer(self._table)
        self._ghost_rows = np.arange(self.n, n, dtype=np.int64)
        owned = (self.x[: self.n], self.v[: self.n], self.mass[: self.n])
        self.x, self.v, self.mass = np.zeros((n, 3)), np.zeros((n, 3)), np.zeros(n)
        self.x[: self.n], self.v[: self.n], self.mass[: self.n] = owned
        self.force, self.stiffness = np.zeros((n, 3)), np.zeros(n)
        self._surface = [self._pointer(a) for a in (self.x, self.v, self.mass, self.force,
                                                    self.stiffness, self._owned_force)]  # fmt: skip
        self._local_half = np.zeros(n)
        if self.half_thickness is not None:
            self._local_half[: self.n] = self.half_thickness
            self._params.half_thickness = self._pointer(self._local_half)
            self._local_size = np.full(n, np.inf)
            self._local_size[: self.n] = self.node_size
            self._params.node_size = self._pointer(self._local_size)
        if self.mirrored is not None:
            share, planes = self.mirrored
            self._local_share, self._local_planes = np.ones(n), np.zeros(n, dtype=np.int8)
            self._local_share[: self.n], self._local_planes[: self.n] = share, planes
            self._ghosts.forward(share.reshape(-1, 1), self._local_share[self.n :].reshape(-1, 1))
            self._params.share = self._pointer(self._local_share)
            self._params.planes = self._pointer(self._local_planes, "int8_t[]")

    def _to_local(self, ids: np.ndarray) -> np.ndarray:
        """Local indices of global numbers ``ids`` (owned surface nodes or ghosts; -1
        stays -1)."""
        owned = self.owners.mine(ids)
        ghosts = self._ghosts.ids
        at = np.where(owned, np.searchsorted(self.ids, ids),
                      self.n + np.searchsorted(ghosts, ids))  # fmt: skip
        return np.where(ids >= 0, at, -1).astype(np.int64)

    def _boxes(self) -> tuple[np.ndarray, np.ndarray]:
        """The boxes (m, low and high corners per rank) of every rank's secondary nodes now
        (collective)."""
        rows = np.concatenate([np.searchsorted(self.ids, sh.secondary) for sh in self.shares])
        x = self.x[rows]
        box = np.concatenate([x.min(axis=0, initial=np.inf), x.max(axis=0, initial=-np.inf)])
        boxes = np.zeros((self.comm.size, 6))
        self.comm.Allgather(box, boxes)
        self.sent += box.nbytes * (self.comm.size - 1)
        return boxes[:, :3], boxes[:, 3:]

    def _sort(self) -> None:
        """Share the segments near each rank's secondary nodes, list the ghosts, and sort
        the candidates of the rank's secondary nodes (collective)."""
        # The positions of the nodes of the segments this rank owns.
        box = self._box_ghosts
        known = np.zeros((len(box.ids), 7))
        box.forward(self._table[: self.n], known)
        ids = np.concatenate([self.ids, box.ids])
        order = np.argsort(ids)
        x = np.concatenate([self.x[: self.n], known[:, :3]])
        low, high = self._boxes()
        widen = self.reach + self.margin
        rows = []
        for k, sh in enumerate(self.shares):
            corners = np.where(sh.segments >= 0, sh.segments, sh.segments[:, :1])
            corners = x[order[np.searchsorted(ids, corners, sorter=order)]]  # (m, 4, 3)
            a, b = corners.min(axis=1) - widen, corners.max(axis=1) + widen
            near = np.all((a[:, None, :] <= high[None]) & (b[:, None, :] >= low[None]), axis=2)
            seg, rank = np.nonzero(near)
            ints = np.column_stack([np.full(len(seg), k), sh.places[seg], sh.segments[seg]])
            rows.append((np.column_stack([np.ascontiguousarray(ints, dtype=np.int64)
                                          .view(np.float64), sh.stiffness[seg],
                                          sh.depth[seg], sh.size[seg]]), rank))  # fmt: skip
        records = np.concatenate([r for r, _ in rows]) if rows else np.zeros((0, 9))
        ranks = np.concatenate([r for _, r in rows]).astype(np.int64) if rows else np.zeros(0, int)
        received = send_rows(self.comm, records.reshape(-1, 9), ranks)
        self.sent += 9 * 8 * int(np.count_nonzero(ranks != self.comm.rank))
        ints = np.ascontiguousarray(received[:, :6]).view(np.int64)
        # Every node of the segments near this rank's secondary nodes: those of other ranks
        # are its ghosts.
        nodes = ints[:, 2:].ravel()
        nodes = np.unique(nodes[nodes >= 0])
        self._local(nodes[~self.owners.mine(nodes)])
        self._read_ghosts()
        passes = []
        for k, sh in enumerate(self.shares):
            here = np.flatnonzero(ints[:, 0] == k)
            here = here[np.argsort(ints[here, 1])]  # in their order in the whole pass
            ps = Pass(np.searchsorted(self.ids, sh.secondary).astype(np.int64),
                      self._to_local(ints[here, 2:]), received[here, 6].copy(),
                      received[here, 7].copy(), received[here, 8].copy())  # fmt: skip
            ps.tangential, ps.gaps = sh.tangential, sh.gaps
            if k < len(self.passes):  # the previous sort's room for the lists: one bucket
                before = self.passes[k]  # sort, not two
                ps.candidates, ps.near = before.candidates, before.near
                ps.near_distance = before.near_distance
            if sh.removed is not None:
                ps.removed = self._removed_here(sh.removed, ints[here, 1])
            passes.append(ps)
        self.passes = passes
        lib, p = self.lib, self._pointer
        for ps in passes:
            reach = np.full(len(ps.segments), widen)
            removed = ((p(ps.removed[0], "int64_t[]"), p(ps.removed[1], "int64_t[]"))
                       if ps.removed is not None else (self.ffi.NULL, self.ffi.NULL))
            while True:
                size = 2 * len(ps.secondary) + 2 * len(ps.candidates) + 1
                if len(self._sort_work) < size:  # scratch, kept from sort to sort
                    self._sort_work = np.empty(size, np.int64)
                work = self._sort_work
                count = lib.contact_sort(
                    len(ps.secondary), p(ps.secondary, "int64_t[]"), len(ps.segments),
                    p(ps.segments, "int64_t[]"), p(reach), p(self.x),
                    *removed, len(ps.candidates), p(ps.offsets, "int64_t[]"),
                    p(ps.candidates, "int64_t[]"), p(work, "int64_t[]"),
                )  # fmt: skip
                if count <= len(ps.candidates):
                    break
                ps.candidates = np.zeros(2 * count, dtype=np.int64)
            # the segments that are candidates, each once, in order (O(n), no sort)
            ps.used = np.flatnonzero(np.bincount(ps.candidates[:count],
                                                 minlength=len(ps.segments)))
        self._sorted_at = self.x[: self.n].copy()
        self._sorted_pointer = self._pointer(self._sorted_at)
        self.sorts += 1
        self._list_near()

    def _removed_here(self, removed: tuple[np.ndarray, np.ndarray],
                      places: np.ndarray) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
        """The nodes the segments at ``places`` of the whole pass (sorted) leave out
        (``removed``: the whole pass's, global numbers) that are this rank's secondary
        nodes' candidates: its owned ones, as local indices, sorted per segment (CSR)."""
        offsets, ids = removed
        counts = offsets[places + 1] - offsets[places]
        ends = np.cumsum(counts)
        rows = np.arange(int(ends[-1]) if len(ends) else 0) + np.repeat(offsets[places]
                                                                         - ends + counts, counts)
        segment = np.repeat(np.arange(len(places)), counts)
        ids = ids[rows]
        mine = self.owners.mine(ids)
        local = np.searchsorted(self.ids, ids[mine]).astype(np.int64)
        kept = np.bincount(segment[mine], minlength=len(places))
        return (np.concatenate([[0], np.cumsum(kept)]).astype(np.int64),
                np.ascontiguousarray(local))  # fmt: skip

    def _list_near(self) -> None:
        """The near lists of the passes (``contact_near``): the candidates within the
        reach and the skin of their node now, with their distances (this rank's own: the
        passes skip the same candidates with them as without, whenever they are listed)."""
        p, skin = self._pointer, SKIN * self.margin
        limit = 1.000001 * self.reach + skin  # FAR reach (kernels/contact.c) and the skin
        for ps in self.passes:
            if len(ps.near) < len(ps.candidates):
                ps.near = np.zeros(len(ps.candidates), dtype=np.int64)
                ps.near_distance = np.zeros(len(ps.candidates))
            count = self.lib.contact_near(
                len(ps.secondary), p(ps.secondary, "int64_t[]"), p(ps.offsets, "int64_t[]"),
                p(ps.candidates, "int64_t[]"), p(ps.segments, "int64_t[]"), len(ps.used),
                p(ps.used, "int64_t[]"), p(ps.boxes), self._surface[0], limit,
                p(ps.near_offsets, "int64_t[]"), p(ps.near, "int64_t[]"),
                p(ps.near_distance),
            )  # fmt: skip
        self._passes = [self._pass_pointers(ps) for ps in self.passes]
        self._near_at = self.x.copy()  # the local nodes' positions at the lists
        self._near_pointer = self._pointer(self._near_at)
        self._near_moved = (skin / 2.0) ** 2  # m^2: a distance changes by 2 moves at most
        self._params.moved = 0.0

    def _near_stale(self, moved: float) -> bool:
        """Whether some local node moved more than half the skin since the near lists (this
        rank's own test: no exchange), the owned surface nodes' largest squared move (m^2)
        being ``moved`` (``_read``); if not, the passes' bound on the moves (m) is the local
        nodes' largest."""
        g = len(self.x) - self.n  # the ghosts'
        if g and moved <= self._near_moved:
            p = self._pointer
            ghosts = self.lib.contact_moved(g, p(self.x[self.n :]), p(self._near_at[self.n :]))
            moved = ghosts if not ghosts <= moved else moved  # NaN stays
        if not moved <= self._near_moved:
            return True
        self._params.moved = math.sqrt(moved)
        return False

    def _moved(self, moved: float) -> bool:
        """Whether some surface node moved more than half the margin since the latest sort
        (collective), this rank's owned surface nodes' largest squared move (m^2) being
        ``moved`` (``_read``)."""
        if self.comm.size > 1:
            moved = self.comm.allreduce(moved if moved == moved else math.inf, op=MPI.MAX)
            self.sent += 8
        return not moved <= (0.5 * self.margin) ** 2

    def _book_pending(self, dt_v: float, power: float | None = None) -> None:
        """Book the latest pass over its velocity step dt_v (s): its impulse (N s, on the
        secondary side) and its work on this rank's nodes (J), ``power`` (W) being its
        forces' power at v^{n+1/2} (default: at the state's velocities now)."""
        if not self._pending:
            return
        if power is None:
            v = self._pointer(self.state.v)
            power = self.lib.contact_power(self.n, self._rows, self._surface[5], v)
        self.impulse = [i + dt_v * f for i, f in zip(self.impulse, self.latest, strict=True)]
        self.work += 0.5 * dt_v * (self._first + power)
        self._pending = False

    def accelerate(self, s) -> None:
        """Add the contact forces of step n to ``s.a``; note the nodal stable step."""
        power, moved, moved_near = self._read(s, self._pending).tolist()
        if self._pending:  # the previous step's books, now that dt^n and v^{n+1/2} are known
            previous = self._previous_dt
            dt_v = s.dt_previous if previous == 0.0 else 0.5 * (previous + s.dt_previous)
            self._book_pending(dt_v, power)
        if self._sorted_at is None or self._moved(moved):
            self._sort()
        else:
            self._read_ghosts()
            if self._near_stale(moved_near):
                self._list_near()
        self._params.dt = s.dt_previous
        lib = self.lib
        energy, tangential, dissipated, normal, contacts = 0.0, 0.0, 0.0, 0.0, 0
        latest = [0.0, 0.0, 0.0]
        for k, (ps, arguments) in enumerate(zip(self.passes, self._passes, strict=True)):
            lib.contact_forces(len(ps.secondary), *arguments)
            out = ps.out.tolist()
            sign = 1.0 if k == 0 else -1.0  # the force on the secondary side of the first
            latest = [f + sign * g for f, g in zip(latest, out[:3], strict=True)]
            contacts += int(out[6])
            energy += out[7]
            tangential += out[8]
            dissipated += out[9]
            normal += out[10]
        n = self.n
        if self.comm.size > 1:
            # The forces and stiffness on the ghosts, to their owners.
            back = self._ghosts.reverse(np.column_stack([self.force[n:], self.stiffness[n:]]))
            np.add.at(self.force, self._ghosts.rows, back[:, :3])
            np.add.at(self.stiffness, self._ghosts.rows, back[:, 3])
            self.force[n:], self.stiffness[n:] = 0.0, 0.0
        _, _, mass, force, stiffness, kept = self._surface
        _, _, state_v, state_mass, a = self._state
        lib.contact_apply(n, self._rows, force, stiffness, mass, state_mass, state_v, a, kept,
                          self._element, self._read_pointers[1])  # fmt: skip
        self._first, self.dt_limit = self._apply_out.tolist()
        self.energy = energy + tangential
        self.dissipated += dissipated
        self.latest, self.normal_force, self.contacts = latest, normal, contacts
        self._pending = True
        self._previous_dt = s.dt_previous

    def combine_with(self, element: np.ndarray) -> None:
        """Make :attr:`dt_limit` the nodal step of the cells and springs together,
        min sqrt(m / (e + k / 2)) over the nodes with contact stiffness k (N/m), ``element``
        (N/m, a row per node of the state, complete on the owned rows; the body's
        :meth:`~rwall_fem.body.PartedBody.track_nodal_stiffness`, changed in place only)
        giving each node's e = sum_c m_c / dt_e^2 of its cells."""
        self._element_array = element
        self._element = self._pointer(element)

    def nodal_forces(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """What the latest pass added to the accelerations: the state rows of this rank's
        owned surface nodes, the force on each (N, rows of 3), and the segments of every
        pass (rows of 4 global node numbers, -1 as the 4th of a triangle; the same on every
        rank: each rank's own, gathered), for the outputs
        (:mod:`rwall_fem.output.contact_loads`; collective)."""
        mine = np.concatenate([sh.segments for sh in self.shares]).reshape(-1, 4)
        segments = np.concatenate(self.comm.allgather(mine)).reshape(-1, 4)
        return self.mine, self._owned_force, segments

    def energies(self) -> dict[str, float]:
        """This rank's share of the books (J) after the update of step n: -W - D on its
        nodes (W up to the first half of step n, as the kinetic energy K^n has it), D of
        its secondary nodes."""
        # As K^n = 1/2 m v^{n-1/2} . v^{n+1/2} books it: of step n, the first half only.
        work = 0.5 * self.state.dt_velocity * self._first if self._pending else 0.0
        return {
            "contact_energy": -(self.work + work) - self.dissipated,
            "contact_friction": self.dissipated,
        }

    def _totals(self) -> dict:
        """The books summed over the ranks (collective): the latest force on the secondary
        side, the normal force, the contacts, the stored energy, the dissipation and the
        impulse so far (with the latest step's)."""
        dt_v = self.state.dt_velocity
        latest = [dt_v * f if self._pending else 0.0 for f in self.latest]  # its impulse
        impulse = [i + j for i, j in zip(self.impulse, latest, strict=True)]
        local = np.array([*self.latest, self.normal_force, self.contacts, self.energy,
                          self.dissipated, *impulse])  # fmt: skip
        total = self.comm.allreduce(local) if self.comm.size > 1 else local
        return {"latest": total[:3], "normal": float(total[3]), "contacts": int(total[4]),
                "energy": float(total[5]), "dissipated": float(total[6]),
                "impulse": total[7:]}  # fmt: skip

    def row(self, t: float, index: int, energy: float) -> tuple:
        """The row of ``contacts.csv`` at time t (s) after the update of the latest step,
        whose booked contact energy (J, summed over the ranks) is ``energy`` (collective)."""
        b = self._totals()
        return (t, index, *b["latest"].tolist(), *b["impulse"].tolist(), b["normal"],
                b["contacts"], energy, b["dissipated"], b["energy"])  # fmt: skip

    def describe(self) -> str:
        """One line for ``run.log``: the surface, the gap, the stiffness and the friction."""
        inside, behind, deepest = self.starting_inside
        start = (
            f"; {inside} node(s) start inside the gap (the deepest {deepest:.3g} m in, "
            f"{behind} behind the surface): their gap is 0.95 of their distance, growing back "
            "as they leave, those behind inactive until they come out (Radioss Inacti = 6)"
            if inside else ""
        )  # fmt: skip
        return (
            f"{self.name}: {len(self.shares)} pass(es), {self.size} surface nodes, "
            f"{self.segments_total} segments; gap {self.gap:.4g} m, "
            f"k0 {self.k0_range[0]:.4g} to {self.k0_range[1]:.4g} N/m, damping "
            f"{self.damping:g}, friction {self.friction:g}{start}"
        )

    def summary(self) -> dict:
        """What ``summary.json`` says of the interface (the same on every rank; collective):
        ``exchanged_bytes`` is what the ranks sent each other for it over the run."""
        b = self._totals()
        sent = self.sent + self._ghost_bytes + self._ghosts.sent + self._box_ghosts.sent
        return {
            "name": self.name,
            "surface_nodes": self.size,
            "segments": self.segments_total,
            "passes": len(self.shares),
            "gap": self.gap,
            "friction": self.friction,
            "sorts": self.sorts,
            "impulse": b["impulse"].tolist(),
            "penalty_energy": b["energy"],
            "contact_friction": b["dissipated"],
            "exchanged_bytes": int(self.comm.allreduce(sent)) if self.comm.size > 1 else 0,
        }

    def checkpoint_state(self) -> dict[str, np.ndarray]:
        """The friction force and own gap of each pass's secondary nodes, per owned surface
        node (0 and inf off the secondary set: their number does not change when erosion
        changes the passes), the books, and the impulse of the latest step (booked now: its
        velocity step is known after the update)."""
        self._book_pending(self.state.dt_velocity)
        arrays = {}
        for k, sh in enumerate(self.shares):
            rows = np.searchsorted(self.ids, sh.secondary)
            arrays[f"tangential{k}"] = np.zeros((self.n, 3))
            arrays[f"tangential{k}"][rows] = sh.tangential
            arrays[f"gaps{k}"] = np.full(self.n, np.inf)
            arrays[f"gaps{k}"][rows] = sh.gaps
        books = [self.dissipated, *self.impulse, *self.latest, self.normal_force,
                 self.contacts, self.energy, self.work]  # fmt: skip
        return arrays | {"books": np.array(books)}

    def restore_state(self, arrays: dict[str, np.ndarray]) -> None:
        for k, sh in enumerate(self.shares):
            rows = np.searchsorted(self.ids, sh.secondary)
            sh.tangential[:] = arrays[f"tangential{k}"][rows]
            sh.gaps[:] = arrays[f"gaps{k}"][rows]
        books = arrays["books"].tolist()
        self.dissipated = books[0]
        self.impulse[:] = books[1:4]
        self.latest[:] = books[4:7]
        self.normal_force, self.contacts, self.energy = books[7], int(books[8]), books[9]
        self.work = books[10]
        self._pending = False
