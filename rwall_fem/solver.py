"""The time loop: explicit central differences over a pipeline of effects.

One step, in the order of ``docs/theory.md`` (section "The step"):

1. the internal force *sets* the acceleration ``a^n`` and estimates every cell's stable
   step on the way;
   The contact interfaces then add their forces and note their nodal stable steps;
2. the step size chooses ``dt^{n+1/2}`` from those estimates (:mod:`rwall_fem.time_step`),
   adding mass to the cells below ``run.dt_min`` when the scene asks for mass scaling;
3. body forces add to ``a^n``, constraints edit it: the rigid bodies, the rigid walls,
   what the walls did to the rigid bodies, then the velocity boundary conditions;
4. recorders sample the steps they are due (fields, frames: ``u^n``, ``v^{n-1/2}``);
5. the update ``v^{n+1/2} = v^{n-1/2} + dt^n a^n`` with ``dt^n = (dt^{n-1/2} +
   dt^{n+1/2}) / 2``, ``u^{n+1} = u^n + dt^{n+1/2} v^{n+1/2}``, in one compiled pass that
   also books the step's kinetic energy (:class:`CentralDifference`);
6. bookkeeping: the history samples the energies of step n; the run stops if the step
   size found a reason to (an inverted cell, ``run.dt_min``, ...); a checkpoint is written
   when one is due (:mod:`rwall_fem.checkpoint`).

Each effect is an object with a small interface (:class:`Force`, :class:`Constraint`,
:class:`Recorder`), and only the effects a scene asks for are in the lists, so nothing
else runs. Every object that carries state from one step to the next is also
:class:`Stateful`, so that a run can be resumed from a checkpoint.
"""

from __future__ import annotations

import contextlib
import functools
import math
import operator
import signal
import threading
import time
from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np

__all__ = [
    "BodyForce",
    "CentralDifference",
    "Constraint",
    "Force",
    "InternalForce",
    "Recorder",
    "RunStopped",
    "Simulation",
    "State",
    "Stateful",
    "StepSize",
]


class RunStopped(Exception):
    """A guard stopped the run; the message names the step, time, quantity and worst node."""


class Stateful(Protocol):
    """An object that carries state from one step to the next (Radioss /RFILE content).

    :meth:`checkpoint_state` gives that state after the update and the history of step n
    as named NumPy arrays (this rank's share; SI units; arrays may be views of the live
    state: they are written at once). The names are the same at every step of a run. An
    object that writes outputs puts them on disk first (collectively, if it writes them
    so): a checkpoint promises the outputs up to its step.
    :meth:`restore_state` takes those arrays back from a checkpoint of the same scene on
    as many ranks, so that step n + 1 runs exactly as it would have; it raises ValueError
    (one line) when an output it continues does not fit the checkpoint. What an object
    derives from the scene alone when it is built (masses, node sets, histories of
    prescribed velocities) needs no place in it.

    The pieces of a run are listed by :attr:`Simulation.stateful`; a recorder is
    stateful when it has these methods (a progress bar needs none).
    """

    def checkpoint_state(self) -> dict[str, np.ndarray]: ...

    def restore_state(self, arrays: dict[str, np.ndarray]) -> None: ...


