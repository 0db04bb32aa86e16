"""The time step of a run: the stable step every cycle, or one step for the whole run.

``docs/theory.md`` ("Stable time step") has the theory. In short: every step, the
element kernels estimate each cell's stable step dt_e = L_e / c_e from its current shape
and wave speed (``kernels/step.h``); the run's stable step at rest, 2 / omega_max from
the largest eigenvalue (:func:`~rwall_fem.mechanics.critical_time_step`), calibrates
them once: ``calibration`` = min(1, exact / min_e L_e / c_e at rest), so that the estimate
never exceeds the exact limit at rest and follows the body as it deforms (the kernels
apply it; the limit of the damped hourglass modes of the viscous form stays as it is).

- :class:`AdaptiveStep` (``run.time_step = "adaptive"``, the default, as in Radioss and
  LS-DYNA): dt^{n+1/2} = dt_scale x min_e dt_e at step n (calibrated), rounded down to 4
  significant figures (the same step on any number of ranks), with the controls of
  ``run.dt_min``: stop there, or add mass to the cells that would go below it
  (:mod:`rwall_fem.mass_scaling`);
- :class:`FixedStep` (``"fixed"``): dt_scale of the stable step at rest, or ``run.dt``,
  for the whole run; the run stops when the deformation lowers the estimate below it.

Either stops the run, after the step in which it happens and its history sample, when
a cell turns inside out, and keeps the records of the run's steps (:class:`StepRecords`).
The estimates of all ranks are reduced once per step (one small ``Allreduce``); where a
cell is is gathered only when a message or an output needs it.
"""

from __future__ import annotations

import math

import numpy as np
from mpi4py import MPI

__all__ = ["AdaptiveStep", "FixedStep", "StepRecords", "round_down", "step_size"]


def round_down(dt: float, digits: int = 4) -> float:
    """``dt`` (s) rounded down to ``digits`` significant figures, so that the round-off of
    a sum in another order (another partitioning) rarely changes it."""
    unit = 10.0 ** (math.floor(math.log10(dt)) - digits + 1)
    return math.floor(dt / unit) * unit


def _position(x) -> str:
    return "(" + ", ".join(f"{c:.4g}" for c in x) + ") m"


class StepRecords:
    """The steps of a run (s): the first, the smallest and the largest, and where the cell
    that set the smallest was (m) at that step, for ``summary.json``. Collective only in
    :meth:`summary`."""

    def __init__(self, comm):
        self.comm = comm
        self.first = self.smallest = self.largest = math.nan
        self.smallest_step, self.smallest_time = -1, math.nan
        self._here = None  # this rank's position of the smallest's cell, when it is here

    def note(self, s, position) -> None:
        """Note the step ``s.dt`` chosen at step ``s.step``; ``position`` is where the cell
        that set it is (m) if this rank holds it, else None."""
        if s.step == 0 or math.isnan(self.first):
            self.first = s.dt
        if not s.dt >= self.smallest:  # also the first time (NaN)
            self.smallest, self.smallest_step, self.smallest_time = s.dt, s.step, s.t
            self._here = None if position is None else [float(c) for c in position]
        if not s.dt <= self.largest:
            self.largest = s.dt

    def summary(self) -> dict:
        """The records as ``summary.json`` gives them (collective)."""
        held = [p for p in self.comm.allgather(self._here) if p is not None]
        return {
            "first": _number(self.first),
            "smallest": _number(self.smallest),
            "largest": _number(self.largest),
            "smallest_at": {
                "step": self.smallest_step,
                "time": _number(self.smallest_time),
                "position": held[0] if held else None,
            },
        }

    def checkpoint_state(self) -> dict[str, np.ndarray]:
        here = self._here if self._here is not None else [math.nan] * 3
        when = [self.smallest_step, self.smallest_time]
        return {"records": np.array([self.first, self.smallest, self.largest, *when, *here])}

    def restore_state(self, arrays: dict[str, np.ndarray]) -> None:
        values = arrays["records"].tolist()
        self.first, self.smallest, self.largest, step, self.smallest_time = values[:5]
        self.smallest_step = int(step)
        self._here = None if math.isnan(values[5]) else values[5:8]


