"""Body forces that a scene may switch on; each is in the step only when asked for.

An effect adds its acceleration to ``state.a`` and knows the work (J) it has
done on this rank's nodes, booked like every other force at mid-step
velocities (see :mod:`rwall_fem.output.energy`).
"""

from __future__ import annotations

import numpy as np

__all__ = ["Gravity"]


class Gravity:
    """Uniform gravity ``acceleration`` (m/s^2) on every node."""

    name = "gravity"

    def __init__(self, acceleration, state):
        self.g = np.asarray(acceleration, dtype=float)
        self._initial_momentum = np.sum(state.mass[:, None] * state.v, axis=0)

    def accelerate(self, state) -> None:
        state.a += self.g

    def checkpoint_state(self) -> dict[str, np.ndarray]:
        """The momentum sum m v^{-1/2} of the start (kg m/s), on which its work rests."""
        return {"initial_momentum": self._initial_momentum}

    def restore_state(self, arrays: dict[str, np.ndarray]) -> None:
        self._initial_momentum[:] = arrays["initial_momentum"]

    def work(self, state) -> float:
        """Work of gravity on this rank's nodes up to step n (J), after the update of step n.

        Mid-step booking of a constant force G = m g sums to
        G . (u^n - u^0) + dt/2 G . v^{-1/2}, i.e. g . (sum m u^n + dt/2 sum m v^{-1/2}):
        the update books sum m u^n (``state.mass_moment``) at no extra cost.
        """
        return float(self.g @ (state.mass_moment + 0.5 * state.dt * self._initial_momentum))
