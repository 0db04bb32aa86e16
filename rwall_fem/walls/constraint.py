"""The kinematic rigid-wall condition, shared by all shapes (``docs/theory.md``, "Rigid walls").

After the acceleration solve, each secondary node's velocity and position are
predicted, ``v* = v^{n-1/2} + dt^n a^n`` and ``x* = x^n + dt^{n+1/2} v*`` (``dt^n``, the
step of the velocity update, is the mean of the steps before and after t^n), and so is
the wall's position. A node whose predicted position is on the forbidden side is
in contact (on a parallelogram only inside it, and only if it is not more than
two steps of normal travel, 2 dt |(v* - V) . n|, behind it). The wall then
applies to the node the impulse ``I`` that

- removes its normal velocity relative to the wall (a node slightly behind a
  parallelogram gets the velocity that brings it back onto it in one step);
- leaves its tangential velocity free (``slide="free"``), removes it
  (``"tied"``), or removes it up to the Coulomb limit ``mu |I_N|``
  (``"friction"``), optionally filtered: ``I_T = alpha I_T + (1 - alpha) I_T_prev``
  (alpha given, 2 pi / period in steps, or 2 pi f dt for a cut-off frequency f, then
  taken again at every step, at most 1).

``I`` is added to ``a^n`` as ``I / (m dt^n)``, which gives the same ``v^{n+1/2}``
as editing both ``v^{n-1/2}`` and ``a^n``. A node stops where it is, at most
one step of travel short of the surface; it is never projected. A node
already behind the surface stays there unless one step takes it out.

A wall carried by a main node (``MainNodeMotion``) receives minus the sum of
the impulses, so momentum is conserved to round-off. The coupling is done in
the same step: the wall's velocity over the step solves
``(M + sum m_i P_i) V = M V* + sum m_i (P_i v*_i - n_i b_i)`` (P_i = n_i n_i^T, or
the identity for tied nodes; b_i the target normal velocity), i.e. the wall
moves with the mass of the nodes it treats: the reference's one-step mass
coupling, without its lag of one step. Tied and sticking nodes then follow the wall exactly.
The components the motion holds (``held``: a main node on the symmetry planes of a half or
quarter model) keep their velocity: their rows of that system are V_j = V*_j, and what
the nodes push along them goes to the planes (as the reaction of a boundary condition).

Energy: the work of the contact impulses is booked at mid-step velocities
relative to the wall, 1/2 I . (w^{n-1/2} + w^{n+1/2}) with w = v - V, split into
normal and tangential (friction) parts; it is the energy the wall dissipates.
A prescribed wall also does driving work 1/2 I . (V^{n-1/2} + V^{n+1/2}), booked
as external work.

Cost: each step tests only the *near set*, the secondary nodes whose clearance
(``shape.clearance``, a lower bound on how far a node must travel relative to the
wall before the wall can treat it) was within a travel budget when the set was
selected. Every step bounds how far any secondary node and the wall may have
travelled since (largest velocity and acceleration components of the rank's
secondary nodes, the wall's exact translation) and selects the set again, from all
secondary nodes, before that bound passes the budget. No node the wall would treat
is ever left out, so the results are those of testing every secondary node; each
rank decides on its own nodes, without communication. The passes over the nodes (the
test, the impulses, the main node's equations, the works, the bound, the selection) are
compiled (:mod:`rwall_fem.walls.contact`).
"""

from __future__ import annotations

import math

import numpy as np
from mpi4py import MPI

from rwall_fem.walls.contact import SLIDES, ContactPasses
from rwall_fem.walls.motion import FixedMotion

__all__ = ["RigidWall", "filter_alpha"]

# The near set is selected for this many steps of travel at the speed bound of the moment.
_HORIZON = 16
# sqrt(3) turns the largest velocity component into a bound on a node's speed; the factor 2
# covers rounding (a float sum u + dt v moves u by at most twice the increment).
_TRAVEL = 2.0 * math.sqrt(3.0)


def filter_alpha(friction_filter: tuple[str, float] | None, dt: float) -> float:
    """The friction filter's alpha from (how, value): a coefficient, a period in steps
    (2 pi / steps) or a cut-off frequency in Hz (2 pi f dt at the step dt, s, at most 1);
    1 (no filter) without one."""
    if friction_filter is None:
        return 1.0
    how, value = friction_filter
    if how == "coefficient":
        return value
    if how == "steps":
        return 2 * math.pi / value
    return min(2 * math.pi * value * dt, 1.0)