def _number(x: float) -> float | None:
    return float(x) if math.isfinite(x) else None


class _StepSize:
    """What both step sizes share: the reduction of the kernels' estimates over the ranks,
    the inverted-cell stop, the records, and going on to the next step.

    ``force`` is the body's :class:`~rwall_fem.body.Body` (None: no estimates,
    a step given by the caller), its estimates calibrated by ``calibration`` (what its
    kernels apply); ``initial`` (s) is the step at the start.
    """

    def __init__(self, initial: float, force=None, calibration: float = 1.0, comm=None):
        self.initial, self.force, self.calibration = initial, force, calibration
        self.at_rest = math.nan  # the smallest L / c of a cell at rest, s (step_size sets it)
        self.comm = comm if comm is not None else MPI.COMM_SELF
        self.records = StepRecords(self.comm)
        self.stop_reason: str | None = None
        self.limit = math.inf  # the smallest (calibrated) estimate at the latest step, s
        self._local = np.zeros(5)
        self._total = np.zeros(5)
        self._reductions = 0  # steps reduced so far: the cache key of controlling_cell
        self._cells: dict = {}  # what controlling_cell found at this step, by its key
        self.contacts = []  # contact interfaces: their nodal stable steps (s) bound the step

    def _reduce(self, s) -> tuple[float, int, int]:
        """The smallest estimate (s) over the ranks, and the largest number of inverted and
        of listed (mass-scaling) cells on a rank, from the latest kernel pass; after a pass
        that eroded cells on some rank, the nodes they held are counted again."""
        step = self.force.step
        # Each contact interface's nodal step on this rank's nodes.
        contacts = self.contacts
        contact = min(c.dt_limit for c in contacts) if contacts else math.inf
        if self.comm.size == 1:
            values = step.tolist()
            smallest, inverted, listed, eroded = (values[0], -values[5], -values[10],
                                                  -values[11])  # fmt: skip
        else:
            self._local[:] = (step[0], -step[5], -step[10], -step[11], contact)
            self.comm.Allreduce(self._local, self._total, op=MPI.MIN)
            smallest, inverted, listed, eroded, contact = self._total.tolist()
        # The contact nodes' own steps, cells and springs combined node by node
        # (ContactInterface.combine_with), beside the cells'.
        smallest = min(smallest, contact)
        self._reductions += 1
        self.limit = smallest
        if inverted:
            self.stop_reason = self._inverted(s)
        if eroded:
            self.force.detach_nodes()
        return smallest, int(-inverted), int(-listed)

    def _inverted(self, s) -> str:
        """'cell at (x, y, z) m inverted at t = ...' of the first rank with one (collective)."""
        step = self.force.step
        mine = (int(step[5]), step[7:10].tolist()) if step[5] else None
        found = [m for m in self.comm.allgather(mine) if m is not None]
        count = sum(n for n, _ in found)
        others = f" (and {count - 1} more)" if count > 1 else ""
        return (
            f"step {s.step}: cell at {_position(found[0][1])} inverted at t = {s.t:.6g} s"
            f"{others}: a volume <= 0 at an integration point or at a corner; the deformation "
            "is too large for the mesh (refine it, or check the loading)"
        )

    def _controlling_here(self, smallest: float):
        """Where the cell that sets ``smallest`` is (m), if this rank holds it."""
        step = self.force.step
        return step[2:5] if step[0] == smallest else None

    def controlling_cell(self, describe: bool = False) -> tuple | None:
        """(the calibrated estimate (s) of the cell that controls the step, where it is now
        (m), its state in words if ``describe``, its part's name for a body of parts or
        None), collective; but a second call at the same step, as from a recorder on rank
        0 alone after the run log, reads the first's answer. None without estimates."""
        key = (self._reductions, describe)
        if key in self._cells:
            return self._cells[key]
        if self.force is None or not math.isfinite(self.limit):
            return None
        step = self.force.step
        held = None
        if step[0] == self.limit:
            cell, body = int(step[1]), self.force
            text = body.describe_cell(cell) if describe else ""
            part = body.parts[body.controlling_part].name if body.explicit else None
            held = (body.cell_position(cell).tolist(), text, part)
        found = next((h for h in self.comm.allgather(held) if h is not None), None)
        answer = None if found is None else (self.limit, *found)
        # both kinds of answer of this step are kept: a recorder on rank 0 alone may ask
        # for either after the run log asked for both
        self._cells = {k: v for k, v in self._cells.items() if k[0] == key[0]} | {key: answer}
        return answer

    def advance(self, s) -> None:
        s.dt_previous = s.dt
        s.step += 1
        s.t = s.t + s.dt

    def summary(self) -> dict:
        """The step's part of ``summary.json`` (collective)."""
        return {"calibration": self.calibration} | self.records.summary()

    def checkpoint_state(self) -> dict[str, np.ndarray]:
        """The records of the run's steps."""
        return self.records.checkpoint_state()

    def restore_state(self, arrays: dict[str, np.ndarray]) -> None:
        self.records.restore_state(arrays)


