"""When a recorder samples: every k-th step, or at times spread over the run.

The step varies, so outputs asked for at times are written at the first step at or after
each time (Radioss's ``/ANIM/DT``, LS-DYNA's ``*DATABASE`` intervals), the last one at the run's
last step; outputs never change the steps.
"""

from __future__ import annotations

__all__ = ["Every", "Times"]


class Every:
    """Steps 0, k, 2k, ... and the run's last step."""

    def __init__(self, k: int):
        self.k = k

    def due(self, state) -> bool:
        return state.step % self.k == 0 or state.last

    def taken(self, state) -> None:
        """Nothing to remember."""


class Times:
    """``count`` times spread evenly over [0, ``end_time``] (s), both ends included: a
    recorder is due at the first step at or after each of them, and at the last step for
    what is left. Several times passed in one step give one sample. :attr:`next` is the
    index of the next time (what a checkpoint keeps)."""

    def __init__(self, count: int, end_time: float):
        self.count, self.end_time = count, end_time
        self.next = 0

    def time(self, k: int) -> float:
        """The k-th time (s)."""
        return 0.0 if self.count <= 1 else k * self.end_time / (self.count - 1)

    def due(self, state) -> bool:
        if self.next >= self.count:
            return False
        # A step that lands on a time up to round-off (a sum of steps) counts.
        return state.last or state.t >= self.time(self.next) - 1e-9 * state.dt

    def taken(self, state) -> None:
        """A sample was taken at this step: go past every time it covers."""
        if state.last:
            self.next = self.count
        while self.next < self.count and state.t >= self.time(self.next) - 1e-9 * state.dt:
            self.next += 1
