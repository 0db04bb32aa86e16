"""Rigid bodies: node sets that move as one rigid body (Radioss ``/RBODY``).

``docs/theory.md`` ("Rigid bodies") derives what is done here. A rigid body is a set of
nodes of the mesh (its *secondary* nodes, each owned by one rank) and a reference point,
its centre of mass c, with a mass M and an inertia tensor J0 about c (kg, kg m^2; from the
nodes' lumped masses and any mass and inertia added at the main node). Its state is c and
the rotation R at t^n, the velocity V^{n-1/2} and the angular momentum L^{n-1/2} (spatial
frame); its nodes' positions are always ``c + R (X - c0)``.

One step, in the pipeline of constraints (:class:`RigidBody`, then the walls, then
:class:`~rwall_fem.rigid_contact.RigidContact`, then the boundary conditions):

1. :meth:`RigidBody.constrain` gathers the force and the moment about c of the nodal
   forces ``m a`` (internal forces and gravity; over the ranks: one ``Allreduce`` of six
   numbers) and predicts ``V^{n+1/2} = V^{n-1/2} + dt^n F / M``, ``L^{n+1/2} = L^{n-1/2} +
   dt^n T``, ``omega^{n+1/2} = R' J0^-1 R'^T L^{n+1/2}`` at the mid-step rotation ``R' =
   exp(dt^{n+1/2}/2 omega^{n+1/2}) R^n`` (a fixed point), ``c^{n+1} = c^n + dt^{n+1/2}
   V^{n+1/2}``, ``R^{n+1} = exp(dt^{n+1/2} omega^{n+1/2}) R^n`` (Rodrigues), and sets the
   nodes' accelerations so that the update moves them exactly to ``c^{n+1} + R^{n+1} (X -
   c0)``;
2. the walls treat the secondary nodes they find in contact, each with its own mass;
3. :class:`~rwall_fem.rigid_contact.RigidContact` takes what the walls did to the body's
   nodes over the body as a whole. From fixed and prescribed walls of free sliding: the change (dV,
   domega) of the least kinetic energy for which every node such a wall treated leaves
   with at least the normal velocity the wall asked for (a least-distance problem,
   solved by non-negative least squares: the contact impulses are its multipliers), so
   the body stops at the wall within the step, as a node does, and exactly what it
   receives is booked by the walls (impulses, works). From walls that are tied, with
   friction or carried by a main node: the impulses they gave the nodes, each with its
   own mass, as they are (what Radioss does with a wall's secondary nodes that belong to
   a rigid body: momentum is exact, but the body is stopped over several steps). Then
   the motion of step 1 is redone with the corrected V and L.

Energy: the body's kinetic energy is its own column ``rigid_body`` of ``energy.csv``, the
shadow ``1/2 M V^{n-1/2} . V^{n+1/2} + 1/4 (L^{n-1/2} . omega^{n+1/2} + L^{n+1/2} .
omega^{n-1/2})``; its nodes are taken out of ``kinetic``, and out of the momentum, which
gets ``M V`` instead. Gravity acts on M (the body applies it: the nodes' share of it is
taken out of their forces first). The cells whose nodes all belong to one body are not
computed (:func:`deactivate_rigid_cells`), as Radioss deactivates them.
"""

from __future__ import annotations

import math

import numpy as np
from mpi4py import MPI

__all__ = [
    "RigidBody",
    "RigidBodyError",
    "build_rigid_bodies",
    "deactivate_rigid_cells",
    "rotation",
]

_ITERATIONS = 8  # of the mid-step angular velocity (each gains about omega dt / 2 digits)