@dataclass
class State:
    """Nodal state of the rank's owned nodes; vectors have shape (n, 3), SI units.

    Steps vary: ``dt`` is dt^{n+1/2} = t^{n+1} - t^n, chosen at step n (before that, the
    previous step's), ``dt_previous`` is dt^{n-1/2} (0 at the first step) and
    :attr:`dt_velocity` the step of the velocity update. ``last`` is set at the step that
    reaches the end time.
    """

    X: np.ndarray  # reference coordinates, m
    mass: np.ndarray  # lumped nodal mass, kg, shape (n,) (mass scaling adds to it)
    dt: float  # s
    u: np.ndarray = None  # displacement u^n, m
    v: np.ndarray = None  # velocity v^{n-1/2}, m/s
    a: np.ndarray = None  # acceleration a^n, m/s^2
    t: float = 0.0  # s
    step: int = 0
    dt_previous: float = 0.0  # s
    last: bool = False
    kinetic: float = 0.0  # K^n = 1/2 sum m v^{n-1/2} . v^{n+1/2} of the latest update, J
    # The momentum booked at mid-step velocities up to step n, sum over steps of
    # dt^k/2 (P^{k-1/2} + P^{k+1/2}) with P = sum m v (first half only of step n), kg m:
    # what the work of uniform gravity needs.
    momentum_integral: np.ndarray = None

    def __post_init__(self):
        for name in ("u", "v", "a"):
            if getattr(self, name) is None:
                setattr(self, name, np.zeros_like(self.X))
        self.momentum_integral = np.zeros(3)
        self.inv_mass = 1.0 / self.mass  # 1/kg, shape (n,)

    @property
    def dt_velocity(self) -> float:
        """dt^n = (dt^{n-1/2} + dt^{n+1/2}) / 2 (s), the step of v^{n-1/2} -> v^{n+1/2}; at
        the first step dt^{1/2}: the initial velocity is taken as v^{-1/2}."""
        return self.dt if self.dt_previous == 0.0 else 0.5 * (self.dt_previous + self.dt)

    def set_mass(self, nodes: np.ndarray, mass: np.ndarray) -> None:
        """Give the owned ``nodes`` the masses ``mass`` (kg), in place (the compiled passes
        hold pointers to these arrays)."""
        self.mass[nodes] = mass
        self.inv_mass[nodes] = 1.0 / mass

    def checkpoint_state(self) -> dict[str, np.ndarray]:
        """u^{n+1} and v^{n+1/2} (``a`` is set again by the internal force), the step, its
        time and size and the one before, whether it was the last, the masses, and what
        the update of step n booked."""
        return {
            "u": self.u,
            "v": self.v,
            "mass": self.mass,
            "clock": np.array([self.step, self.t, self.dt, self.dt_previous, self.last]),
            "booked": np.array([self.kinetic]),
            "momentum_integral": self.momentum_integral,
        }

    def restore_state(self, arrays: dict[str, np.ndarray]) -> None:
        self.u[:] = arrays["u"]
        self.v[:] = arrays["v"]
        self.set_mass(slice(None), arrays["mass"])
        step, self.t, self.dt, self.dt_previous, last = arrays["clock"].tolist()
        self.step, self.last = int(step), bool(last)
        (self.kinetic,) = arrays["booked"].tolist()
        self.momentum_integral[:] = arrays["momentum_integral"]


class Force(Protocol):
    """An effect on the acceleration ``state.a`` (m/s^2) of step n."""

    name: str

    def accelerate(self, state: State) -> None: ...


class InternalForce(Force, Protocol):
    """The body's internal force: first in the pipeline, it *sets* ``state.a``.

    ``energy_names`` are the energies it stores (``("internal",)``, and e.g. ``"hourglass"``),
    ``energy_parts`` parts of them reported beside them (e.g. ``"plastic_work"``);
    :meth:`energies` gives them all (J) on this rank's share of the body at step n.
    ``nodal_force`` is the latest force (N, owned nodes). When ``books_work`` (a force
    without a stored energy, or one with it and a varying step), the update sums its work
    at mid-step velocities and hands the sums to :meth:`book`.
    """

    energy_names: tuple[str, ...]
    energy_parts: tuple[str, ...]
    conservative: bool
    books_work: bool
    nodal_force: np.ndarray

    def book(self, state: State, first: float, second: float) -> None:
        """After the update of step n: sum f . v^{n-1/2} and sum f . v^{n+1/2} (W) of its
        force on this rank's owned nodes."""
        ...

    def energies(self, state: State) -> dict[str, float]: ...

    def cell_fields(self, state: State) -> dict[str, np.ndarray]:
        """Values per owned cell for the outputs (e.g. ``"plastic_strain"``); may be empty."""
        ...


class BodyForce(Force, Protocol):
    """An external force that adds to ``state.a``; :meth:`work` is its work (J) on this
    rank's nodes up to step n, booked at mid-step velocities."""

    def work(self, state: State) -> float: ...


