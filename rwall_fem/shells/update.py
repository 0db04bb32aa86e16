"""The update of a step of a shell body: central differences on translations and
rotations.

The translations go through the solids' compiled pass
(:class:`~rwall_fem.solver.CentralDifference`); the rotations follow in the same step, with
the same steps: w^{n+1/2} = w^{n-1/2} + dt^n alpha^n, the angular velocity in the global
frame, alpha^n = -M^n / I from the body's moments (rad/s, rad/s^2, N m, kg m^2). The step
books the rotations' shadow kinetic energy 1/2 sum I w^{n-1/2} . w^{n+1/2} and the sums
M . w^{n-1/2} and M . w^{n+1/2} of the moments' work, as the translations' pass does for
the forces (``docs/theory.md``, "Energy balance"). Vectorised over the nodes.
"""

from __future__ import annotations

import numpy as np

from rwall_fem.solver import CentralDifference

__all__ = ["ShellUpdate"]


class ShellUpdate(CentralDifference):
    """The update of ``state`` and of the rotations of the :class:`~rwall_fem.shells.body.ShellBody`
    ``body``, its internal force."""

    def __init__(self, state, body):
        super().__init__(state, body)
        self.body = body
        self._w_old = np.zeros_like(body.w.owned)

    def __call__(self, state) -> None:
        body = self.body
        w, alpha, moments = body.w.owned, body.alpha, body.moments
        inertia = body.inertia[:, 1]
        self._w_old[:] = w
        first = float(np.einsum("ij,ij->", moments, w))
        w += state.dt_velocity * alpha
        turning = getattr(body, "turning", None)  # 0 at a rigid body's nodes: its energy
        if turning is not None:
            inertia = inertia * turning
        body.rotational_kinetic = 0.5 * float(
            np.einsum("i,ij,ij->", inertia, self._w_old, w)
        )
        body.rotational_sums = (first, float(np.einsum("ij,ij->", moments, w)))
        super().__call__(state)