def rotation(theta: np.ndarray) -> np.ndarray:
    """The rotation matrix exp([theta]x) of the rotation vector ``theta`` (rad), by
    Rodrigues's formula (its series near zero)."""
    angle2 = float(theta @ theta)
    K = np.array([[0.0, -theta[2], theta[1]], [theta[2], 0.0, -theta[0]],
                  [-theta[1], theta[0], 0.0]])  # fmt: skip
    if angle2 < 1e-12:
        a, b = 1.0 - angle2 / 6.0, 0.5 - angle2 / 24.0
    else:
        angle = math.sqrt(angle2)
        a, b = math.sin(angle) / angle, (1.0 - math.cos(angle)) / angle2
    return np.eye(3) + a * K + b * (K @ K)


class RigidBody:
    """The rigid body ``name`` of the owned secondary ``nodes`` (local indices) of
    ``state``, with its mass (kg), inertia tensor about its centre of mass (kg m^2, 3 x 3),
    centre ``center`` (m), initial velocity ``velocity`` (m/s) and angular velocity
    ``angular_velocity`` (rad/s), under ``gravity`` (m/s^2 or None). The same on every
    rank but for ``nodes``. Build it with :func:`rwall_fem.rigid_bodies.rigid_body`."""

    def __init__(self, name: str, nodes: np.ndarray, state, comm, *, mass: float,
                 inertia: np.ndarray, center: np.ndarray, velocity: np.ndarray,
                 angular_velocity: np.ndarray, gravity=None):  # fmt: skip
        self.name, self.comm = name, comm
        self.nodes = np.asarray(nodes, dtype=np.int64)
        self.mass = float(mass)
        self.inertia0 = np.array(inertia, dtype=float)  # J0 about c, in the frame of t = 0
        self.inverse0 = np.linalg.inv(self.inertia0)
        self.center0 = np.array(center, dtype=float)
        self.positions0 = state.X[self.nodes]  # X, m
        self.offsets = self.positions0 - self.center0  # X - c0, m
        self.node_mass = state.mass[self.nodes]  # kg (fixed: no mass scaling with a body)
        self._first_moment = self.node_mass @ self.offsets  # this rank's sum m (X - c0), kg m
        self._arms = self.offsets.copy()  # x - c at t^n, m: R (X - c0)
        self.gravity = None if gravity is None else np.asarray(gravity, dtype=float)
        # The state at t^n (c, R) and over the latest step (V, L, omega: n - 1/2).
        self.center = self.center0.copy()
        self.R = np.eye(3)
        self.velocity = np.array(velocity, dtype=float)
        self.omega = np.array(angular_velocity, dtype=float)
        self.angular_momentum = self.inertia0 @ self.omega
        # Those of the step before (n - 1/2 after the update of step n), for the shadow
        # kinetic energy, and the nodes' velocities v^{n-1/2} (their kinetic energy).
        self.previous = (self.velocity.copy(), self.angular_momentum.copy(), self.omega.copy())
        self.nodes_before = np.zeros((len(self.nodes), 3))
        # The gravity's work of M V less that of the nodes' m v (kg m; finished steps, and
        # the latest step's first half).
        self._gravity_integral = np.zeros(3)
        self._half = 0.0  # dt^{n-1}/2 of the latest step, s
        self._predicted = None  # c^{n+1}, R^{n+1} and the arms of the latest prediction
        self.node_velocity = np.zeros((len(self.nodes), 3))  # v^{n+1/2} it gave them, m/s
        self.rotations = None  # shell nodes' rotations (rwall_fem.shells.rigid), if any

    # --- the step -----------------------------------------------------------------------

    def spatial_inertia(self) -> np.ndarray:
        """R J0 R^T (kg m^2): the inertia about c at t^n in the global frame."""
        return self.R @ self.inertia0 @ self.R.T

    def angular_velocity(self, L: np.ndarray, dt: float) -> np.ndarray:
        """omega^{n+1/2} = R J0^-1 R^T L (rad/s) at the rotation of mid-step, R^{n+1/2} =
        exp(dt/2 omega) R^n: a fixed point, found in a few iterations from R^n's."""
        omega = self.R @ (self.inverse0 @ (self.R.T @ L))
        for _ in range(_ITERATIONS):
            R = rotation(0.5 * dt * omega) @ self.R
            again = R @ (self.inverse0 @ (R.T @ L))
            done = np.abs(again - omega).max() <= 1e-15 * np.abs(again).max()
            omega = again
            if done:
                break
        return omega

    def constrain(self, state) -> None:
        """Gather the nodal forces, predict the motion over the step, move the nodes with it."""
        nodes, dt_v = self.nodes, state.dt_velocity
        v = state.v[nodes]
        self._book_gravity(state, v)
        self.previous = (self.velocity, self.angular_momentum, self.omega)
        self.nodes_before = v
        forces = self.node_mass[:, None] * state.a[nodes]
        S = self._arms.T @ forces  # sum (x - c) f^T: the moment is its antisymmetric part
        local = np.array([*forces.sum(axis=0), S[1, 2] - S[2, 1], S[2, 0] - S[0, 2],
                          S[0, 1] - S[1, 0]])  # fmt: skip
        if self.rotations is not None:  # the moments on shell nodes
            local[3:] += self.rotations.torque()
        if self.gravity is not None:  # the body applies gravity to all its mass below
            local[:3] -= self.node_mass.sum() * self.gravity
            local[3:] -= np.cross(self.R @ self._first_moment, self.gravity)
        total = np.empty(6)
        self.comm.Allreduce(local, total, op=MPI.SUM)
        if self.gravity is not None:
            total[:3] += self.mass * self.gravity
        self.velocity = self.previous[0] + dt_v * total[:3] / self.mass
        self.angular_momentum = self.previous[1] + dt_v * total[3:]
        self.omega = self.angular_velocity(self.angular_momentum, state.dt)
        self._move(state)

    def correct(self, state, dv: np.ndarray, dL: np.ndarray) -> None:
        """Add the contact impulses' changes of V (m/s) and L (kg m^2/s) and move again."""
        self.velocity = self.velocity + dv
        self.angular_momentum = self.angular_momentum + dL
        self.omega = self.angular_velocity(self.angular_momentum, state.dt)
        self._move(state)

    def _move(self, state) -> None:
        """Set the nodes' accelerations so that the update takes them to c^{n+1} + R^{n+1}
        (X - c0), from V^{n+1/2} and omega^{n+1/2}."""
        dt, dt_v, nodes = state.dt, state.dt_velocity, self.nodes
        center = self.center + dt * self.velocity
        R = rotation(dt * self.omega) @ self.R
        arms = self.offsets @ R.T
        self._predicted = (center, R, arms)
        velocity = (center + arms - self.positions0 - state.u[nodes]) / dt
        self.node_velocity = velocity  # before the walls, m/s
        state.a[nodes] = (velocity - self.nodes_before) / dt_v
        if self.rotations is not None:
            self.rotations.follow(self.omega, dt_v)

    def commit(self) -> None:
        """Take the motion of the step: c^{n+1} and R^{n+1} (after the walls)."""
        self.center, self.R, self._arms = self._predicted

    # --- books --------------------------------------------------------------------------

    @property
    def kinetic(self) -> float:
        """The shadow kinetic energy of the latest update (J; the same on every rank)."""
        V0, L0, w0 = self.previous
        translation = 0.5 * self.mass * float(V0 @ self.velocity)
        turning = 0.25 * float(L0 @ self.omega + self.angular_momentum @ w0)
        return translation + turning

    def initial_kinetic(self) -> float:
        """1/2 M V.V + 1/2 omega.L (J) at the start."""
        return 0.5 * self.mass * float(self.velocity @ self.velocity) + 0.5 * float(
            self.omega @ self.angular_momentum
        )

    def nodal_kinetic(self, state) -> float:
        """What the update booked as the kinetic energy of this rank's secondary nodes (J):
        1/2 sum m v^{n-1/2} . v^{n+1/2}, taken out of ``kinetic``."""
        v = state.v[self.nodes]
        return 0.5 * float(np.einsum("i,ij,ij->", self.node_mass, self.nodes_before, v))

    def nodal_momentum(self, state) -> np.ndarray:
        """sum m v (kg m/s) of this rank's secondary nodes, taken out of the momentum."""
        return self.node_mass @ state.v[self.nodes]

    @property
    def momentum(self) -> np.ndarray:
        """M V^{n+1/2} (kg m/s; the same on every rank)."""
        return self.mass * self.velocity

    def _book_gravity(self, state, v: np.ndarray) -> None:
        """Before the step's update: book the latest step's second half and this step's
        first half of M V^{n-1/2} - sum m v^{n-1/2} (the nodes' share is in the gravity's
        own books; M V split evenly over the ranks, which the caller sums)."""
        if self.gravity is None:
            return
        half = 0.5 * state.dt_velocity
        difference = self.mass * self.velocity / self.comm.size - self.node_mass @ v
        self._gravity_integral += (self._half + half) * difference
        self._half = half

    def gravity_work(self, state) -> float:
        """The work of gravity on the added mass's momentum beyond the nodes' (J), summed
        over the ranks by the caller (each rank holds its nodes' share)."""
        if self.gravity is None:
            return 0.0
        return float(self.gravity @ self._gravity_integral)

    def checkpoint_state(self) -> dict[str, np.ndarray]:
        """The motion, the latest step's velocities and the books."""
        V0, L0, w0 = self.previous
        return {
            "motion": np.concatenate([self.center, self.R.ravel(), self.velocity,
                                      self.angular_momentum, self.omega, V0, L0, w0]),
            "nodes_before": self.nodes_before,
            "gravity": np.concatenate([self._gravity_integral, [self._half]]),
        } | ({} if self.rotations is None else self.rotations.checkpoint_state())  # fmt: skip

    def restore_state(self, arrays: dict[str, np.ndarray]) -> None:
        motion = arrays["motion"]
        self.center, self.R = motion[0:3].copy(), motion[3:12].reshape(3, 3).copy()
        self._arms = self.offsets @ self.R.T
        self.velocity, self.angular_momentum, self.omega = (
            motion[12:15].copy(), motion[15:18].copy(), motion[18:21].copy()
        )  # fmt: skip
        self.previous = (motion[21:24].copy(), motion[24:27].copy(), motion[27:30].copy())
        self.nodes_before = arrays["nodes_before"].copy()
        self._gravity_integral = arrays["gravity"][:3].copy()
        self._half = float(arrays["gravity"][3])
        if self.rotations is not None:
            self.rotations.restore_state(arrays)


