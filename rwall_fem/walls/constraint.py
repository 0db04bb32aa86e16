"""The kinematic rigid-wall condition (spec section 4), shared by all shapes.

After the acceleration solve, each secondary node's velocity is predicted,
``v* = v^{n-1/2} + dt a^n``, and its position, ``x* = x^n + dt v*``. A node
whose predicted position is on the forbidden side (and, on planes, whose
relative normal velocity points into the wall) is in contact: the wall
applies the impulse that removes its relative normal velocity. The impulse
is added to ``a^n`` as ``I / (m dt)``, which gives exactly the velocity
``v^{n+1/2}`` of editing both ``v^{n-1/2}`` and ``a^n``. The node stops where
it is, up to one step of travel short of the surface: no projection.
"""

from __future__ import annotations

import numpy as np

__all__ = ["RigidWall"]


class RigidWall:
    """A fixed rigid wall acting on the owned secondary nodes ``nodes`` of a body.

    Attributes accumulated on this rank (reduce over ranks to report them):
    ``impulse`` (N s), the push of the structure on the wall; ``work`` (J), the
    work of the wall on the structure booked at mid-step velocities; and the
    contact counters.
    """

    def __init__(self, shape, nodes: np.ndarray, name: str):
        self.shape = shape
        self.name = name
        self.nodes = np.asarray(nodes, dtype=np.int64)
        self.impulse = np.zeros(3)
        self.work = 0.0
        self.contacts = 0  # nodes treated in the latest step
        self.first_contact = np.inf  # s
        self.last_contact = -np.inf  # s
        self._pending_work = 0.0  # 1/2 I^n . v^{n+1/2}, booked at the next step

    def constrain(self, state) -> None:
        """Edit ``state.a`` of the secondary nodes in contact at step ``state.step``."""
        dt, idx = state.dt, self.nodes
        v_old = state.v[idx]
        v_pred = v_old + dt * state.a[idx]
        x_pred = state.X[idx] + state.u[idx] + dt * v_pred
        d = self.shape.distance(x_pred)
        n = self.shape.normals(x_pred)
        vn = v_pred @ n if n.ndim == 1 else np.einsum("ij,ij->i", v_pred, n)
        hit = d < 0.0
        if not self.shape.radial:
            hit &= vn < 0.0
        self.work += self._pending_work
        self._pending_work = 0.0
        self.contacts = int(np.count_nonzero(hit))
        if not self.contacts:
            return
        nh = n if n.ndim == 1 else n[hit]
        dv = -vn[hit, None] * nh
        m = state.mass[idx[hit], None]
        state.a[idx[hit]] += dv / dt
        impulse = m * dv
        self.impulse -= impulse.sum(axis=0)
        self.work += 0.5 * np.sum(impulse * v_old[hit])
        self._pending_work = 0.5 * np.sum(impulse * (v_pred[hit] + dv))
        self.first_contact = min(self.first_contact, state.t)
        self.last_contact = state.t
