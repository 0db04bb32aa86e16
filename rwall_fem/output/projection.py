"""How far the run still has to go at its current step: the projection the cycle lines
and the progress bar show, and the warning when a step that collapsed puts the end out of
reach.

An adaptive step falls as cells are crushed; a user's small ``run.dt_scale`` or a cell
crushed flat can make it fall so far that the run would take a hundred times the steps
planned at the start. At each cycle line the projection is cheap arithmetic: the steps
left at the current step, ``ceil((end_time - t) / dt)``, and the wall time they take at the
mean wall time per step since the first line. Cycle lines are due at times spread over
the run, so a collapsed step would also stop them: :class:`CycleSteps` adds a line at least
every 1/20 of the steps planned at the start.
"""

from __future__ import annotations

import logging
import math

from rwall_fem.output.schedule import Every, Times

__all__ = ["COLLAPSE_FACTOR", "CycleSteps", "StepCollapse", "steps_left"]

log = logging.getLogger("rwall_fem")

COLLAPSE_FACTOR = 10.0  # projected over planned steps past which the run warns, once
LINES = 20  # with a step that stays as planned, cycle lines due by steps alone: this many


def steps_left(sim, s) -> int:
    """The steps from step ``s.step`` to ``sim.end_time`` at the current step ``s.dt``."""
    if s.last or s.dt <= 0.0:
        return 0
    return max(0, math.ceil((sim.end_time - s.t) / s.dt - 1e-9))


class CycleSteps:
    """When cycle lines are due: what ``schedule`` says (:class:`Every` steps, or
    :class:`Times` over the run), and with times at least every ``LINES``-th of the steps
    planned at the start (learnt at the first line), so that lines go on when the step
    collapses. The same steps on every rank (steps and times only)."""

    def __init__(self, schedule: Every | Times):
        self.schedule = schedule
        self.gap: int | None = None  # steps; None: by the schedule alone
        self._last = 0  # the step of the latest line

    @property
    def k(self) -> int:
        return self.schedule.k

    def due(self, s) -> bool:
        if self.schedule.due(s):
            return True
        return self.gap is not None and s.step - self._last >= self.gap

    def taken(self, sim, s) -> None:
        """A line was written at this step of ``sim``."""
        self.schedule.taken(s)
        if self.gap is None and isinstance(self.schedule, Times):
            self.gap = max(1, sim.planned_steps // LINES)
        self._last = s.step


class StepCollapse:
    """Warns once when the steps a run would take at its current step pass
    ``COLLAPSE_FACTOR`` times those planned at the start, naming the cell that controls the
    step (checked at the cycle lines, collective: the controlling cell is looked for on
    every rank)."""

    def __init__(self):
        self.warned = False

    def check(self, sim, s) -> str | None:
        """The warning's text the first time the projection passes the factor (every rank;
        rank 0 logs it), else None."""
        if self.warned:
            return None
        planned = sim.planned_steps
        projected = s.step + steps_left(sim, s)
        if projected <= COLLAPSE_FACTOR * planned:
            return None
        self.warned = True
        cell = sim.step_size.controlling_cell(describe=True)
        where = ""
        if cell is not None:
            position = ", ".join(f"{c:.4g}" for c in cell[1])
            part = f" in part {cell[3]}" if cell[3] else ""
            where = f"; it is set by the cell at ({position}) m{part}, {cell[2]}"
        text = (
            f"step {s.step}, t = {s.t:.6g} s: the step fell to {s.dt:.4g} s: at this step the "
            f"run would take {projected:.4g} steps, {projected / planned:.3g} times the "
            f"{planned} planned at the start{where}; set run.dt_min with run.dt_min_action "
            "('stop', 'mass_scaling' or 'erode') to bound the step"
        )
        log.warning("%s", text)
        return text
