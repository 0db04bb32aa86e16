"""A progress bar for the command line (rank 0, terminals only, runs longer than a second)."""

from __future__ import annotations

import sys

from rwall_fem.output.schedule import Every

__all__ = ["Progress"]


class Progress:
    """Recorder that shows simulated time, step, steps/s, ETA and the energy balance error."""

    def __init__(self, num_steps: int, updates: int = 500):
        from tqdm import tqdm

        self.steps = Every(max(1, num_steps // updates), num_steps)
        self._bar = tqdm(
            total=num_steps + 1,
            unit="step",
            delay=1.0,
            file=sys.stderr,
            dynamic_ncols=True,
            leave=False,
        )
        self._shown = 0

    def due(self, step: int) -> bool:
        return step in self.steps

    def record(self, sim, s) -> None:
        latest = sim.history.balance.error
        error = "-" if latest is None else f"{latest:.1e}"
        self._bar.set_postfix_str(f"t = {s.t:.4g} s, energy error {error}", refresh=False)
        self._bar.update(s.step + 1 - self._shown)
        self._shown = s.step + 1

    def close(self, sim) -> None:
        self._bar.close()