class Constraint(Protocol):
    """A kinematic condition that edits ``state.a`` after the forces (a wall, a clamp)."""

    name: str

    def constrain(self, state: State) -> None: ...


class StepSize(Protocol):
    """Chooses dt^{n+1/2} after the internal force of step n (:mod:`rwall_fem.time_step`)."""

    stop_reason: str | None  # a reason to stop the run after this step's history sample

    varies: bool  # whether the step may change during the run

    def choose(self, sim: Simulation, state: State) -> None:
        """Set ``state.dt``; may add mass (then ``state.a`` and ``state.v`` follow)."""
        ...

    def advance(self, state: State) -> None:
        """Go on to the next step: its number, time and previous step."""
        ...


class Recorder(Protocol):
    """Samples the run at the steps it is :meth:`due` (before the update of that step; the
    history samples after it) and is closed once when the run ends, however it ends."""

    def due(self, state: State) -> bool: ...

    def record(self, sim: Simulation, state: State) -> None: ...

    def close(self, sim: Simulation) -> None: ...


class CentralDifference:
    """The update of a step in one compiled pass (``kernels/update.c``):
    v^{n+1/2} = v^{n-1/2} + dt^n a^n and u^{n+1} = u^n + dt^{n+1/2} v^{n+1/2}, booking on
    the way the shadow kinetic energy K^n in ``state.kinetic`` and the momentum integral in
    ``state.momentum_integral``; when the ``internal`` force books its work, the pass sums
    f . v^{n-1/2} and f . v^{n+1/2} (all owned nodes, and part by part after its
    ``labels`` into its ``part_sums``) and hands them to its :meth:`~InternalForce.book`.
    """

    def __init__(self, state: State, internal=None):
        self._out = np.zeros(9)
        self._integral = np.zeros(3)  # momentum integral of the finished steps, kg m
        books = internal is not None and getattr(internal, "books_work", False)
        self._internal = internal if books else None
        self._force = internal.nodal_force if books else None
        self._labels = getattr(internal, "labels", None) if books else None
        self._part_sums = internal.part_sums if self._labels is not None else None
        self._bind(state)

    @staticmethod
    def _state_arrays(state: State) -> tuple:
        return state.mass, state.a, state.v, state.u, state.momentum_integral

    def _bind(self, state: State) -> None:
        """Bind the pass to the arrays of ``state``, keeping them (the pass holds pointers
        to them)."""
        from rwall_fem.kernels import load

        ffi, lib = load()

        def ptr(array, kind="double *"):
            return ffi.cast(kind, array.ctypes.data) if array is not None else ffi.NULL

        for name in ("u", "v", "a"):
            if not getattr(state, name).flags.c_contiguous:
                raise ValueError(f"state.{name} must be a C-contiguous (n, 3) array")
        self._bound = self._state_arrays(state)
        mass, a, v, u, momentum = self._bound
        self._pass = functools.partial(lib.central_difference, len(mass))
        self._arrays = (
            ptr(mass), ptr(a), ptr(v), ptr(u), ptr(self._force), ptr(self._out),
            ptr(self._integral), ptr(momentum), ptr(self._labels, "int32_t *"),
            ptr(self._part_sums),
        )  # fmt: skip

    def __call__(self, state: State) -> None:
        if any(map(operator.is_not, self._state_arrays(state), self._bound)):
            self._bind(state)  # another state, or one whose arrays were replaced
        if self._part_sums is not None:
            self._part_sums[:] = 0.0
        self._pass(state.dt_velocity, state.dt, *self._arrays)
        state.kinetic = self._out[0]
        if self._internal is not None:
            self._internal.book(state, self._out[1], self._out[2])

    def checkpoint_state(self) -> dict[str, np.ndarray]:
        """The momentum integral of the finished steps (kg m)."""
        return {"integral": self._integral}

    def restore_state(self, arrays: dict[str, np.ndarray]) -> None:
        self._integral[:] = arrays["integral"]


