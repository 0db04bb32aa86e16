"""The rows of ``walls.csv``: per wall and sample, the push of the structure on the wall.

Forces are the change of the cumulative impulses since the previous sample over the
time between the two (N; at the first sample, over the velocity update's step);
impulses are cumulative (N s). Both are the push of the
structure on the wall: negative along the normal of a wall hit from its allowed side.
"""

from __future__ import annotations

import numpy as np

__all__ = ["WALL_COLUMNS", "WallTable"]

WALL_COLUMNS = (
    ["time", "wall"]
    + [f"force_{c}" for c in "xyz"]
    + [f"impulse_{c}" for c in "xyz"]
    + [f"normal_force_{c}" for c in "xyz"]
    + [f"tangential_force_{c}" for c in "xyz"]
    + [f"normal_impulse_{c}" for c in "xyz"]
    + [f"tangential_impulse_{c}" for c in "xyz"]
    + ["contacts"]
    + [f"position_{c}" for c in "xyz"]
    + [f"velocity_{c}" for c in "xyz"]
)


class WallTable:
    """Turns the per-wall sums of a sample into rows with the columns of ``walls.csv``.

    :attr:`sums` gives the shape of each per-rank quantity it needs summed over ranks
    (the history reduces them with everything else of the sample in one call).
    """

    def __init__(self, walls):
        self.walls = walls
        n = len(walls)
        # Per wall: the normal and the tangential impulse (N s), and the contacts.
        self.sums = {"impulses": (n, 6), "contacts": (n,)}
        self.peak_contacts = np.zeros(n, dtype=int)  # most nodes treated in one step
        self._last_impulses = np.zeros((n, 6))  # normal and tangential, N s
        self._last_time = None  # s

    def checkpoint_state(self) -> dict[str, np.ndarray]:
        """The impulses (N s) and time (s) of the latest sample (forces are differences from
        them), and the peak contact counts."""
        last = np.nan if self._last_time is None else self._last_time
        return {
            "last_impulses": self._last_impulses,
            "last_time": np.array(last),
            "peak_contacts": self.peak_contacts,
        }

    def restore_state(self, arrays: dict[str, np.ndarray]) -> None:
        self._last_impulses[:] = arrays["last_impulses"]
        last = float(arrays["last_time"])
        self._last_time = None if np.isnan(last) else last
        self.peak_contacts[:] = arrays["peak_contacts"]

    def fill(self, local: dict) -> None:
        """Write this rank's impulses (N s) and contact counts into the ``local`` sums."""
        for i, w in enumerate(self.walls):
            local["impulses"][i, :3] = w.normal_impulse
            local["impulses"][i, 3:] = w.tangential_impulse
            local["contacts"][i] = w.contacts

    def rows(self, state, total: dict) -> list[tuple]:
        """The rows of step ``state.step`` from the sums over ranks ``total`` (in Python
        floats: a few walls of a few values each)."""
        if self._last_time is None:
            interval = state.dt_velocity  # s: the first step's impulses act over it
        else:
            interval = state.t - self._last_time  # s since the previous sample
        self._last_time = state.t
        rows = []
        for i, (w, impulses, last, contacts) in enumerate(
            zip(self.walls, total["impulses"].tolist(), self._last_impulses.tolist(),
                total["contacts"].tolist(), strict=True)
        ):  # fmt: skip
            if interval:
                forces = [
                    (now - before) / interval for now, before in zip(impulses, last, strict=True)
                ]
            else:  # the time did not advance (a step below its resolution): inf or nan
                forces = ((np.array(impulses) - last) / interval).tolist()
            force = [forces[c] + forces[c + 3] for c in range(3)]
            impulse = [impulses[c] + impulses[c + 3] for c in range(3)]
            contacts = int(contacts)
            self.peak_contacts[i] = max(self.peak_contacts[i], contacts)
            motion = (*w.position.tolist(), *w.motion.velocity.tolist())
            rows.append((state.t, i, *force, *impulse, *forces, *impulses, contacts, *motion))
        self._last_impulses[:] = total["impulses"]
        return rows
