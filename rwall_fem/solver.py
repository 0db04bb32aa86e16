"""Explicit central-difference time stepping with a pipeline of effects.

One step, in the order of the spec (section 4):

1. forces -> acceleration ``a^n`` (``forces``: the internal force first, then
   body forces; each adds to ``a``);
2. constraints edit ``a^n`` (rigid walls);
3. bookkeeping at sample steps (energies need ``v^{n-1/2}`` and ``a^n``);
4. ``v^{n+1/2} = v^{n-1/2} + dt a^n``; ``u^{n+1} = u^n + dt v^{n+1/2}``.

Only the effects a scene asks for are in the lists, so nothing else runs.
"""

from __future__ import annotations

import math
import signal
import threading
import time
from dataclasses import dataclass, field

import numpy as np
from petsc4py import PETSc

__all__ = ["LinearElasticForce", "RunStopped", "Simulation", "State"]


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

    def __post_init__(self):
        for name in ("u", "v", "a"):
            if getattr(self, name) is None:
                setattr(self, name, np.zeros_like(self.X))
        self.inv_mass = (1.0 / self.mass)[:, None]


class LinearElasticForce:
    """Internal force -K u of small-strain linear elasticity with a constant stiffness K.

    It *sets* ``state.a`` (it is always first in the force list). The strain
    energy 1/2 u.Ku comes for free from the product already computed.
    """

    name = "linear_elastic"

    def __init__(self, K: PETSc.Mat, state: State):
        self.K = K
        self.ku = np.zeros_like(state.u)
        comm, size = K.comm, (state.u.size, PETSc.DECIDE)
        self._u = PETSc.Vec().createWithArray(state.u.reshape(-1), size=size, bsize=3, comm=comm)
        self._ku = PETSc.Vec().createWithArray(self.ku.reshape(-1), size=size, bsize=3, comm=comm)
        # -1/m per component: one pass per step, and a contiguous (n, 3) operand is several
        # times faster than broadcasting an (n, 1) column over rows of 3.
        self._minus_inv_mass = -np.repeat(state.inv_mass, 3, axis=1)

    def accelerate(self, state: State) -> None:
        self.K.mult(self._u, self._ku)
        np.multiply(self.ku, self._minus_inv_mass, out=state.a)

    def strain_energy(self, state: State) -> float:
        """Strain energy 1/2 u.Ku (J) on this rank's rows."""
        return 0.5 * float(np.vdot(state.u, self.ku))


@dataclass
class Simulation:
    """A body, its effects and its outputs; :meth:`run` advances it to ``end_time``."""

    state: State
    end_time: float  # s
    internal: LinearElasticForce
    forces: list = field(default_factory=list)
    constraints: list = field(default_factory=list)
    recorders: list = field(default_factory=list)
    history: object = None  # the History among the recorders
    wall_seconds: float = 0.0
    status: str = "not run"  # "done", or "stopped: <reason>"
    terminate_requested: bool = False  # set by SIGTERM; acted on at the next history sample

    @property
    def num_steps(self) -> int:
        return math.ceil(self.end_time / self.state.dt - 1e-9)

    @property
    def effects(self) -> list[str]:
        """Names of the effects in the step pipeline, in the order they act."""
        return [e.name for e in [self.internal, *self.forces, *self.constraints]]

    def run(self) -> str:
        """Advance from t = 0 to ``end_time`` (s), then close the recorders.

        Returns ``self.status``: "done", or "stopped: ..." when a guard (see
        :class:`~rwall_fem.history.History`) or SIGTERM stopped the run. Either way
        every recorder is closed, so the outputs up to the last sample stay valid.
        """
        s, forces, last = self.state, [self.internal, *self.forces], self.num_steps
        scratch = np.empty_like(s.u)
        started = time.perf_counter()
        previous = _on_sigterm(self)
        try:
            for step in range(last + 1):
                s.step, s.t = step, step * s.dt
                for effect in forces:
                    effect.accelerate(s)
                for constraint in self.constraints:
                    constraint.constrain(s)
                for recorder in self.recorders:
                    if recorder.due(step):
                        recorder.record(self, s)
                np.multiply(s.a, s.dt, out=scratch)
                s.v += scratch
                np.multiply(s.v, s.dt, out=scratch)
                s.u += scratch
            self.status = "done"
        except RunStopped as stop:
            self.status = f"stopped: {stop}"
        finally:
            if previous is not None:
                signal.signal(signal.SIGTERM, previous)
            self.wall_seconds = time.perf_counter() - started
            for recorder in self.recorders:
                recorder.close(self)
        return self.status


def _on_sigterm(sim: Simulation):
    """Make SIGTERM a request to stop cleanly; returns the previous handler (None if the
    handler cannot be set, outside the main thread)."""
    if threading.current_thread() is not threading.main_thread():
        return None

    def request(signum, frame):
        sim.terminate_requested = True

    return signal.signal(signal.SIGTERM, request)