@dataclass
class Simulation:
    """A body, its effects and its outputs; :meth:`run` advances it to ``end_time``."""

    state: State
    end_time: float  # s
    internal: InternalForce
    comm: Any  # the body's MPI communicator
    forces: list[BodyForce] = field(default_factory=list)
    # Contact interfaces (rwall_fem.contact): forces after the internal force, before the
    # step size is chosen (their stiffness enters the stable step).
    contacts: list = field(default_factory=list)
    walls: list[Constraint] = field(default_factory=list)  # RigidWall
    boundaries: list[Constraint] = field(default_factory=list)  # VelocityBoundary
    # Rigid bodies (rwall_fem.rigid_body), before the walls; their contact after the walls.
    rigid_bodies: list[Constraint] = field(default_factory=list)
    rigid_contact: Constraint | None = None
    recorders: list[Recorder] = field(default_factory=list)
    # What was built: scene, cells, nodes, mass (kg), dt_stable (s), ... (summary.json)
    info: dict = field(default_factory=dict)
    history: Recorder | None = None  # the energy books, sampled after the update
    update: CentralDifference | None = None  # built from the state when not given
    wall_seconds: float = 0.0  # of the time loop, on this rank
    status: str = "not run"  # "done", "stopped: <reason>" or "failed: <error>"
    # Names of the stop signals received ("SIGTERM", "SIGINT"); the history acts on them.
    stop_requests: set[str] = field(default_factory=set)
    checkpoints: Any = None  # rwall_fem.checkpoint.Checkpoints: written after the history
    first_step: int = 0  # after a resume, the step after the checkpoint's
    # Chooses dt^{n+1/2} (rwall_fem.time_step); by default state.dt for the whole run.
    step_size: StepSize | None = None

    def __post_init__(self):
        if self.step_size is None:
            from rwall_fem.time_step import FixedStep

            self.step_size = FixedStep(self.state.dt)
        if self.update is None:
            # A stored energy needs the step's correction only where the step varies.
            if self.step_size.varies and hasattr(self.internal, "book"):
                self.internal.books_work = True
            self.update = CentralDifference(self.state, self.internal)

    @property
    def planned_steps(self) -> int:
        """The steps to ``end_time`` at the step of the start: all of them with a fixed
        step, an estimate with an adaptive one (fewer than it takes when the step falls)."""
        return math.ceil(self.end_time / self.step_size.initial - 1e-9)

    @property
    def constraints(self) -> list[Constraint]:
        """Rigid bodies, walls, what the walls did to the rigid bodies, then boundary
        conditions: a clamp acts last and wins over a wall."""
        contact = [self.rigid_contact] if self.rigid_contact is not None else []
        return [*self.rigid_bodies, *self.walls, *contact, *self.boundaries]

    @property
    def effects(self) -> list[str]:
        """Names of the effects in the step pipeline, in the order they act."""
        return [e.name for e in [self.internal, *self.contacts, *self.forces, *self.constraints]]

    @property
    def stateful(self) -> dict[str, Stateful]:
        """Every object of the run that carries state from one step to the next, by a name
        that is the same in every run of the scene: what a checkpoint holds."""
        pieces = {"state": self.state, "update": self.update, "internal": self.internal}
        pieces["step_size"] = self.step_size
        forces = [f for f in self.forces if hasattr(f, "checkpoint_state")]
        pieces |= {f"force[{i}]": f for i, f in enumerate(forces)}
        pieces |= {f"contact[{i}]": c for i, c in enumerate(self.contacts)}
        pieces |= {f"wall[{i}]": w for i, w in enumerate(self.walls)}
        pieces |= {f"boundary[{i}]": b for i, b in enumerate(self.boundaries)}
        pieces |= {f"rigid_body[{i}]": r for i, r in enumerate(self.rigid_bodies)}
        if self.history is not None:
            pieces["history"] = self.history
        recorders = [r for r in self.recorders if hasattr(r, "checkpoint_state")]
        return pieces | {f"recorder[{i}]": r for i, r in enumerate(recorders)}

    def run(self) -> str:
        """Advance from t = 0 (or the step after a checkpoint's, after a resume) to
        ``end_time`` (s), then close every recorder.

        Returns ``self.status``: "done", or "stopped: ..." when a guard (see
        :mod:`rwall_fem.output.guards`), SIGTERM or SIGINT (Ctrl-C) stopped the run; the
        outputs up to the last sample stay valid, and a stop after a whole step writes a
        checkpoint. Any other error propagates after every recorder was closed; a recorder
        that fails to close does not keep the others from closing, and never hides an error
        raised before it (it is noted on it). A simulation runs once: build another to run
        again (a resumed run is another simulation).
        """
        if self.status != "not run":
            raise RuntimeError(
                f"Simulation.run: this simulation has already run ({self.status.partition(':')[0]}"
                "); build a new one (build_simulation) to run the scene again"
            )
        s, update, history, step_size = self.state, self.update, self.history, self.step_size
        internal, forces, constraints = self.internal, self.forces, self.constraints
        contacts, recorders = self.contacts, self.recorders
        checkpoints, end_time = self.checkpoints, self.end_time
        # A resumed run goes on after its checkpoint's step, unless that step was the last.
        going = not (self.first_step and s.last)
        with contextlib.ExitStack() as closing:
            outputs = [history, *self.recorders] if history is not None else self.recorders
            for recorder in reversed(outputs):  # closed in the order of the list
                closing.push(_closer(recorder, self))
            closing.enter_context(_stop_signals(self))
            if checkpoints is not None:
                checkpoints.start(self.first_step)
            if history is not None and hasattr(history, "start"):
                history.start(self)  # summary.json says "running", and keeps its room
            started = time.perf_counter()
            updated = s.step - 1 if not self.first_step else s.step  # the latest update done
            try:
                if self.first_step and going:
                    step_size.advance(s)
                while going:
                    s.last = s.t >= end_time - 1e-9 * s.dt_previous
                    internal.accelerate(s)
                    for contact in contacts:
                        contact.accelerate(s)
                    step_size.choose(self, s)
                    for force in forces:
                        force.accelerate(s)
                    for constraint in constraints:
                        constraint.constrain(s)
                    for recorder in recorders:
                        if recorder.due(s):
                            recorder.record(self, s)
                    update(s)
                    updated = s.step
                    if history is not None and (history.due(s) or step_size.stop_reason):
                        history.record(self, s)
                    if step_size.stop_reason:
                        raise RunStopped(step_size.stop_reason)
                    if checkpoints is not None and checkpoints.due(s.step):
                        checkpoints.save(self)
                    if s.last:
                        break
                    step_size.advance(s)
                self.status = "done"
            except RunStopped as stop:
                self.status = f"stopped: {stop}"
                if checkpoints is not None and updated == s.step:
                    checkpoints.save(self)  # stopped after its history: a whole step
            except Exception as error:
                self.status = f"failed: {type(error).__name__}: {error}"
                raise
            finally:
                self.wall_seconds = time.perf_counter() - started
        return self.status


def _closer(recorder: Recorder, sim: Simulation):
    """An exit callback that closes ``recorder``. When an error is already on its way
    (from the run or from an earlier close), a failure to close is noted on that error
    instead of replacing it."""

    def close(kind, error, traceback) -> bool:
        try:
            recorder.close(sim)
        except Exception as failure:
            if error is None:
                raise
            error.add_note(f"closing {type(recorder).__name__} failed too: {failure!r}")
        return False

    return close


@contextlib.contextmanager
def _stop_signals(sim: Simulation):
    """While the loop runs, SIGTERM and SIGINT (Ctrl-C) only add their name to
    ``sim.stop_requests``: the history stops the run within a fraction of a second, on
    every rank at the same step. Signals can be handled in the main thread only;
    elsewhere they keep their handlers."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def request(signum, frame):
        sim.stop_requests.add(signal.Signals(signum).name)

    previous = {n: signal.signal(n, request) for n in (signal.SIGTERM, signal.SIGINT)}
    try:
        yield
    finally:
        for number, handler in previous.items():
            signal.signal(number, handler)
