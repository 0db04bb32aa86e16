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

from rwall_fem.kernels import load
from rwall_fem.walls.motion import PrescribedMotion

__all__ = ["VelocityBoundary"]

# The most values the compiled pass sums as NumPy does (one block of NumPy's buffer; more,
# and NumPy sums them, as its versions differ there).
_SUMMED = 8192


class VelocityBoundary:
    """Prescribed velocity of some components of the nodes ``nodes`` (local indices, a set:
    each node once).

    ``velocity`` is [vx, vy, vz] (m/s) or rows [t, vx, vy, vz] (s, m/s) interpolated
    linearly; ``components`` (a subset of "xyz") are the global directions prescribed,
    the others stay free. The pass over the nodes is compiled (``kernels/boundary.c``).
    """

    def __init__(self, name: str, nodes: np.ndarray, velocity, components: str = "xyz"):
        self.name = name
        self.nodes = np.asarray(nodes, dtype=np.int32)
        self.prescribed = PrescribedMotion(velocity)  # the velocity history
        self.axes = np.array(["xyz".index(c) for c in components])
        # The prescribed values' places in a C-contiguous (nodes, 3) array, (nodes, axes)
        self._flat = 3 * self.nodes.astype(np.int64)[:, None] + self.axes[None, :]
        # The impulse's components that the sums add to: all of them in order, or some.
        self._components = slice(None) if self.axes.tolist() == [0, 1, 2] else self.axes
        self.impulse = np.zeros(3)  # reaction on this rank's nodes so far, N s
        self.work = 0.0  # work of the reaction up to step n, J (mid-step booking)
        self._reaction = None  # the latest step's reaction (N s), for its v^{n+1/2} half
        # What the compiled pass writes: the reaction (N s), its power (N m/s), its sums per
        # component (N s); and the prescribed velocity (m/s) when it is constant.
        self._reactions = np.zeros(self._flat.shape)
        self._power = np.zeros(self._flat.shape)
        self._sums = np.zeros(len(self.axes))
        self._works = np.zeros(2)  # the powers summed, the latest step's and this one's
        self._target = np.zeros(len(self.axes))
        self._constant = len(self.prescribed.times) == 1
        if self._constant:
            self._target[:] = self.prescribed.values[0][self.axes]
        self._bound = None  # (state, its pointers), at the first step

    def checkpoint_state(self) -> dict[str, np.ndarray]:
        """The reaction impulse and work so far, and the latest step's reaction (N s)."""
        reaction = self._reaction if self._reaction is not None else np.zeros((0, len(self.axes)))
        return {"impulse": self.impulse, "work": np.array(self.work), "reaction": reaction}

    def restore_state(self, arrays: dict[str, np.ndarray]) -> None:
        self.impulse[:] = arrays["impulse"]
        self.work = float(arrays["work"])
        self._reaction = arrays["reaction"] if len(arrays["reaction"]) else None

    def _pointers(self, state):
        """The pass's pointers into ``state`` (whose arrays never move) and this condition's
        arrays, bound at its first step."""
        if self._bound is None or self._bound[0] is not state:
            ffi, lib = load()
            p = ffi.from_buffer
            pointers = {
                "v": p("double[]", state.v), "a": p("double[]", state.a),
                "mass": p("double[]", state.mass), "nodes": p("int32_t[]", self.nodes),
                "flat": p("int64_t[]", self._flat), "target": p("double[]", self._target),
                "reactions": p("double[]", self._reactions),
                "power": p("double[]", self._power), "sums": p("double[]", self._sums),
                "works": p("double[]", self._works),
            }  # fmt: skip
            self._bound = (state, ffi, lib, pointers)
        return self._bound[1:]

    def settle(self, state) -> None:
        """Book the v^{n+1/2} half of the work of the latest step's reaction with the
        velocities the nodes now have; before the masses change, and at every step."""
        if self._reaction is not None:
            ffi, lib, q = self._pointers(state)
            reaction = self._reaction  # the pass's array, or a checkpoint's
            r = q["reactions"] if reaction is self._reactions else ffi.from_buffer(
                "double[]", np.ascontiguousarray(reaction))  # fmt: skip
            lib.boundary_power(reaction.size, q["flat"], r, q["v"], q["power"])
            self.work += 0.5 * float(np.sum(self._power))
            self._reaction = None

    def constrain(self, state) -> None:
        """Set ``state.a`` of the prescribed components so that v^{n+1/2} = v_p(t_n +
        dt^{n+1/2}/2), the velocity update's step being dt^n (``state.dt_velocity``)."""
        if not self._constant:
            self._target[:] = self.prescribed.predict(state.t, state.dt)[self.axes]
        summed = self._reactions.size <= _SUMMED
        settle = summed and self._reaction is self._reactions  # in the same pass
        if not settle:
            self.settle(state)
        ffi, lib, q = self._pointers(state)
        lib.boundary_velocity(
            len(self.nodes), len(self.axes), q["nodes"], q["flat"], q["target"],
            state.dt_velocity, q["mass"], q["v"], q["a"], q["reactions"], q["power"], q["sums"],
            settle, q["works"],
        )  # fmt: skip
        latest, now = self._works.tolist()
        if settle:
            self.work += 0.5 * latest
        self.work += 0.5 * (now if summed else float(np.sum(self._power)))
        self._reaction = self._reactions
        # NumPy's sum over the nodes of one component is pairwise, of 2 or 3 in node order.
        sums = self._sums if len(self.axes) > 1 else self._reactions.sum(axis=0)
        self.impulse[self._components] += sums