class FixedStep(_StepSize):
    """One step ``dt`` (s) for the whole run; t^n = n dt. With a ``force``, the run stops
    after the step in which a cell inverts, or in which the calibrated estimate falls
    below ``dt``: the deformation lowered the stable limit (the step is kept: raising the
    step of a run is what the adaptive step is for)."""

    mode = "fixed"
    varies = False

    def __init__(self, dt: float, force=None, calibration: float = 1.0, comm=None):
        super().__init__(dt, force, calibration, comm)
        self.dt = dt

    def choose(self, sim, s) -> None:
        s.dt = self.dt
        if self.force is None:
            self.records.note(s, None)
            return
        smallest, _, _ = self._reduce(s)
        self.records.note(s, self._controlling_here(smallest))
        if self.stop_reason is None and self.dt > self.limit:
            where = self.controlling_cell()
            at = f" in the cell at {_position(where[1])}" if where else ""
            self.stop_reason = (
                f"step {s.step}, t = {s.t:.6g} s: the deformation lowered the stable step to "
                f"{self.limit:.4g} s{at} ({self.limit / self.initial:.3f} of dt), below the "
                f"fixed dt = {self.dt:.4g} s; use run.time_step = 'adaptive', or lower "
                "run.dt_scale"
            )

    def advance(self, s) -> None:
        s.dt_previous = s.dt
        s.step += 1
        s.t = s.step * self.dt


