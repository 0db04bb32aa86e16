"""The time loop: explicit central differences over a pipeline of effects.

One step, in the order of ``docs/theory.md`` (section "The step"):

1. forces -> acceleration ``a^n``: the internal force *sets* ``a``, body forces add to it;
2. constraints edit ``a^n``: the rigid walls, then the velocity boundary conditions;
3. recorders sample the steps they are due (fields, frames: ``u^n``, ``v^{n-1/2}``);
4. the update ``v^{n+1/2} = v^{n-1/2} + dt a^n``, ``u^{n+1} = u^n + dt v^{n+1/2}``, in one
   compiled pass that also books the step's kinetic energy (:class:`CentralDifference`);
5. bookkeeping: the history samples the energies of step n.

Each effect is an object with a small interface (:class:`Force`, :class:`Constraint`,
:class:`Recorder`), and only the effects a scene asks for are in the lists, so nothing
else runs.
"""

from __future__ import annotations

import contextlib
import functools
import math
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
]


class RunStopped(Exception):
    """A guard stopped the run; the message names the step, time, quantity and worst node."""


@dataclass
class State:
    """Nodal state of the rank's owned nodes; vectors have shape (n, 3), SI units."""

    X: np.ndarray  # reference coordinates, m
    mass: np.ndarray  # lumped nodal mass, kg, shape (n,)
    dt: float  # s
    u: np.ndarray = None  # displacement u^n, m
    v: np.ndarray = None  # velocity v^{n-1/2}, m/s
    a: np.ndarray = None  # acceleration a^n, m/s^2
    t: float = 0.0  # s
    step: int = 0
    kinetic: float = 0.0  # K^n = 1/2 sum m v^{n-1/2} . v^{n+1/2} of the latest update, J
    internal_work: float = 0.0  # of an internal force without stored energy, up to step n, J
    mass_moment: np.ndarray = None  # sum m u^n of the latest update, kg m

    def __post_init__(self):
        for name in ("u", "v", "a"):
            if getattr(self, name) is None:
                setattr(self, name, np.zeros_like(self.X))
        self.mass_moment = np.zeros(3)
        self.inv_mass = (1.0 / self.mass)[:, None]  # 1/kg, shape (n, 1)


class Force(Protocol):
    """An effect on the acceleration ``state.a`` (m/s^2) of step n."""

    name: str

    def accelerate(self, state: State) -> None: ...


class InternalForce(Force, Protocol):
    """The body's internal force: first in the pipeline, it *sets* ``state.a``.

    ``energy_names`` are the energies it stores (``("internal",)``, and e.g. ``"hourglass"``);
    :meth:`energies` gives them (J) on this rank's share of the body at step n.
    ``booked_force`` is None for a force with a stored energy; otherwise it is the nodal
    force (N, owned nodes) whose work the update books in ``state.internal_work``.
    """

    energy_names: tuple[str, ...]
    booked_force: np.ndarray | None

    def energies(self, state: State) -> dict[str, float]: ...


class BodyForce(Force, Protocol):
    """An external force that adds to ``state.a``; :meth:`work` is its work (J) on this
    rank's nodes up to step n, booked at mid-step velocities."""

    def work(self, state: State) -> float: ...


class Constraint(Protocol):
    """A kinematic condition that edits ``state.a`` after the forces (a wall, a clamp)."""

    name: str

    def constrain(self, state: State) -> None: ...


class Recorder(Protocol):
    """Samples the run at the steps it is :meth:`due` (before the update of that step; the
    history samples after it) and is closed once when the run ends, however it ends."""

    def due(self, step: int) -> bool: ...

    def record(self, sim: Simulation, state: State) -> None: ...

    def close(self, sim: Simulation) -> None: ...


