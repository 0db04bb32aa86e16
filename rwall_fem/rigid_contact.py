"""After the walls: what they did to the nodes of rigid bodies, taken by each body as a
whole (``docs/theory.md``, "Rigid bodies": Walls).

From fixed and prescribed walls of free sliding, the body's change of velocity is the one
of least kinetic energy for which every node a wall treated leaves with at least the
normal velocity the wall asked for: a least-distance problem in six unknowns
(:func:`least_distance`, by Lawson and Hanson's non-negative least squares), whose
multipliers are the contact impulses the walls then book, their work at the body's
velocities V + omega x a (what its kinetic energy takes), not at the nodes' chords of its
finite rotation. From walls that are tied, with
friction or carried by a main node, the impulses they gave the nodes, as they are.
"""

from __future__ import annotations

import math

import numpy as np
from mpi4py import MPI

from rwall_fem.rigid_body import RigidBody

__all__ = ["RigidContact", "least_distance"]


def _nnls(A: np.ndarray, b: np.ndarray) -> np.ndarray:
    """x >= 0 minimising |A x - b| (Lawson and Hanson's active-set method); A has few rows
    (7), so at most that many entries of x are positive and the loops are short."""
    m, n = A.shape
    x = np.zeros(n)
    passive = np.zeros(n, dtype=bool)
    scale = max(float(np.abs(A).max(initial=0.0)), 1e-300)
    tol = 1e-12 * scale * max(m, n)
    w = A.T @ (b - A @ x)
    for _ in range(3 * m + 30):
        free = np.where(passive, -np.inf, w)
        j = int(np.argmax(free))
        if not free[j] > tol:
            break
        passive[j] = True
        for _ in range(3 * m + 30):
            z = np.zeros(n)
            z[passive] = np.linalg.lstsq(A[:, passive], b, rcond=None)[0]
            if (z[passive] > 0.0).all():
                break
            q = passive & (z <= 0.0)
            alpha = float(np.min(x[q] / (x[q] - z[q])))
            x = x + alpha * (z - x)
            passive &= x > tol
            x[~passive] = 0.0
        x = z
        w = A.T @ (b - A @ x)
    return x


