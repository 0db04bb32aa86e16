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

    def __init__(self, acceleration):
        self.g = np.asarray(acceleration, dtype=float)

    def accelerate(self, state) -> None:
        state.a += self.g

    def work(self, state) -> float:
        """Work of gravity on this rank's nodes up to step n (J), after the update of step n.

        Mid-step booking of the force m g sums to g . (sum over steps of dt^k/2 (P^{k-1/2}
        + P^{k+1/2})), P = sum m v: the update books that momentum integral
        (``state.momentum_integral``) at no extra cost, whatever the steps and masses."""
        return float(self.g @ state.momentum_integral)
