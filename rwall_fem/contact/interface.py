"""A contact interface between parts of the body, or of a part with itself (Radioss
/INTER/TYPE7; ``docs/theory.md``, "Contact between parts").

:class:`ContactInterface` is a force of the step, after the internal force and before the
step size is chosen (its stiffness enters the stable step). Each step it

1. gathers the positions x^n, velocities v^{n-1/2} and masses of the interface's surface
   nodes from every rank (one ``Allgatherv``), in the order of their global numbers;
2. sorts the secondary nodes' candidate segments again (buckets, ``kernels/contact.c``)
   when some node moved more than half the margin since the last sort;
3. runs its passes (secondary nodes against main segments; two, each side against the
   other, by default) in compiled code, on every rank alike: each rank then adds the forces
   of its own nodes to a^n. The global numbers depend on the partition, and so does the
   element forces' round-off: the forces agree to round-off on any number of ranks since
   they are continuous in the nodal state (``docs/theory.md``, "MPI" of the contact); the
   price is that every rank treats the whole contact surface (fine up to some 10^5 surface
   nodes; a partitioned search is for later).

Books (J), like every force's, at mid-step velocities: the work W of the contact forces,
1/2 f^n . (v^{n-1/2} + v^{n+1/2}) dt^n summed over the steps, is split into the work that
friction dissipated, ``contact_friction`` (D, from the slip of each node: -f_t . du_slip),
and the rest, ``contact_energy`` = -W - D, what the penalty springs hold as the scheme books
it; the energy balance then closes to round-off. ``contacts.csv`` also gives the springs'
potential at step n, ``penalty_energy`` (k0 g^2 ((1 - x) ln(1 - x) + x) summed, x = p / g,
plus ``|f_t|^2 / 2 k0``): the two differ by the error of a penalty spring integrated by
central differences, at most about k0 (w dt)^2 / 2 per node that comes into or out of
contact at a normal speed w within a step (the spring is switched on or off between two
steps), and they agree again once the bodies have separated.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rwall_fem.kernels import load

__all__ = ["CONTACT_COLUMNS", "ContactInterface", "Pass"]

# The penetration ratio p / gap beyond which the penalty stiffness stays at k0 / (1 - CAP).
CAP = 0.99

CONTACT_COLUMNS = (
    ["time", "contact"]
    + [f"force_{c}" for c in "xyz"]
    + [f"impulse_{c}" for c in "xyz"]
    + ["normal_force", "contacts", "contact_energy", "contact_friction", "penalty_energy"]
)


@dataclass
class Pass:
    """Secondary nodes (indices into the interface's surface nodes) against segments
    (rows of 4 indices, -1 as the 4th of a triangle) with their stiffness k0 (N/m) and
    depth (m); ``exclude``: a node is kept off its own segments' neighbours (self-contact).
    """

    secondary: np.ndarray
    segments: np.ndarray
    stiffness: np.ndarray
    depth: np.ndarray
    exclude: bool = False

    def __post_init__(self):
        # The segments of each surface node (CSR), for the exclusion of neighbours.
        nodes = self.segments.ravel()
        seg = np.repeat(np.arange(len(self.segments), dtype=np.int64), 4)
        valid = nodes >= 0
        nodes, seg = nodes[valid], seg[valid]
        order = np.argsort(nodes, kind="stable")
        self.node_segs = np.ascontiguousarray(seg[order])
        size = int(max(nodes.max(initial=-1), self.secondary.max(initial=-1))) + 2
        self.node_offsets = np.zeros(size, dtype=np.int64)
        np.add.at(self.node_offsets, nodes + 1, 1)
        self.node_offsets = np.cumsum(self.node_offsets)
        self.offsets = np.zeros(len(self.secondary) + 1, dtype=np.int64)
        self.candidates = np.zeros(max(16, 4 * len(self.secondary)), dtype=np.int64)
        self.tangential = np.zeros((len(self.secondary), 3))  # friction force, N
        self.gaps = np.full(len(self.secondary), np.inf)  # own gap (m) of a node that started
        # inside the gap, growing back (kernels/contact.c); inf for the others
        self.out = np.zeros(11)


class ContactInterface:
    """The contact ``name`` (``contact[i]``) over the surface nodes ``nodes`` (global
    numbers, sorted) with its ``passes``; ``gap`` (m), Coulomb's ``friction`` and the
    filter's ``alpha``; ``margin`` (m) is how far nodes may move between sorts (half of it
    each). ``owned_global`` are the global numbers of this rank's owned nodes, whose rows
    ``state`` holds."""

    def __init__(self, name, nodes, passes, *, gap, friction, alpha, margin, state, comm,
                 owned_global, damping=0.05):  # fmt: skip
        self.name, self.passes, self.comm, self.state = name, passes, comm, state
        self.gap, self.friction, self.alpha, self.margin = gap, friction, alpha, margin
        self.ffi, self.lib = load()
        n = len(nodes)
        self.size, self.nodes = n, nodes
        position = np.searchsorted(nodes, owned_global)
        position = np.minimum(position, max(n - 1, 0))
        hit = (nodes[position] == owned_global) if n else np.zeros(len(owned_global), bool)
        self.mine = np.flatnonzero(hit)  # owned rows of the state on the surface
        self.where = position[self.mine]  # their surface indices
        pieces = comm.allgather(self.where)
        self.counts = np.array([len(p) for p in pieces])
        self.order = np.concatenate(pieces) if pieces else np.zeros(0, np.int64)
        self._send = np.zeros((len(self.mine), 7))
        self._receive = np.zeros((n, 7))
        self.x, self.v, self.mass = np.zeros((n, 3)), np.zeros((n, 3)), np.zeros(n)
        self.force = np.zeros((n, 3))
        self.stiffness = np.zeros(n)
        self._sorted_at = None  # positions of the latest sort
        self._params = self.ffi.new("contact_params *")
        self._params.gap, self._params.cap = gap, CAP
        self._params.friction, self._params.alpha = friction, alpha
        self._params.damping = damping
        # The segments within this distance of a node compete for it, whatever their own
        # depth, so that the closest (the best aligned) decides; the sort finds them all.
        self.reach = max([gap, *(float(ps.depth.max(initial=0.0)) for ps in passes)])
        self._params.reach = self.reach
        self.damping = damping
        self.dt_limit = math.inf  # the nodal stable step of the latest pass, s
        self.sorts = 0
        # The books: stored energies of the latest pass, the friction's dissipation and the
        # impulses so far (J, J, N s), the latest force on the secondary side and normal
        # force sum (N), and the contacts of the latest pass.
        self.energy, self.dissipated = 0.0, 0.0
        self.impulse = np.zeros(3)
        self.latest = np.zeros(3)
        self.normal_force, self.contacts = 0.0, 0
        # The work of the forces on this rank's nodes over the finished steps (J); the
        # latest pass's force on them (N) and f . v^{n-1/2} (W), and dt^{n-1/2} (s).
        self.work = 0.0
        self._owned_force = np.zeros((len(self.mine), 3))
        self._first = 0.0
        self._pending = False
        self._previous_dt = 0.0
        # Pointers for the compiled passes (the state's arrays never move).
        p = self._pointer
        self.mine, self.where = self.mine.astype(np.int64), self.where.astype(np.int64)
        self.order = self.order.astype(np.int64)
        self._state = [p(x) for x in (state.X, state.u, state.v, state.mass, state.a)]
        self._rows = (p(self.mine, "int64_t[]"), p(self.where, "int64_t[]"),
                      p(self.order, "int64_t[]"))  # fmt: skip
        self._surface = [p(x) for x in (self.x, self.v, self.mass, self.force, self.stiffness,
                                        self._send, self._receive, self._owned_force)]  # fmt: skip
        self._passes = [self._pass_pointers(ps) for ps in passes]
        self.gap_max = gap  # the largest pair gap (vary_gap)
        self.starting_inside = (0, 0, 0.0)  # nodes within the gap at the start, of them
        # behind the surface, and the deepest initial penetration (m)

    def start(self, s) -> None:
        """The gaps of the nodes that start inside the gap (Radioss TYPE7 Inacti = 6,
        ``kernels/contact.c``): each such node's gap is 0.95 of its distance, and grows
        back as it moves away; from the state ``s`` at the start."""
        self._gather(s)
        self._sort()
        out = np.zeros(3)
        inside, behind, deepest = 0, 0, 0.0
        for ps in self.passes:
            p = self._pointer
            self.lib.contact_initial_gaps(
                len(ps.secondary), p(ps.secondary, "int64_t[]"), p(ps.offsets, "int64_t[]"),
                p(ps.candidates, "int64_t[]"), p(ps.segments, "int64_t[]"), p(ps.stiffness),
                p(ps.depth), self._surface[0], self._params, p(ps.gaps), p(out),
            )  # fmt: skip
            inside, behind = inside + int(out[0]), behind + int(out[1])
            deepest = max(deepest, float(out[2]))
        self.starting_inside = (inside, behind, deepest)

    def vary_gap(self, half_thickness: np.ndarray) -> None:
        """A variable gap (Radioss Igap 1): node s against a segment gets the larger of
        :attr:`gap` (the floor) and ``half_thickness[s]`` plus the segment's half thickness
        (a shell's: -depth; 0 for a solid's face); ``half_thickness`` (m) per surface node
        (half its thickest shell)."""
        self.half_thickness = np.ascontiguousarray(half_thickness, dtype=np.float64)
        self._params.half_thickness = self._pointer(self.half_thickness)
        shells = [-ps.depth.min(initial=0.0) for ps in self.passes]
        self.gap_max = max(self.gap, float(self.half_thickness.max(initial=0.0)) + max(shells))
        self.reach = max(self.reach, self.gap_max)
        self._params.reach = self.reach

    def _pointer(self, array, kind="double[]"):
        return self.ffi.from_buffer(kind, array)

    def _pass_pointers(self, ps: Pass) -> tuple:
        """The arguments of contact_forces for pass ``ps`` after its number of nodes."""
        p = self._pointer
        x, v, mass, force, stiffness = self._surface[:5]
        return (
            p(ps.secondary, "int64_t[]"), p(ps.offsets, "int64_t[]"),
            p(ps.candidates, "int64_t[]"), p(ps.segments, "int64_t[]"), p(ps.stiffness),
            p(ps.depth), x, v, mass, self._params, p(ps.tangential), p(ps.gaps), force,
            stiffness, p(ps.out),
        )  # fmt: skip

    def _gather(self, s) -> None:
        """x^n, v^{n-1/2} and masses of the surface nodes, from every rank."""
        X, u, v, mass, _ = self._state
        mine, _, order = self._rows
        send, receive = self._surface[5:7]
        self.lib.contact_pack(len(self.mine), mine, X, u, v, mass, send)
        if self.comm.size > 1:
            self.comm.Allgatherv(self._send, [self._receive, self.counts * 7])
            send = receive
        x, v, mass = self._surface[:3]
        self.lib.contact_unpack(self.size, order, send, x, v, mass)

    def _sort(self) -> None:
        lib, p = self.lib, self._pointer
        for ps in self.passes:
            reach = np.full(len(ps.segments), self.reach + self.margin)
            while True:
                work = np.zeros(2 * len(ps.secondary) + 2 * len(ps.candidates) + 1, np.int64)
                count = lib.contact_sort(
                    len(ps.secondary), p(ps.secondary, "int64_t[]"), len(ps.segments),
                    p(ps.segments, "int64_t[]"), p(reach), p(self.x), int(ps.exclude),
                    p(ps.node_offsets, "int64_t[]"), p(ps.node_segs, "int64_t[]"),
                    len(ps.candidates), p(ps.offsets, "int64_t[]"),
                    p(ps.candidates, "int64_t[]"), p(work, "int64_t[]"),
                )  # fmt: skip
                if count <= len(ps.candidates):
                    break
                ps.candidates = np.zeros(2 * count, dtype=np.int64)
        self._passes = [self._pass_pointers(ps) for ps in self.passes]
        self._sorted_at = self.x.copy()
        self._sorted_pointer = self._pointer(self._sorted_at)
        self.sorts += 1

    def _pending_books(self, dt_v: float, v: np.ndarray) -> tuple[np.ndarray, float]:
        """The impulse (N s, on the secondary side) and the work on this rank's nodes (J)
        of the latest pass over its velocity step dt_v (s), v^{n+1/2} being ``v``."""
        if not self._pending:
            return np.zeros(3), 0.0
        v = self._pointer(v)
        second = self.lib.contact_power(len(self.mine), self._rows[0], self._surface[7], v)
        return dt_v * self.latest, 0.5 * dt_v * (self._first + second)

    def _book_pending(self, dt_v: float, v: np.ndarray) -> None:
        impulse, work = self._pending_books(dt_v, v)
        self.impulse += impulse
        self.work += work
        self._pending = False

    def accelerate(self, s) -> None:
        """Add the contact forces of step n to ``s.a``; note the nodal stable step."""
        if self._pending:  # the previous step's books, now that dt^n and v^{n+1/2} are known
            previous = self._previous_dt
            dt_v = s.dt_previous if previous == 0.0 else 0.5 * (previous + s.dt_previous)
            self._book_pending(dt_v, s.v)
        self._gather(s)
        if self._sorted_at is None:
            self._sort()
        else:
            moved = self.lib.contact_moved(self.size, self._surface[0], self._sorted_pointer)
            if not moved <= (0.5 * self.margin) ** 2:
                self._sort()
        self.force[:] = 0.0
        self._params.dt = s.dt_previous
        lib = self.lib
        energy, tangential, dissipated, normal, contacts = 0.0, 0.0, 0.0, 0.0, 0
        latest = np.zeros(3)
        for k, (ps, arguments) in enumerate(zip(self.passes, self._passes, strict=True)):
            lib.contact_forces(len(ps.secondary), *arguments)
            out = ps.out
            latest += out[:3] if k == 0 else -out[:3]
            contacts += int(out[6])
            energy += out[7]
            tangential += out[8]
            dissipated += out[9]
            normal += out[10]
        x, v, mass, force, stiffness = self._surface[:5]
        self.dt_limit = lib.contact_step(self.size, mass, stiffness)
        _, _, state_v, state_mass, a = self._state
        mine, where, _ = self._rows
        self._first = lib.contact_apply(len(self.mine), mine, where, force, state_mass, state_v,
                                        a, self._surface[7])  # fmt: skip
        self.energy = energy + tangential
        self.dissipated += dissipated
        self.latest, self.normal_force, self.contacts = latest, normal, contacts
        self._pending = True
        self._previous_dt = s.dt_previous

    def nodal_forces(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """What the latest pass added to the accelerations: the state rows of this rank's
        owned surface nodes, the force on each (N, rows of 3), and the segments of every
        pass (rows of 4 global node numbers, -1 as the 4th of a triangle; the same on every
        rank), for the outputs (:mod:`rwall_fem.output.contact_loads`)."""
        segments = [np.where(ps.segments >= 0, self.nodes[np.maximum(ps.segments, 0)], -1)
                    for ps in self.passes]  # fmt: skip
        return self.mine, self._owned_force, np.concatenate(segments).reshape(-1, 4)

    def energies(self) -> dict[str, float]:
        """This rank's share of the books (J) after the update of step n: -W - D on its
        nodes (W up to the first half of step n, as the kinetic energy K^n has it), D on
        rank 0 (every rank computes it all)."""
        # As K^n = 1/2 m v^{n-1/2} . v^{n+1/2} books it: of step n, the first half only.
        work = 0.5 * self.state.dt_velocity * self._first if self._pending else 0.0
        dissipated = self.dissipated if self.comm.rank == 0 else 0.0
        return {
            "contact_energy": -(self.work + work) - dissipated,
            "contact_friction": dissipated,
        }

    def row(self, t: float, index: int, energy: float) -> tuple:
        """The row of ``contacts.csv`` at time t (s) after the update of the latest step,
        whose booked contact energy (J, summed over the ranks) is ``energy``."""
        impulse, _ = self._pending_books(self.state.dt_velocity, self.state.v)
        return (t, index, *self.latest.tolist(), *(self.impulse + impulse).tolist(),
                self.normal_force, self.contacts, energy, self.dissipated, self.energy)  # fmt: skip

    def describe(self) -> str:
        """One line for ``run.log``: the surface, the gap, the stiffness and the friction."""
        k0 = np.concatenate([ps.stiffness for ps in self.passes])
        inside, behind, deepest = self.starting_inside
        start = (
            f"; {inside} node(s) start inside the gap (the deepest {deepest:.3g} m in, "
            f"{behind} behind the surface): their gap is 0.95 of their distance, growing back "
            "as they leave, those behind inactive until they come out (Radioss Inacti = 6)"
            if inside else ""
        )  # fmt: skip
        return (
            f"{self.name}: {len(self.passes)} pass(es), {self.size} surface nodes, "
            f"{sum(len(ps.segments) for ps in self.passes)} segments; gap {self.gap:.4g} m, "
            f"k0 {k0.min(initial=np.inf):.4g} to {k0.max(initial=0.0):.4g} N/m, damping "
            f"{self.damping:g}, friction {self.friction:g}{start}"
        )

    def summary(self) -> dict:
        """What ``summary.json`` says of the interface (the same on every rank)."""
        impulse = self.impulse + self._pending_books(self.state.dt_velocity, self.state.v)[0]
        return {
            "name": self.name,
            "surface_nodes": self.size,
            "segments": sum(len(ps.segments) for ps in self.passes),
            "passes": len(self.passes),
            "gap": self.gap,
            "friction": self.friction,
            "sorts": self.sorts,
            "impulse": impulse.tolist(),
            "penalty_energy": self.energy,
            "contact_friction": self.dissipated,
        }

    def checkpoint_state(self) -> dict[str, np.ndarray]:
        """The friction forces of each pass, the books, and the impulse of the latest step
        (booked now: its velocity step is known after the update)."""
        self._book_pending(self.state.dt_velocity, self.state.v)
        arrays = {f"tangential{k}": ps.tangential for k, ps in enumerate(self.passes)}
        arrays |= {f"gaps{k}": ps.gaps for k, ps in enumerate(self.passes)}
        books = [self.dissipated, *self.impulse, *self.latest, self.normal_force,
                 self.contacts, self.energy, self.work]  # fmt: skip
        return arrays | {"books": np.array(books)}

    def restore_state(self, arrays: dict[str, np.ndarray]) -> None:
        for k, ps in enumerate(self.passes):
            ps.tangential[:] = arrays[f"tangential{k}"]
            ps.gaps[:] = arrays[f"gaps{k}"]
        books = arrays["books"].tolist()
        self.dissipated = books[0]
        self.impulse[:] = books[1:4]
        self.latest[:] = books[4:7]
        self.normal_force, self.contacts, self.energy = books[7], int(books[8]), books[9]
        self.work = books[10]
        self._pending = False