class AdaptiveStep(_StepSize):
    """dt^{n+1/2} = ``dt_scale`` x the smallest (calibrated) estimate of the cells at step n
    (s), rounded down to 4 significant figures.

    ``dt_min`` (s) is ``run.dt_min``: below it the run stops after the step, unless
    ``mass_scaling`` (a :class:`~rwall_fem.mass_scaling.MassScaling`) adds mass to the cells
    below it so that the step holds at ``dt_min``, or ``erode`` (``run.dt_min_action =
    "erode"``: the force's kernels erode those cells) holds it there. Past ``max_steps``
    steps (None: no limit) the run stops.
    """

    mode = "adaptive"

    def __init__(
        self,
        initial: float,
        force,
        calibration: float,
        comm,
        *,
        dt_scale: float,
        dt_min: float = 0.0,
        mass_scaling=None,
        erode: bool = False,
        max_steps: float | None = None,
    ):
        super().__init__(initial, force, calibration, comm)
        self.dt_scale, self.dt_min = dt_scale, dt_min
        self.mass_scaling, self.max_steps = mass_scaling, max_steps
        self.erode = erode
        if erode:
            force.erode_below(self.floor)

    @property
    def varies(self) -> bool:
        """Whether the step may change: not for a small-strain body, whose limit does not
        (unless mass scaling changes it), without contact."""
        return self.force.estimate_every_step or bool(self.contacts)

    @property
    def floor(self) -> float:
        """The estimate (s) of a cell below which the step would fall under ``dt_min``."""
        return self.dt_min / self.dt_scale

    def choose(self, sim, s) -> None:
        smallest, _, listed = self._reduce(s)
        here = self._controlling_here(smallest)
        scaled = self.mass_scaling is not None
        if scaled and listed:
            reason = self.mass_scaling.add(sim, s, self.floor)
            self.stop_reason = self.stop_reason or reason
            smallest = max(smallest, self.floor)
        # With every cell eroded nothing limits the step: the nodes fly freely at the last.
        dt = round_down(self.dt_scale * smallest) if math.isfinite(smallest) else s.dt
        if scaled or self.erode:
            # The cells below it were given the mass to hold it, or eroded: rounding down
            # alone takes the step below dt_min.
            dt = max(dt, self.dt_min)
        s.dt = dt
        self.records.note(s, here)
        if self.stop_reason is not None:
            return
        if dt < self.dt_min:
            where = self.controlling_cell(describe=True)
            cell = f"; it is set by the cell at {_position(where[1])}, {where[2]}" if where else ""
            self.stop_reason = (
                f"step {s.step}, t = {s.t:.6g} s: the stable step fell to {dt:.4g} s, below "
                f"run.dt_min = {self.dt_min:g} s{cell} (run.dt_min_action = 'mass_scaling' "
                "would hold it there, 'erode' would erode the cell)"
            )
        elif self.max_steps is not None and s.step >= self.max_steps and not s.last:
            self.stop_reason = (
                f"step {s.step}, t = {s.t:.6g} s: run.max_steps = {self.max_steps:g} reached "
                f"before the end time (the step is {dt:.4g} s); raise run.max_steps or "
                "run.dt_min, or pass --lift-limits to rwall-fem"
            )

    def summary(self) -> dict:
        extra = {} if self.mass_scaling is None else self.mass_scaling.summary()
        return super().summary() | extra

    def checkpoint_state(self) -> dict[str, np.ndarray]:
        """The records, and what mass scaling added."""
        arrays = super().checkpoint_state()
        if self.mass_scaling is not None:
            arrays |= {f"mass_{k}": v for k, v in self.mass_scaling.checkpoint_state().items()}
        return arrays

    def restore_state(self, arrays: dict[str, np.ndarray]) -> None:
        super().restore_state(arrays)
        if self.mass_scaling is not None:
            self.mass_scaling.restore_state(
                {k.removeprefix("mass_"): v for k, v in arrays.items() if k.startswith("mass_")}
            )