def least_distance(E: np.ndarray, f: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The y of least |y| with E y >= f, and the multipliers mu >= 0 with y = E^T mu
    (Lawson and Hanson's reduction of the least-distance problem to non-negative least
    squares). E: (k, n), f: (k,)."""
    k, n = E.shape
    G = np.vstack([E.T, f[None, :]])
    h = np.zeros(n + 1)
    h[-1] = 1.0
    u = _nnls(G, h)
    r = G @ u - h
    if not r[-1] < 0.0:  # incompatible constraints (never for a wall's: y = big dV works)
        return np.zeros(n), np.zeros(k)
    mu = u / -r[-1]
    return E.T @ mu, mu


class RigidContact:
    """After the walls: what they did to the nodes of the rigid ``bodies`` is taken by each
    body as a whole (see the module's docstring), and the bodies' motion is committed.
    ``walls`` are the walls that may treat their nodes (fixed or prescribed, free sliding:
    the scene refuses others). ``owned`` is the number of owned nodes."""

    name = "rigid_contact"

    def __init__(self, bodies: list[RigidBody], walls: list, owned: int, comm):
        self.bodies, self.comm = bodies, comm
        rigid = np.concatenate([b.nodes for b in bodies])
        # Only the walls whose secondary nodes hold some of the bodies' (over the ranks).
        self.walls = [w for w in walls if comm.allreduce(len(np.intersect1d(w.nodes, rigid)))]
        self.body_of = np.full(owned, -1, dtype=np.int64)
        # Each secondary node's row in the bodies' node lists, one after the other.
        self._row_of = np.full(owned, -1, dtype=np.int64)
        start = 0
        for b, body in enumerate(bodies):
            self.body_of[body.nodes] = b
            self._row_of[body.nodes] = start + np.arange(len(body.nodes))
            start += len(body.nodes)

    def constrain(self, state) -> None:
        rows = self._contacts(state) if self.walls else None
        if rows is not None:
            self._take(state, rows)
        for body in self.bodies:
            body.commit()

    def _contacts(self, state):
        """This rank's rows (wall, position in its contacts, body, node) of the nodes of the
        bodies that a wall treated at this step; None when no rank has any."""
        found = []
        for w, wall in enumerate(self.walls):
            if not wall.contacts:
                continue
            touching = wall.touching
            which = self.body_of[touching]
            at = np.flatnonzero(which >= 0)
            if len(at):
                found.append(np.column_stack([np.full(len(at), w), at, which[at], touching[at]]))
        rows = np.concatenate(found) if found else np.zeros((0, 4), dtype=np.int64)
        if not self.comm.allreduce(len(rows)):
            return None
        return rows

    def _take(self, state, rows: np.ndarray) -> None:
        """Give each touched body what the walls did to its nodes (collective: every rank
        calls it when some rank has rows): the impulses of walls that are tied, with
        friction or carried by a main node as they are; then over all ranks' rows of the
        fixed and prescribed walls of free sliding, the least-distance change, whose
        impulses those walls then book."""
        exact = np.array([w.slide == "free" and not w.motion.dynamic for w in self.walls])
        as_given = ~exact[rows[:, 0]]
        self._redistribute(state, rows[as_given])
        rows = rows[~as_given]
        mine = np.zeros((len(rows), 8))  # body, n, (x - c) x n, the normal velocity asked
        predicted = np.concatenate([b.node_velocity for b in self.bodies])
        for w, wall in enumerate(self.walls):
            mask = rows[:, 0] == w
            if not mask.any():
                continue
            normals, wanted = wall.contact_rows(rows[mask, 1])
            nodes, which = rows[mask, 3], rows[mask, 2]
            centers = np.array([b.center for b in self.bodies])[which]
            arms = state.X[nodes] + state.u[nodes] - centers
            mine[mask, 0] = which
            mine[mask, 1:4] = normals
            mine[mask, 4:7] = np.cross(arms, normals)
            velocity = predicted[self._row_of[nodes]]
            mine[mask, 7] = wanted - np.einsum("ij,ij->i", normals, velocity)
        gathered = self.comm.allgather(mine)
        if not sum(len(g) for g in gathered):
            return
        offset = sum(len(g) for g in gathered[: self.comm.rank])
        table = np.concatenate(gathered)
        impulses = np.zeros(len(table))
        for b, body in enumerate(self.bodies):
            chosen = table[:, 0] == b
            if not chosen.any():
                continue
            G, demand = table[chosen, 1:7], table[chosen, 7]
            root = np.linalg.cholesky(body.spatial_inertia())
            scale = np.zeros((6, 6))  # L^-T of the mass matrix diag(M I, J) = L L^T
            scale[:3, :3] = np.eye(3) / math.sqrt(body.mass)
            scale[3:, 3:] = np.linalg.inv(root).T
            _, mu = least_distance(G @ scale, demand)
            impulses[chosen] = mu
            change = G.T @ mu  # the sum of the impulses, and their moment about c
            body.correct(state, change[:3] / body.mass, change[3:])
        mu = impulses[offset : offset + len(rows)]
        given = mu[:, None] * mine[:, 1:4]
        before, after = self._body_velocity_shifts(state, rows)
        for w, wall in enumerate(self.walls):
            mask = rows[:, 0] == w
            if mask.any():
                halves = [0.5 * float(np.einsum("ij,ij->", given[mask], shift[mask]))
                          for shift in (before, after)]  # fmt: skip
                wall.reassign(rows[mask, 1], given[mask], halves)

    def _body_velocity_shifts(self, state, rows: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """For each row (a node of a body): (V + omega x a) - v (m/s) at n - 1/2 and at
        n + 1/2, with a = x^n - c^n the arm of the body's moments and v the node's
        velocity, the chord of the body's finite rotation (it differs from omega x a by
        dt/2 omega x (omega x a)). The wall's impulses I booked at V + omega x a do the
        work the body receives, 1/2 (sum I . (V^- + V^+) + dL . (omega^- + omega^+)),
        which its kinetic energy takes; at the nodes' velocities they would miss it by
        O(dt omega^2 |a| |I|)."""
        shifts = np.zeros((2, len(rows), 3))
        nodes_before = np.concatenate([b.nodes_before for b in self.bodies])
        nodes_after = np.concatenate([b.node_velocity for b in self.bodies])
        for b, body in enumerate(self.bodies):
            mask = rows[:, 2] == b
            if not mask.any():
                continue
            nodes = rows[mask, 3]
            arms = state.X[nodes] + state.u[nodes] - body.center
            line = self._row_of[nodes]
            V0, _, w0 = body.previous
            shifts[0, mask] = V0 + np.cross(w0, arms) - nodes_before[line]
            shifts[1, mask] = body.velocity + np.cross(body.omega, arms) - nodes_after[line]
        return shifts[0], shifts[1]

    def _redistribute(self, state, rows: np.ndarray) -> None:
        """The bodies take the impulses (N s) that walls of other kinds gave their nodes
        ``rows``, and their moments, as they are (collective)."""
        local = np.zeros((len(self.bodies), 6))
        for w, wall in enumerate(self.walls):
            mask = rows[:, 0] == w
            if not mask.any():
                continue
            impulses = wall.contact_impulses(rows[mask, 1])
            nodes, which = rows[mask, 3], rows[mask, 2]
            centers = np.array([b.center for b in self.bodies])[which]
            arms = state.X[nodes] + state.u[nodes] - centers
            np.add.at(local, which, np.hstack([impulses, np.cross(arms, impulses)]))
        total = np.empty_like(local)
        self.comm.Allreduce(local, total, op=MPI.SUM)
        for b, body in enumerate(self.bodies):
            if total[b].any():
                body.correct(state, total[b, :3] / body.mass, total[b, 3:])