def _largest(values: np.ndarray) -> float:
    """Largest absolute component of ``values`` (two reductions, no temporary)."""
    return float(max(values.max(), -values.min()))


class RigidWall:
    """A rigid wall acting on the owned secondary ``nodes`` (local node indices) of a body.

    Accumulated on this rank (reduce over ranks to report): ``normal_impulse``
    and ``tangential_impulse`` (N s, the push of the structure on the wall),
    ``normal_work`` and ``friction_work`` (J, work of the wall on the structure
    relative to the wall), ``driving_work`` (J, prescribed walls), contact counts.
    Over all ranks, after :meth:`find_initial_penetration`: ``initially_penetrated``
    secondary nodes started behind the wall, the deepest ``deepest_penetration`` (m)
    behind it at ``deepest_position`` (m).
    """

    def __init__(
        self,
        shape,
        nodes: np.ndarray,
        name: str,
        *,
        slide: str = "free",
        friction: float = 0.0,
        friction_filter: tuple[str, float] | None = None,
        dt: float = 0.0,
        motion=None,
        comm: MPI.Comm = MPI.COMM_WORLD,
    ):
        if slide not in SLIDES:
            raise ValueError(f"slide must be one of {SLIDES}")
        self.shape, self.name, self.slide = shape, name, slide
        self.friction = float(friction)
        # The friction filter (how, value) of Radioss; alpha at the step dt (s) of the start.
        self.friction_filter = friction_filter
        self.filter_alpha = filter_alpha(friction_filter, dt)
        self.motion = motion if motion is not None else FixedMotion()
        self.comm = comm
        self.nodes = np.asarray(nodes, dtype=np.int64)
        # The secondary nodes as a range (first, end) when they follow one another: the bound
        # on their travel is then a contiguous pass.
        n = len(self.nodes)
        follow = n and self.nodes[-1] - self.nodes[0] == n - 1 and np.all(np.diff(self.nodes) == 1)
        self._span = (int(self.nodes[0]), int(self.nodes[-1]) + 1) if follow else None
        self._held = np.zeros(3, dtype=np.uint8)  # the main node's held components, a mask
        self._held[getattr(self.motion, "held", [])] = 1
        self.finite = shape.kind == "parallelogram"
        self.normal_impulse = np.zeros(3)
        self.tangential_impulse = np.zeros(3)
        self.normal_work = self.friction_work = self.driving_work = 0.0
        self.contacts = 0  # number of nodes treated in the latest step
        self.touching = self.nodes[:0]  # those nodes (local indices)
        self.first_contact = np.inf  # s
        self.last_contact = -np.inf  # s
        # The latest step's treated nodes, impulses (N s) and wall velocity (m/s): the
        # v^{n+1/2} halves of their work are booked at the next step, from the velocities
        # the nodes then have (whatever acted on them after the wall).
        self._latest = None
        self._pending_driving = 0.0  # J
        self._pending_body = 0.0  # J, the v^{n+1/2} half of a rigid body's share (reassign)
        self._passes: ContactPasses | None = None  # the compiled passes, at the first step
        filtered = slide == "friction" and friction_filter is not None
        self._previous_tangential = np.zeros((len(self.nodes), 3)) if filtered else None
        self._filtered_rows = self.nodes[:0]  # rows of it written in the latest step
        # Near set: the secondary nodes (positions in ``nodes``) tested this step; selected
        # at the first step (the budget, m, is -inf until then).
        self._near = self._near_nodes = self.nodes[:0]
        self._budget, self._travel, self._anchor = -np.inf, 0.0, [0.0, 0.0, 0.0]
        self.initially_penetrated = 0
        self.deepest_penetration = 0.0  # m
        self.deepest_position = np.zeros(3)  # m

    @property
    def work(self) -> float:
        """Work (J) of the contact impulses relative to the wall: the energy it dissipated."""
        return self.normal_work + self.friction_work

    @property
    def impulse(self) -> np.ndarray:
        """Total push (N s) of this rank's nodes on the wall."""
        return self.normal_impulse + self.tangential_impulse

    @property
    def position(self) -> np.ndarray:
        """Current position (m) of the wall's defining point M (the main node)."""
        return self.shape.point + self.motion.offset

    def find_initial_penetration(self, state, tolerance: float) -> None:
        """Count the secondary nodes (over all ranks) that start more than ``tolerance``
        (m) behind the wall: those the wall holds there (inside a parallelogram, those
        within its two steps of normal travel: it pushes them back onto it). Collective."""
        x = state.X[self.nodes] + state.u[self.nodes]
        d = self.shape.distance(x, self.motion.offset)
        behind = d < -tolerance
        if self.finite:
            speed = np.abs((state.v[self.nodes] - self.motion.velocity) @ self.shape.normal)
            behind &= self.shape.inside_patch(x, self.motion.offset) & (d >= -2 * state.dt * speed)
        depth = -d[behind]
        i = int(np.argmax(depth)) if len(depth) else -1
        mine = (depth[i], *x[behind][i]) if i >= 0 else (0.0, 0.0, 0.0, 0.0)
        deepest = max(self.comm.allgather(mine), key=lambda c: c[0])
        self.initially_penetrated = self.comm.allreduce(int(behind.sum()))
        self.deepest_penetration = float(deepest[0])
        self.deepest_position = np.array(deepest[1:])

    def checkpoint_state(self) -> dict[str, np.ndarray]:
        """What the wall booked so far, the latest step's contacts (the v^{n+1/2} halves of
        their work are booked at the next step), the friction filter's previous
        impulses, the near set and the wall's motion."""
        latest = self._latest or (self.nodes[:0], np.zeros((0, 3)), None, np.zeros(0))
        nodes, normal, tangential, final = latest
        arrays = {
            "normal_impulse": self.normal_impulse,
            "tangential_impulse": self.tangential_impulse,
            "works": np.array(
                [self.normal_work, self.friction_work, self.driving_work, self._pending_driving,
                 self._pending_body]  # fmt: skip
            ),
            "contact_times": np.array([self.first_contact, self.last_contact]),
            "contacts": np.array(self.contacts),
            "touching": self.touching,
            "latest_nodes": nodes,
            "latest_normal": normal,
            "latest_tangential": np.zeros((0, 3)) if tangential is None else tangential,
            "latest_final": final,  # empty: no latest step
            "filtered_rows": self._filtered_rows,
            "near": self._near,
            "near_budget": np.array([self._budget, self._travel, *self._anchor]),
        }
        if self._previous_tangential is not None:
            arrays["previous_tangential"] = self._previous_tangential
        return arrays | {f"motion_{k}": v for k, v in self.motion.checkpoint_state().items()}

    def restore_state(self, arrays: dict[str, np.ndarray]) -> None:
        self.normal_impulse[:] = arrays["normal_impulse"]
        self.tangential_impulse[:] = arrays["tangential_impulse"]
        works = arrays["works"].tolist()
        (self.normal_work, self.friction_work, self.driving_work, self._pending_driving,
         self._pending_body) = works  # fmt: skip
        self.first_contact, self.last_contact = arrays["contact_times"].tolist()
        self.contacts = int(arrays["contacts"])
        self.touching = arrays["touching"]
        self._latest = None
        if len(arrays["latest_final"]):
            tangential = None if self.slide == "free" else arrays["latest_tangential"]
            self._latest = (
                arrays["latest_nodes"], arrays["latest_normal"], tangential, arrays["latest_final"]
            )  # fmt: skip
        self._filtered_rows = arrays["filtered_rows"]
        if self._previous_tangential is not None:
            self._previous_tangential[:] = arrays["previous_tangential"]
        self._near = arrays["near"]
        self._near_nodes = self.nodes[self._near]
        self._budget, self._travel, *self._anchor = arrays["near_budget"].tolist()
        motion = {k[7:]: v for k, v in arrays.items() if k.startswith("motion_")}
        self.motion.restore_state(motion)

    def _passes_for(self, state) -> ContactPasses:
        """The compiled passes on the arrays of ``state`` (made at its first step)."""
        if self._passes is None or self._passes.state is not state:
            self._passes = ContactPasses(self.shape, state)
        return self._passes

    def settle(self, state) -> None:
        """Book the v^{n+1/2} halves of the work of the latest step's impulses with the
        velocities the nodes now have (whatever acted on them after the wall); before the
        masses change, and at the start of every step."""
        if self._latest is not None:
            nodes, normal, tangential, final = self._latest
            normal_work, friction_work = self._passes_for(state).work(
                normal, tangential, final, nodes
            )
            self.normal_work += 0.5 * normal_work
            if tangential is not None:
                self.friction_work += 0.5 * friction_work
            self._latest = None
        self.driving_work += self._pending_driving
        self.normal_work += self._pending_body
        self._pending_driving = self._pending_body = 0.0

    def constrain(self, state) -> None:
        """Edit ``state.a`` of the secondary nodes in contact at step ``state.step``."""
        dt, dt_v, motion = state.dt, state.dt_velocity, self.motion
        passes = self._passes_for(state)
        # First: the nodes' arrays of the latest step are filled again below.
        self.settle(state)
        wall_velocity = motion.predict(state.t, dt)
        offset = motion.offset
        wall_next = offset + dt * wall_velocity
        if len(self.nodes):
            self._follow(state, passes, wall_velocity, wall_next)
        near = self._near_nodes
        k = passes.find(near, dt_v, dt, offset, wall_next, wall_velocity)

        if self.friction_filter is not None and self.friction_filter[0] == "frequency":
            self.filter_alpha = filter_alpha(self.friction_filter, dt)
        self.contacts = k
        self.touching = passes.nodes[:k]  # nodes treated in the latest step
        kept = None
        if self._previous_tangential is not None:
            # Only the rows written in the previous step are non-zero: clear those alone.
            rows = self._near[passes.hits[:k]]
            kept = self._previous_tangential[rows]
            self._previous_tangential[self._filtered_rows] = 0.0
            self._filtered_rows = rows
        if not k and not motion.dynamic:
            motion.advance(wall_velocity, dt)
            return

        free = self.slide == "free"
        if motion.dynamic:
            predicted = wall_velocity
            wall_velocity = self._coupled_velocity(predicted, passes, k)
        passes.impulses(k, self.slide, self.friction, self.filter_alpha, wall_velocity, kept)
        if motion.dynamic and self.slide == "friction":
            # Second pass: sticking nodes move with the wall, slipping ones push it.
            wall_velocity = self._coupled_velocity(predicted, passes, k, slip=True)
            passes.impulses(k, self.slide, self.friction, self.filter_alpha, wall_velocity, kept)
        normal = passes.normal[:k]
        tangential = None if free else passes.tangential[:k]
        if self._previous_tangential is not None:
            self._previous_tangential[self._filtered_rows] = tangential
        before = motion.velocity
        sums, (normal_work, friction_work) = passes.apply(k, not free, dt_v, before)
        normal_sum, tangential_sum, impulse_sum = sums

        final = wall_velocity
        if motion.dynamic:
            # The main node takes exactly what the nodes received (momentum to round-off).
            final = predicted - self._summed(impulse_sum) / motion.mass
            if len(motion.held):
                final[motion.held] = predicted[motion.held]  # the symmetry planes' reaction
        motion.advance(final, dt)
        self.normal_work += 0.5 * normal_work
        if tangential is not None:
            self.friction_work += 0.5 * friction_work
            self.tangential_impulse -= tangential_sum
        self._latest = (self.touching, normal, tangential, final)
        if motion.prescribed:
            self.driving_work += 0.5 * impulse_sum @ before
            self._pending_driving = 0.5 * impulse_sum @ final
        self.normal_impulse -= normal_sum
        if k:
            self.first_contact = min(self.first_contact, state.t)
            self.last_contact = state.t

    def contact_rows(self, positions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The normals and the normal velocities (m/s, absolute) that the wall asked of its
        contacts ``positions`` (rows of :attr:`touching`) in the latest step: what a
        rigid body owning those nodes must give them (:mod:`rwall_fem.rigid_body`)."""
        passes = self._passes
        normals = passes.normals[positions]
        return normals, passes.target[positions] + normals @ self.motion.velocity

    def contact_impulses(self, positions: np.ndarray) -> np.ndarray:
        """The impulses (N s, normal and tangential) the wall gave its contacts
        ``positions`` (rows of :attr:`touching`) in the latest step."""
        passes = self._passes
        impulses = passes.normal[positions]
        if self.slide != "free":
            impulses = impulses + passes.tangential[positions]
        return impulses

    def reassign(self, positions: np.ndarray, impulses: np.ndarray, body_halves=(0.0, 0.0)) -> None:
        """The contacts ``positions`` of the latest step received ``impulses`` (N s, (k, 3))
        rather than those the wall gave them (their rigid body took the wall's push as a
        whole): the wall's impulse and works are booked with these, the work at the body's
        velocities rather than its nodes': ``body_halves`` (J) are what that adds to the
        v^{n-1/2} half, booked now, and to the v^{n+1/2} half, booked at the next step
        (:mod:`rwall_fem.rigid_contact`). Free sliding only."""
        passes = self._passes
        change = impulses - passes.normal[positions]
        passes.normal[positions] = impulses  # the latest step's, booked again at the next
        total = change.sum(axis=0)
        before = self.motion.previous_velocity
        self.normal_impulse -= total
        relative = passes.previous[positions] - before
        self.normal_work += 0.5 * float(np.einsum("ij,ij->", change, relative)) + body_halves[0]
        self._pending_body += body_halves[1]
        if self.motion.prescribed:
            self.driving_work += 0.5 * float(total @ before)
            self._pending_driving += 0.5 * float(total @ self.motion.velocity)

    def _follow(self, state, passes, wall_velocity, wall_next) -> None:
        """Keep the near set valid for this step's test; select it again when the nodes
        and the wall may have travelled, relative to each other, more than its budget.

        A node outside the set had a clearance above the budget when the set was
        selected, and clearance changes by at most the relative travel, so the test
        ``distance(x*, wall_next) < 0`` cannot be true for it while the travel bound
        ``reach`` (m) stays within the budget. The bound uses the largest velocity and
        acceleration components of the secondary nodes (one compiled pass) and the wall's
        exact translation.
        """
        dt = state.dt
        # bounds on the |v^{n-1/2}| (m/s) and |a^n| (m/s^2) components
        speed, acceleration = passes.largest(self.nodes, self._span)
        self._travel += state.dt_previous * speed  # of x^n from where the set was selected
        ahead = speed + state.dt_velocity * acceleration  # bounds those of v*, m/s
        wall_travel = math.dist(wall_next.tolist(), self._anchor)  # lists: 6x faster
        reach = _TRAVEL * (self._travel + dt * ahead) + wall_travel
        if not reach <= self._budget:  # also when NaN
            self._select(state, passes, ahead, wall_velocity)

    def _select(self, state, passes, ahead: float, wall_velocity) -> None:
        """Select the near set: the secondary nodes that can reach the wall within about
        ``_HORIZON`` steps at the current bound ``ahead`` (m/s) of the velocity
        components and the wall's velocity (m/s)."""
        dt = state.dt
        self._budget = _HORIZON * dt * (_TRAVEL * ahead + math.hypot(*wall_velocity))
        self._travel = 0.0
        self._anchor = self.motion.offset.tolist()
        clearance, largest = passes.clearance(self.nodes, self.motion.offset)
        # Rounding in positions and distances is far below 1e-12 of their size.
        size = largest + np.abs(self.position).max() + self._budget
        slack = self._budget + 1e-12 * size
        if not np.isfinite(slack):
            slack = np.inf  # every node with a finite position
        self._near = np.flatnonzero(clearance <= slack)
        self._near_nodes = self.nodes[self._near]

    def _coupled_velocity(self, predicted, passes, k, slip=False) -> np.ndarray:
        """Velocity (m/s) of a main-node wall over the step when it moves with the mass of
        the k nodes in contact (``passes``): normal motion shared by all, tangential by the
        tied ones (all if the wall is ``tied``; with ``slip``, those of ``passes.slip``
        that do not slip, the slipping ones giving their tangential impulses on top)."""
        tied, mass = self.slide == "tied", self.motion.mass
        if self.comm.size == 1:
            return passes.coupled_velocity(k, tied, slip, mass, predicted, self._held)
        total = self.comm.allreduce(passes.coupling(k, tied, slip))
        return passes.velocity(total, mass, predicted, self._held)

    def _summed(self, values: np.ndarray) -> np.ndarray:
        """``values`` summed over the ranks (on one rank, themselves: no exchange)."""
        return values if self.comm.size == 1 else self.comm.allreduce(values)
