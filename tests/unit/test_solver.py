"""The time loop with stand-in effects: the order of the phases, and how recorders close."""

import numpy as np
import pytest
from mpi4py import MPI

from rwall_fem.solver import CentralDifference, RunStopped, Simulation, State
from rwall_fem.time_step import FixedStep


class Push:
    """Internal force giving every node the acceleration ``a`` (m/s^2); fails at ``fail``."""

    name = "push"
    energy_names = ("internal",)
    energy_parts = ()
    conservative = True

    def __init__(self, a=1.0, fail=None):
        self.a, self.fail = a, fail
        self.nodal_force = np.zeros((2, 3))

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

    def due(self, s):
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


def test_the_update_books_kinetic_energy_and_momentum_as_numpy_does():
    """The compiled update pass (kernels/update.c) against the NumPy formulas it replaces,
    to the bit, over steps of varying size: K^n = 1/2 sum m v^{n-1/2} . v^{n+1/2} (summed
    node by node), and the momentum integral sum over steps of dt^k/2 (P^{k-1/2} +
    P^{k+1/2}), of which step n's first half only."""
    rng = np.random.default_rng(7)
    n = 50
    state = State(X=np.zeros((n, 3)), mass=rng.uniform(1.0, 2.0, n), dt=0.1)
    state.v[:] = rng.standard_normal((n, 3))
    update = CentralDifference(state)
    integral = np.zeros(3)
    for dt_previous, dt in ((0.0, 0.1), (0.1, 0.13), (0.13, 0.07)):
        state.dt_previous, state.dt = dt_previous, dt
        state.a[:] = rng.standard_normal((n, 3))
        dt_v = state.dt_velocity
        old = state.v.copy()
        new = old + dt_v * state.a
        kinetic = 0.0
        for m, before, after in zip(state.mass, old, new, strict=True):
            for c in range(3):
                kinetic += m * before[c] * after[c]
        first = (state.mass[:, None] * old).sum(axis=0)  # node after node, as the pass
        second = (state.mass[:, None] * new).sum(axis=0)
        momentum = integral + 0.5 * dt_v * first
        integral = integral + 0.5 * dt_v * (first + second)
        update(state)
        assert state.kinetic == 0.5 * kinetic
        assert np.array_equal(state.v, new)
        assert np.array_equal(state.momentum_integral, momentum)


def test_central_differences_of_a_constant_acceleration():
    sim = simulation(Push(a=2.0))
    assert sim.run() == "done" and sim.planned_steps == 3
    # v^{n+1/2} = (n + 1) a dt and u^{n+1} = sum of them times dt, after steps 0..3.
    assert sim.state.v == pytest.approx(np.full((2, 3), 4 * 2.0 * 0.1))
    assert sim.state.u == pytest.approx(np.full((2, 3), (1 + 2 + 3 + 4) * 2.0 * 0.01))


class Alternating(FixedStep):
    """Steps of 0.1 and 0.2 s in turn."""

    varies = True

    def choose(self, sim, s):
        s.dt = 0.1 if s.step % 2 == 0 else 0.2

    def advance(self, s):
        s.dt_previous, s.step, s.t = s.dt, s.step + 1, s.t + s.dt


def test_a_varying_step_updates_the_velocity_over_the_mean_of_the_steps_around_t():
    """v^{n+1/2} = v^{n-1/2} + (dt^{n-1/2} + dt^{n+1/2})/2 a (dt^{1/2} at the first step:
    the initial velocity is v^{-1/2}), u^{n+1} = u^n + dt^{n+1/2} v^{n+1/2}; the run ends at
    the first step at or after end_time."""
    sim = simulation(Push(a=2.0))
    sim.step_size = Alternating(0.1)
    assert sim.run() == "done"
    # steps 0..2 at t = 0, 0.1, 0.3 (>= 0.3: the last); dt = 0.1, 0.2, 0.1
    assert sim.state.step == 2 and sim.state.t == pytest.approx(0.3)
    v = [2.0 * 0.1, 2.0 * (0.1 + 0.15), 2.0 * (0.1 + 0.15 + 0.15)]
    u = 0.1 * v[0] + 0.2 * v[1] + 0.1 * v[2]
    assert sim.state.v == pytest.approx(np.full((2, 3), v[2]))
    assert sim.state.u == pytest.approx(np.full((2, 3), u))


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
