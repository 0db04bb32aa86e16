"""The rotations of a rigid body's shell nodes (``[[rigid_body]]`` on a body of shells).

A rigid body whose nodes are shell nodes carries their rotations: their rotational
inertia I (kg m^2, one value about every axis: :mod:`rwall_fem.shells.inertia`) joins the
body's inertia tensor about its centre (J0 += sum I 1), the moments on them (the cells'
and damping's, I alpha after the body's accelerate) join its torque, and after its motion
is found their angular velocity is the body's, w^{n+1/2} = omega^{n+1/2} (their angular
acceleration set so that the update gives exactly that). Their rotational kinetic energy
is the body's (``rigid_body`` in ``energy.csv``), not the shells' ``rotational_kinetic``.
"""

from __future__ import annotations

import numpy as np

__all__ = ["RigidRotations", "carry_rotations"]


class RigidRotations:
    """The rotations of the owned ``nodes`` (local indices) of the shell body ``shells``
    (a :class:`~rwall_fem.shells.body.ShellBody`) in one rigid body."""

    def __init__(self, shells, nodes: np.ndarray):
        self.shells, self.nodes = shells, np.asarray(nodes, dtype=np.int64)
        self._before = np.zeros((len(self.nodes), 3))  # w^{n-1/2}, rad/s

    def torque(self) -> np.ndarray:
        """This rank's sum of the moments I alpha on the nodes (N m), and keep their
        angular velocities w^{n-1/2}."""
        shells, nodes = self.shells, self.nodes
        self._before = shells.w.owned[nodes].copy()
        return shells.inertia[nodes, 1] @ shells.alpha[nodes]

    def follow(self, omega: np.ndarray, dt_v: float) -> None:
        """Set the nodes' angular accelerations so that the update gives them the angular
        velocity ``omega`` (rad/s)."""
        self.shells.alpha[self.nodes] = (omega - self._before) / dt_v

    def checkpoint_state(self) -> dict[str, np.ndarray]:
        return {"w_before": self._before}

    def restore_state(self, arrays: dict[str, np.ndarray]) -> None:
        self._before = arrays["w_before"].copy()


def carry_rotations(bodies, shells, comm) -> None:
    """Give each rigid body of ``bodies`` (:class:`~rwall_fem.rigid_body.RigidBody`) the
    rotations of its shell nodes: their inertia in its tensor, their angular velocity set
    to its own, their rotational kinetic energy taken out of the shells' (collective)."""
    weight = np.ones(len(shells.inertia))
    for body in bodies:
        nodes = body.nodes
        extra = comm.allreduce(float(shells.inertia[nodes, 1].sum()))
        body.inertia0 = body.inertia0 + extra * np.eye(3)
        body.inverse0 = np.linalg.inv(body.inertia0)
        body.angular_momentum = body.inertia0 @ body.omega
        body.previous = (body.velocity.copy(), body.angular_momentum.copy(), body.omega.copy())
        shells.w.owned[nodes] = body.omega
        body.rotations = RigidRotations(shells, nodes)
        weight[nodes] = 0.0
    shells.turning = weight
