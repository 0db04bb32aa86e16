"""The update of a step of a shell body: central differences on translations and
rotations, in one compiled sweep over the nodes (``shell_central_difference`` of
``kernels/update.c``).

Each node's translations advance as the solids' (:class:`~rwall_fem.solver.CentralDifference`)
and its rotations in the same sweep, with the same steps: w^{n+1/2} = w^{n-1/2} + dt^n alpha^n,
the angular velocity in the global frame, alpha^n = -M^n / I from the body's moments (rad/s,
rad/s^2, N m, kg m^2). The pass books the rotations' shadow kinetic energy
1/2 sum I w^{n-1/2} . w^{n+1/2} and the sums M . w^{n-1/2} and M . w^{n+1/2} of the moments'
work, as it does for the forces (``docs/theory.md``, "Energy balance"). The rotations are
angular velocities only (the elements take their frame from the current coordinates): no
nodal triad is turned.
"""

from __future__ import annotations

import functools
import operator

import numpy as np

from rwall_fem.kernels import load
from rwall_fem.solver import CentralDifference

__all__ = ["ShellUpdate"]


class ShellUpdate(CentralDifference):
    """The update of ``state`` and of the rotations of the :class:`~rwall_fem.shells.body.ShellBody`
    ``body``, its internal force."""

    def __init__(self, state, body):
        self.body = body
        self._turns = np.zeros(3)  # 1/2 sum I w- . w+, sum M . w-, sum M . w+
        super().__init__(state, body)

    def _bind(self, state) -> None:
        """Bind the compiled pass to the state's arrays (the translations', as the solids')
        and to the body's (the body's ``turning``, 0 at a rigid body's nodes, may come after
        the update is built), keeping them."""
        super()._bind(state)
        ffi, lib = load()
        body = self.body
        w, moments = body.w.owned, body.moments
        turning = getattr(body, "turning", None)
        rotations = (body.inertia, turning, body.alpha, moments, w)
        for array in rotations:
            if array is not None and not array.flags.c_contiguous:
                raise ValueError("a shell body's inertia, alpha, moments and w must be "
                                 "C-contiguous")  # fmt: skip
        if len(body.inertia) != len(w) or body.inertia.shape[1:] != (2,):
            raise ValueError("a shell body's inertia must be (nodes, 2): masses, inertias")

        def ptr(array):
            return ffi.cast("double *", array.ctypes.data) if array is not None else ffi.NULL

        self._bound_turning = turning
        self._pass = functools.partial(lib.shell_central_difference, len(w))
        self._arrays = self._arrays[:10] + (*map(ptr, rotations), ptr(self._turns))
        self._keep = rotations  # what the rotations' pointers point into

    def __call__(self, state) -> None:
        body = self.body
        arrays = self._state_arrays(state)
        if getattr(body, "turning", None) is not self._bound_turning or any(
            map(operator.is_not, arrays, self._bound)
        ):
            self._bind(state)  # another state, or the body's turning given late
        if self._part_sums is not None:
            self._part_sums[:] = 0.0
        self._pass(state.dt_velocity, state.dt, *self._arrays)
        state.kinetic = self._out[0]
        body.rotational_kinetic, *sums = self._turns.tolist()
        body.rotational_sums = tuple(sums)
        if self._internal is not None:
            self._internal.book(state, self._out[1], self._out[2])