def _tensor(six) -> np.ndarray:
    """The symmetric 3 x 3 tensor of [Jxx, Jyy, Jzz, Jxy, Jyz, Jxz] (kg m^2; the off-diagonal
    components are the tensor's, -integral of x y dm, as Radioss reads them)."""
    xx, yy, zz, xy, yz, xz = six
    return np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]], dtype=float)


def _point_inertia(mass, arms: np.ndarray) -> np.ndarray:
    """sum m (|r|^2 I - r r^T) (kg m^2) of point masses ``mass`` at ``arms`` (k, 3)."""
    mass = np.broadcast_to(mass, len(arms))
    second = np.einsum("i,ij,ik->jk", mass, arms, arms)
    return np.trace(second) * np.eye(3) - second


class RigidBodyError(ValueError):
    """A rigid body that cannot be built: one line naming its key."""


def build_rigid_bodies(specs, selections: list[np.ndarray], state, comm, gravity=None,
                       size: float = 1.0) -> list[RigidBody]:  # fmt: skip
    """The rigid bodies of the scene's ``specs`` (:class:`~rwall_fem.scene.RigidBodySpec`),
    of the owned nodes ``selections`` (one array of local indices each, chosen by the
    caller from the sets, parts and box), their nodes' initial velocities set to the rigid
    motion. ``size`` (m) is the body's size, for the tolerance of a singular inertia.
    RigidBodyError (collective) for an empty body, a node in two bodies, no mass, or an
    inertia tensor that is not positive definite."""
    taken = np.zeros(len(state.mass), dtype=np.int64) - 1
    bodies = []
    for i, (spec, nodes) in enumerate(zip(specs, selections, strict=True)):
        where = f"rigid_body[{i}]"
        count = comm.allreduce(len(nodes))
        if not count:
            raise RigidBodyError(f"{where}: no node of the mesh is in its sets, parts or box: "
                                 "a rigid body needs nodes")  # fmt: skip
        shared = taken[nodes]
        others = comm.allreduce(np.unique(shared[shared >= 0]).tolist())
        if others:
            overlap = comm.allreduce(int((shared >= 0).sum()))
            raise RigidBodyError(f"{where}: {overlap} of its nodes are also in rigid_body"
                                 f"[{min(others)}]: a node belongs to one rigid body")  # fmt: skip
        taken[nodes] = i
        m, X, v = state.mass[nodes], state.X[nodes], state.v[nodes]
        sums = comm.allreduce(np.concatenate([[m.sum()], m @ X, m @ v]))
        node_mass, first, momentum = sums[0], sums[1:4], sums[4:7]
        nodes_center = first / node_mass
        added = _tensor(spec.inertia)
        if spec.node_masses:
            point = nodes_center if spec.main_node is None else np.array(spec.main_node)
            mass = node_mass + spec.mass
            if spec.center == "nodes":
                center, point = nodes_center, nodes_center
            else:
                center = (first + spec.mass * point) / mass
            inertia = comm.allreduce(_point_inertia(m, X - center))
            inertia = inertia + added + _point_inertia(spec.mass, (point - center)[None, :])
        else:
            mass, center, inertia = spec.mass, np.array(spec.main_node), added
        if not mass > 0.0:
            raise RigidBodyError(f"{where}.mass: the body has no mass (node_masses = false and "
                                 "mass = 0 kg); give it a mass > 0")  # fmt: skip
        eigen = np.linalg.eigvalsh(inertia)
        if not eigen[0] > 1e-9 * max(eigen[-1], mass * size**2):
            raise RigidBodyError(
                f"{where}.inertia: the inertia tensor about its centre of mass is not positive "
                f"definite (principal moments {', '.join(f'{e:.4g}' for e in eigen)} kg m^2: "
                "its nodes on a line, or node_masses = false without inertia); add inertia"
            )
        velocity = momentum / node_mass
        omega = np.array(spec.angular_velocity, dtype=float)
        state.v[nodes] = velocity + np.cross(omega, X - center)
        bodies.append(RigidBody(where, nodes, state, comm, mass=mass, inertia=inertia,
                                center=center, velocity=velocity, angular_velocity=omega,
                                gravity=gravity))  # fmt: skip
    return bodies


def deactivate_rigid_cells(internal, bodies: list[RigidBody], V, comm) -> int:
    """Stop computing the cells of the internal force ``internal`` (a
    :class:`~rwall_fem.body.Body`) whose nodes all belong to one of the rigid ``bodies``, as
    Radioss does: their forces are internal to the body, and a small-strain material would
    give them forces under a rigid rotation. Parts whose cells may erode keep theirs.
    Returns how many cells were deactivated (over the ranks; collective)."""
    from rwall_fem.elements import GhostedField

    tag = GhostedField(V)  # each node's body, from 1 (0: none), on the ghosts too
    for b, body in enumerate(bodies):
        tag.owned[body.nodes, 0] = b + 1
    tag.scatter_forward()
    which = tag.array[:, 0]
    count = 0
    for force in internal.elements:
        if force.erosion is not None or not hasattr(force, "deactivate"):
            continue  # (shells: a rigid motion strains them nothing, computed or not)
        mine = which[force.cells]
        rigid = (mine[:, 0] > 0) & (mine == mine[:, :1]).all(axis=1)
        if rigid.any():
            force.deactivate(np.flatnonzero(rigid))
        count += int(rigid.sum())
    return comm.allreduce(count)

