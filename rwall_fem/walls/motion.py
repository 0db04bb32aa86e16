"""How a wall moves: fixed, carried by a main node of given mass, or prescribed.

A moving wall translates and never rotates (``docs/theory.md``, "Fixed and moving
walls"): its state is the translation ``offset`` (m) of its defining points at time
t_n and its velocity (m/s) over the current step. Every rank holds the same wall state: whatever
changes it (the contact impulse) is summed over ranks first.
"""

from __future__ import annotations

import numpy as np

__all__ = ["FixedMotion", "MainNodeMotion", "PrescribedMotion"]


class FixedMotion:
    """A wall that never moves: a pure kinematic condition."""

    dynamic = False
    prescribed = False
    mass = np.inf

    def __init__(self):
        self.offset = np.zeros(3)
        self.velocity = np.zeros(3)  # V^{n+1/2}
        self.previous_velocity = np.zeros(3)  # V^{n-1/2}

    def predict(self, t: float, dt: float) -> np.ndarray:
        """Wall velocity (m/s) over [t, t + dt] before this step's contact impulse."""
        return self.velocity

    def advance(self, velocity: np.ndarray, dt: float) -> None:
        """Take ``velocity`` (m/s) as V^{n+1/2} and move by ``dt`` (s)."""

    def checkpoint_state(self) -> dict[str, np.ndarray]:
        """The translation (m) and the velocities over the latest two steps (m/s)."""
        return {
            "offset": self.offset,
            "velocity": self.velocity,
            "previous_velocity": self.previous_velocity,
        }

    def restore_state(self, arrays: dict[str, np.ndarray]) -> None:
        self.offset = arrays["offset"].copy()
        self.velocity = arrays["velocity"].copy()
        self.previous_velocity = arrays["previous_velocity"].copy()


class _Translating(FixedMotion):
    """A wall that moves: each step translates it by dt times its velocity over the step."""

    def advance(self, velocity: np.ndarray, dt: float) -> None:
        self.previous_velocity = self.velocity
        self.velocity = np.asarray(velocity, dtype=float)
        self.offset = self.offset + dt * self.velocity


class MainNodeMotion(_Translating):
    """A wall carried by a main node of ``mass`` (kg) starting at ``velocity`` (m/s).

    Contact impulses act on the main node by momentum conservation, but for the global
    components ``held`` (some of "xyz"), which keep their initial velocity: the main node
    of a half or quarter model lies on its symmetry planes, and may not leave them.
    """

    dynamic = True

    def __init__(self, mass: float, velocity, held: str = ""):
        super().__init__()
        self.mass = float(mass)
        self.velocity = np.asarray(velocity, dtype=float).copy()
        self.previous_velocity = self.velocity.copy()
        self.held = np.array(["xyz".index(c) for c in held], dtype=int)


class PrescribedMotion(_Translating):
    """A wall that follows a velocity history, whatever hits it.

    ``table`` is a constant velocity [vx, vy, vz] (m/s) or rows [t, vx, vy, vz]
    (s, m/s) interpolated linearly and held constant outside the table.
    """

    prescribed = True

    def __init__(self, table):
        table = np.atleast_2d(np.asarray(table, dtype=float))
        if table.shape[1] == 3:
            table = np.hstack([[[0.0]], table])
        self.times, self.values = table[:, 0], table[:, 1:]
        super().__init__()
        self.velocity = self._at(0.0)
        self.previous_velocity = self.velocity.copy()

    def _at(self, t: float) -> np.ndarray:
        if len(self.times) == 1:  # a constant velocity: no interpolation at each step
            return self.values[0].copy()
        return np.array([np.interp(t, self.times, column) for column in self.values.T])

    def predict(self, t: float, dt: float) -> np.ndarray:
        return self._at(t + 0.5 * dt)
