"""A run whose step collapses (issue 28, class 7): the cycle lines of ``run.log`` go on
(at least every 1/20 of the steps planned) and show the steps left at the current step
and the wall time they take; one warning, naming the cell that controls the step, when
the run would take more than ``COLLAPSE_FACTOR`` times the steps planned at the start.

Reference: the copper bar crushed by a wall on a main node, whose step falls over three
times within 30 us (``test_time_step.py``); the factor is lowered to 2 here, so that the
warning comes within the test's steps. The projection is checked against its definition
(step + ceil((end_time - t) / dt)) from the line's own columns, and the warning's step
against the lines before and after it."""

import re

from conftest import run
from mpi4py import MPI
from test_time_step import crush_scene

from rwall_fem.output import projection

LINE = re.compile(r"^ +(\d+) +(\S+) +(\S+) +(\S+) +(\S+) +(\d+) +(\S+) +(\S+)  at ", re.MULTILINE)


def test_a_collapsing_step_is_projected_and_warned_once(shared_dir, monkeypatch):
    monkeypatch.setattr(projection, "COLLAPSE_FACTOR", 2.0)
    sim = run(crush_scene(), shared_dir)
    assert sim.status == "done"
    if MPI.COMM_WORLD.rank:
        return
    log = (shared_dir / "run.log").read_text()
    planned, end = sim.planned_steps, sim.end_time
    lines = [(int(c[0]), float(c[1]), float(c[2]), int(c[5])) for c in LINE.findall(log)]
    assert lines[-1][0] == sim.state.step and lines[-1][3] == 0
    for step, t, dt, left in lines[:-1]:
        # the line's own figures, printed to 5 and 6 digits
        assert abs(left - (end - t) / dt) <= 1.0 + 1e-4 * left
    gaps = [b[0] - a[0] for a, b in zip(lines, lines[1:], strict=False)]
    assert max(gaps) <= max(1, planned // projection.LINES)
    [warning] = re.findall(r"^warning: (.*)$", log, re.MULTILINE)
    assert f"times the {planned} planned at the start" in warning
    assert "it is set by the cell at (" in warning and "plastic strain" in warning
    assert "run.dt_min" in warning and "run.dt_min_action" in warning
    step = int(warning.split(",")[0].removeprefix("step "))
    projected = [(s + left) for s, _, _, left in lines]
    at = [s for s, _, _, _ in lines].index(step)
    assert projected[at] > 2.0 * planned and all(p <= 2.0 * planned for p in projected[:at])
