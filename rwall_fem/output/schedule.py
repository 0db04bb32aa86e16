"""When a recorder samples: every k-th step, at times spread over the run, or at the
multiples of a time interval.

The step varies, so outputs asked for at times are written at the first step at or after
each time (Radioss's ``/ANIM/DT`` and ``/TFILE``, LS-DYNA's ``*DATABASE`` intervals), the last
one at the run's last step; outputs never change the steps. A schedule decides from the
step's number or time alone, which every rank has alike, so the ranks sample at the same
steps without exchanging anything.
"""

from __future__ import annotations

import math

__all__ = ["Every", "Interval", "Times"]


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


class Interval:
    """The multiples 0, T, 2T, ... of ``interval`` T (s): a recorder is due at the first step
    at or after each of them (the run's first step is at 0) and at the run's last step.
    Several multiples passed in one step give one sample. :attr:`next` is the index of the
    next multiple (what a checkpoint keeps)."""

    def __init__(self, interval: float):
        self.interval = interval
        self.next = 0

    def _reached(self, state) -> bool:
        # A step that lands on a multiple up to round-off (a sum of steps) counts.
        return state.t >= self.next * self.interval - 1e-9 * state.dt

    def due(self, state) -> bool:
        return state.last or self._reached(state)

    def taken(self, state) -> None:
        """A sample was taken at this step: go past every multiple it reached."""
        if self._reached(state):
            reached = math.floor((state.t + 1e-9 * state.dt) / self.interval)
            self.next = max(self.next + 1, reached + 1)
