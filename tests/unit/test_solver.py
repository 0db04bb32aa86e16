"""The time loop with stand-in effects: the order of the phases, and how recorders close."""

import numpy as np
import pytest
from mpi4py import MPI

from rwall_fem.solver import RunStopped, Simulation, State


class Push:
    """Internal force giving every node the acceleration ``a`` (m/s^2); fails at ``fail``."""

    name = "push"
    energy_names = ("internal",)
    energy_parts = ()
    booked_force = None

    def __init__(self, a=1.0, fail=None):
        self.a, self.fail = a, fail

    def accelerate(self, state):
        if state.step == self.fail:
            raise ZeroDivisionError("the force broke")
        state.a[:] = self.a

    def energies(self, state):
        return {"internal": 0.0}


class Log:
    """Recorder that notes the steps it sampled and whether it was closed; it raises
    ``error`` when closed, or RunStopped at step ``stop``."""

    def __init__(self, closed, name, error=None, stop=None):
        self.closed, self.name, self.error, self.stop = closed, name, error, stop
        self.steps = []

    def due(self, step):
        return True

    def record(self, sim, s):
        if s.step == self.stop:
            raise RunStopped(f"step {s.step}: enough")
        self.steps.append(s.step)

    def close(self, sim):
        self.closed.append(self.name)
        if self.error:
            raise self.error


def simulation(force=None, recorders=()):
    state = State(X=np.zeros((2, 3)), mass=np.ones(2), dt=0.1)
    sim = Simulation(state, end_time=0.3, internal=force or Push(), comm=MPI.COMM_SELF)
    sim.recorders += recorders
    return sim


def test_central_differences_of_a_constant_acceleration():
    sim = simulation(Push(a=2.0))
    assert sim.run() == "done" and sim.num_steps == 3
    # v^{n+1/2} = (n + 1) a dt and u^{n+1} = sum of them times dt, after steps 0..3.
    assert sim.state.v == pytest.approx(np.full((2, 3), 4 * 2.0 * 0.1))
    assert sim.state.u == pytest.approx(np.full((2, 3), (1 + 2 + 3 + 4) * 2.0 * 0.01))


def test_every_recorder_closes_in_order_when_one_fails_to_close():
    closed = []
    broken = OSError("disk full")
    recorders = [Log(closed, "first"), Log(closed, "broken", error=broken), Log(closed, "last")]
    sim = simulation(recorders=recorders)
    with pytest.raises(OSError, match="disk full"):
        sim.run()
    assert closed == ["first", "broken", "last"]
    assert sim.status == "done" and recorders[0].steps == [0, 1, 2, 3]


def test_an_error_in_the_loop_is_not_hidden_by_a_failing_close():
    closed = []
    recorders = [Log(closed, "broken", error=ValueError("cannot close")), Log(closed, "last")]
    sim = simulation(Push(fail=2), recorders)
    with pytest.raises(ZeroDivisionError, match="the force broke") as caught:
        sim.run()
    assert closed == ["broken", "last"]
    assert any("cannot close" in note for note in caught.value.__notes__)
    assert sim.status == "failed: ZeroDivisionError: the force broke"


def test_a_stopped_run_closes_its_recorders_and_says_why():
    closed = []
    sim = simulation(recorders=[Log(closed, "guard", stop=1), Log(closed, "other")])
    assert sim.run() == "stopped: step 1: enough"
    assert closed == ["guard", "other"]