def step_size(scene, force, dt_stable: float, *, V, body_mass: float, limits: bool = True):
    """The step size of ``scene``'s ``[run]`` for the body's internal ``force`` (a
    :class:`~rwall_fem.body.Body` on the space ``V``), whose exact stable
    step at rest is ``dt_stable`` (s) and mass ``body_mass`` (kg); ``limits`` False lifts
    ``run.max_steps``. Raises :class:`~rwall_fem.scene.SceneError` for a ``run.dt`` above
    the stable limit, or a ``run.dt_min`` that would stop the run at its first step."""
    from rwall_fem.mass_scaling import MassScaling
    from rwall_fem.scene import SceneError

    run, comm = scene.run, V.mesh.comm
    fixed = run.time_step == "fixed"
    # The exact limit over the estimate L / c at rest; a fixed step's limit at rest is the
    # exact one, an adaptive step's never more.
    ratio = force.calibrate(dt_stable, cap=not fixed)
    at_rest = comm.allreduce(float(force.steps_at_rest().min(initial=math.inf)), op=MPI.MIN)
    if fixed:
        if run.dt is not None and run.dt > dt_stable:
            raise SceneError(
                f"{scene.source}: run.dt: {run.dt:g} s is above the stable limit "
                f"{dt_stable:.6g} s (2/omega_max); use a smaller dt or drop it to use dt_scale"
            )
        dt = run.dt if run.dt is not None else round_down(run.dt_scale * dt_stable)
        if dt > at_rest:  # only the damped hourglass modes can be below the stiffness's limit
            raise SceneError(
                f"{scene.source}: element.hourglass_coefficient: the viscous hourglass form "
                f"damps its modes so much that they need a step of at most {at_rest:.4g} s, "
                f"below the fixed step {dt:.4g} s; lower the coefficient (LS-DYNA's QM is "
                "0.1 by default) or use run.time_step = 'adaptive', which takes it into account"
            )
        step = FixedStep(dt, force, ratio, comm)
        step.at_rest = dt_stable / ratio
        return step
    calibration = force.calibration
    initial = round_down(run.dt_scale * at_rest)
    mass_scaling = None
    if run.dt_min_action == "mass_scaling":
        floor = run.dt_min / run.dt_scale
        added = comm.allreduce(added_at_rest(force, floor))
        if added > run.max_added_mass * body_mass:
            raise SceneError(
                f"{scene.source}: run.dt_min: {run.dt_min:g} s would have mass scaling add "
                f"{added:.4g} kg to the cells at rest ({100.0 * added / body_mass:.3g} % of "
                f"the body's {body_mass:.4g} kg, above run.max_added_mass = "
                f"{run.max_added_mass:g}) at the first step, whose step at rest is "
                f"{initial:.4g} s; lower run.dt_min"
            )
        mass_scaling = MassScaling(force, V, body_mass, run.max_added_mass, floor)
    elif run.dt_min > initial:
        outcome = (
            eroded_at_rest(force, run.dt_min / run.dt_scale, comm)
            if run.dt_min_action == "erode"
            else "stop"
        )
        raise SceneError(
            f"{scene.source}: run.dt_min: {run.dt_min:g} s is above the step at rest, "
            f"{initial:.4g} s: the run would {outcome} at its first step; lower it, or set "
            "run.dt_min_action = 'mass_scaling'"
        )
    adaptive = AdaptiveStep(
        initial,
        force,
        calibration,
        comm,
        dt_scale=run.dt_scale,
        dt_min=run.dt_min,
        mass_scaling=mass_scaling,
        erode=run.dt_min_action == "erode",
        max_steps=run.max_steps if limits else None,
    )
    adaptive.at_rest = dt_stable / ratio
    return adaptive


def added_at_rest(body, floor: float) -> float:
    """The mass (kg, this rank's cells) mass scaling would add at the first step to hold
    the cells of ``body`` at rest at ``floor`` (s): (floor / dt_e)^2 - 1 of each cell's
    mass (:mod:`rwall_fem.mass_scaling`)."""
    added = 0.0
    for part, force in zip(body.parts, body.elements, strict=True):
        steps = force.steps_at_rest()
        below = steps < floor
        ratio = (floor / steps[below]) ** 2 - 1.0
        added += float(np.sum(part.material.density * force.volume0[below] * ratio))
    return added


def eroded_at_rest(body, floor: float, comm) -> str:
    """What ``run.dt_min_action = "erode"`` would erode at the first step, in words: the
    cells of ``body`` whose estimate at rest is below ``floor`` (s), every cell, or how
    many of which parts (collective)."""
    below = [int(np.count_nonzero(f.steps_at_rest() < floor)) for f in body.elements]
    cells = [f.num_cells for f in body.elements]
    below, cells = comm.allreduce(np.array(below)), comm.allreduce(np.array(cells))
    if below.sum() == cells.sum():
        return "erode every cell"
    if not body.explicit:
        return f"erode {below.sum()} of its {cells.sum()} cells"
    named = [
        f"{n} of the {total} of part {part.name}"
        for part, n, total in zip(body.parts, below.tolist(), cells.tolist(), strict=True)
        if n
    ]
    return f"erode {below.sum()} of its {cells.sum()} cells ({', '.join(named)})"
