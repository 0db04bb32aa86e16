"""Velocity boundary conditions on named node sets (clamps, driven edges).

LS-DYNA's ``*BOUNDARY_SPC`` / ``*BOUNDARY_PRESCRIBED_MOTION_SET`` and Radioss
``/BCS`` / ``/IMPVEL`` in one: the chosen global components of the velocity of
a set of nodes follow a history (zero: clamped). Applied after the walls, so a
clamp wins over a wall on a node both act on.

The reaction is the impulse that sets the step's velocity, m (v_p - v_pred);
its work is booked at mid-step velocities like every other force (see
:mod:`rwall_fem.output.energy`): the half with v^{n-1/2} at step n, the half with
v^{n+1/2} at the next step, read from the state then (so that whatever acted
after it on the same node, the balance closes exactly).
"""

from __future__ import annotations

import numpy as np

from rwall_fem.walls.motion import PrescribedMotion

__all__ = ["VelocityBoundary"]


class VelocityBoundary:
    """Prescribed velocity of some components of the nodes ``nodes`` (local indices).

    ``velocity`` is [vx, vy, vz] (m/s) or rows [t, vx, vy, vz] (s, m/s) interpolated
    linearly; ``components`` (a subset of "xyz") are the global directions prescribed,
    the others stay free.
    """

    def __init__(self, name: str, nodes: np.ndarray, velocity, components: str = "xyz"):
        self.name = name
        self.nodes = np.asarray(nodes, dtype=np.int32)
        self.prescribed = PrescribedMotion(velocity)  # the velocity history
        self.axes = np.array(["xyz".index(c) for c in components])
        # The prescribed values' places in a C-contiguous (nodes, 3) array, (nodes, axes)
        self._flat = 3 * self.nodes.astype(np.int64)[:, None] + self.axes[None, :]
        self.impulse = np.zeros(3)  # reaction on this rank's nodes so far, N s
        self.work = 0.0  # work of the reaction up to step n, J (mid-step booking)
        self._reaction = None  # the latest step's reaction (N s), for its v^{n+1/2} half

    def checkpoint_state(self) -> dict[str, np.ndarray]:
        """The reaction impulse and work so far, and the latest step's reaction (N s)."""
        reaction = self._reaction if self._reaction is not None else np.zeros((0, len(self.axes)))
        return {"impulse": self.impulse, "work": np.array(self.work), "reaction": reaction}

    def restore_state(self, arrays: dict[str, np.ndarray]) -> None:
        self.impulse[:] = arrays["impulse"]
        self.work = float(arrays["work"])
        self._reaction = arrays["reaction"] if len(arrays["reaction"]) else None

    def settle(self, state) -> None:
        """Book the v^{n+1/2} half of the work of the latest step's reaction with the
        velocities the nodes now have; before the masses change, and at every step."""
        if self._reaction is not None:
            v_now = state.v.reshape(-1)[self._flat]
            self.work += 0.5 * float(np.sum(self._reaction * v_now))
            self._reaction = None

    def constrain(self, state) -> None:
        """Set ``state.a`` of the prescribed components so that v^{n+1/2} = v_p(t_n +
        dt^{n+1/2}/2), the velocity update's step being dt^n (``state.dt_velocity``)."""
        rows = self._flat  # of the (n, 3) arrays' values
        target = self.prescribed.predict(state.t, state.dt)[self.axes]
        self.settle(state)
        v_old = state.v.reshape(-1)[rows]
        m = state.mass[self.nodes][:, None]
        dt_v = state.dt_velocity
        a = state.a.reshape(-1)  # a view: the state is C-contiguous (the update asks it)
        reaction = m * (target - v_old - dt_v * a[rows])  # N s
        a[rows] = (target - v_old) / dt_v
        self.work += 0.5 * float(np.sum(reaction * v_old))
        self._reaction = reaction
        self.impulse[self.axes] += reaction.sum(axis=0)