class CentralDifference:
    """The update of a step in one compiled pass (``kernels/update.c``):
    v^{n+1/2} = v^{n-1/2} + dt a^n and u^{n+1} = u^n + dt v^{n+1/2}, booking on the way the
    shadow kinetic energy K^n in ``state.kinetic``, sum m u^n in ``state.mass_moment`` and,
    when ``booked`` is given, the work of that force at mid-step velocities in
    ``state.internal_work`` (J, this rank: both halves of every step before n and the
    first half of step n, as every work is booked).
    """

    def __init__(self, state: State, booked: np.ndarray | None = None):
        from rwall_fem.kernels import load

        ffi, lib = load()
        self._out = np.zeros(6)
        self._done = 0.0  # work of the finished steps, J

        def ptr(array):
            return ffi.cast("double *", array.ctypes.data) if array is not None else ffi.NULL

        for name in ("u", "v", "a"):
            if not getattr(state, name).flags.c_contiguous:
                raise ValueError(f"state.{name} must be a C-contiguous (n, 3) array")
        self._booked = booked is not None
        self._pass = functools.partial(
            lib.central_difference, len(state.mass), state.dt, ptr(state.mass), ptr(state.a),
            ptr(state.v), ptr(state.u), ptr(booked), ptr(self._out),
        )  # fmt: skip

    def __call__(self, state: State) -> None:
        self._pass()
        kinetic, first, second = self._out[:3]
        state.kinetic = kinetic
        state.mass_moment[:] = self._out[3:]
        if self._booked:
            state.internal_work = self._done + first
            self._done += first + second


@dataclass
class Simulation:
    """A body, its effects and its outputs; :meth:`run` advances it to ``end_time``."""

    state: State
    end_time: float  # s
    internal: InternalForce
    comm: Any  # the body's MPI communicator
    forces: list[BodyForce] = field(default_factory=list)
    walls: list[Constraint] = field(default_factory=list)  # RigidWall
    boundaries: list[Constraint] = field(default_factory=list)  # VelocityBoundary
    recorders: list[Recorder] = field(default_factory=list)
    # What was built: scene, cells, nodes, mass (kg), dt_stable (s), ... (summary.json)
    info: dict = field(default_factory=dict)
    history: Recorder | None = None  # the energy books, sampled after the update
    update: CentralDifference | None = None  # built from the state when not given
    wall_seconds: float = 0.0  # of the time loop, on this rank
    status: str = "not run"  # "done", "stopped: <reason>" or "failed: <error>"
    # Names of the stop signals received ("SIGTERM", "SIGINT"); the history acts on them.
    stop_requests: set[str] = field(default_factory=set)

    def __post_init__(self):
        if self.update is None:
            self.update = CentralDifference(self.state, self.internal.booked_force)

    @property
    def num_steps(self) -> int:
        return math.ceil(self.end_time / self.state.dt - 1e-9)

    @property
    def constraints(self) -> list[Constraint]:
        """Walls, then boundary conditions: a clamp acts last and wins over a wall."""
        return [*self.walls, *self.boundaries]

    @property
    def effects(self) -> list[str]:
        """Names of the effects in the step pipeline, in the order they act."""
        return [e.name for e in [self.internal, *self.forces, *self.constraints]]

    def run(self) -> str:
        """Advance from t = 0 to ``end_time`` (s), then close every recorder.

        Returns ``self.status``: "done", or "stopped: ..." when a guard (see
        :mod:`rwall_fem.output.guards`), SIGTERM or SIGINT (Ctrl-C) stopped the run; the
        outputs up to the last sample stay valid. Any other error propagates after every
        recorder was closed; a recorder that fails to close does not keep the others from
        closing, and never hides an error raised before it (it is noted on it). A
        simulation runs once: build another to run again.
        """
        if self.status != "not run":
            raise RuntimeError(
                f"Simulation.run: this simulation has already run ({self.status.partition(':')[0]}"
                "); build a new one (build_simulation) to run the scene again"
            )
        s, last, update, history = self.state, self.num_steps, self.update, self.history
        forces, constraints = [self.internal, *self.forces], self.constraints
        with contextlib.ExitStack() as closing:
            outputs = [history, *self.recorders] if history is not None else self.recorders
            for recorder in reversed(outputs):  # closed in the order of the list
                closing.push(_closer(recorder, self))
            closing.enter_context(_stop_signals(self))
            started = time.perf_counter()
            try:
                for step in range(last + 1):
                    s.step, s.t = step, step * s.dt
                    for force in forces:
                        force.accelerate(s)
                    for constraint in constraints:
                        constraint.constrain(s)
                    for recorder in self.recorders:
                        if recorder.due(step):
                            recorder.record(self, s)
                    update(s)
                    if history is not None and history.due(step):
                        history.record(self, s)
                self.status = "done"
            except RunStopped as stop:
                self.status = f"stopped: {stop}"
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
