"""A progress bar for the command line (rank 0, terminals only, runs longer than a second)."""

from __future__ import annotations

import sys

from rwall_fem.output.projection import steps_left

__all__ = ["Progress"]


class Progress:
    """Recorder that shows the share of ``end_time`` (s) simulated, step, dt, the energy
    balance error, the steps left at the current step and the time left at the present
    rate of simulated time (the step varies, so the bar counts time, not steps); updated
    about ``updates`` times over the run, and at least every ``updates``-th of the steps
    planned at the start (a step that collapses still updates it)."""

    def __init__(self, end_time: float, updates: int = 500):
        from tqdm import tqdm

        self.end_time, self.every = end_time, end_time / updates
        self._bar = tqdm(
            total=100.0,
            unit="%",
            delay=1.0,
            file=sys.stderr,
            dynamic_ncols=True,
            leave=False,
            bar_format="{l_bar}{bar}| {n:.1f}/100 % [{elapsed}<{remaining}{postfix}]",
        )
        self.updates = updates
        self._next = 0.0
        self._next_step = 0

    def due(self, s) -> bool:
        return s.t >= self._next or s.last or s.step >= self._next_step

    def record(self, sim, s) -> None:
        self._next = s.t + self.every
        self._next_step = s.step + max(1, sim.planned_steps // self.updates)
        latest = sim.history.balance.error
        error = "-" if latest is None else f"{latest:.1e}"
        self._bar.set_postfix_str(
            f"step {s.step}, t = {s.t:.4g} s, dt = {s.dt:.3g} s, "
            f"{steps_left(sim, s)} steps left, energy error {error}",
            refresh=False,
        )
        self._bar.update(min(100.0 * s.t / self.end_time, 100.0) - self._bar.n)

    def close(self, sim) -> None:
        self._bar.close()
