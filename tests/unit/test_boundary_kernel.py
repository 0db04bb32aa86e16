"""The compiled pass of the velocity boundary (kernels/boundary.c) against the NumPy code
it replaces (``boundary.py`` before): the accelerations it sets, the reaction impulse and
its work booked at mid-step velocities, to the bit, over steps with a changing
prescribed velocity and another force acting between them."""

import numpy as np
import pytest

from rwall_fem.boundary import VelocityBoundary

RNG = np.random.default_rng(20261207)


class State:
    """What the boundary reads: velocities, accelerations, masses and the step."""

    def __init__(self, n=500):
        self.v = RNG.uniform(-20.0, 20.0, (n, 3))
        self.a = RNG.uniform(-1e7, 1e7, (n, 3))
        self.mass = RNG.uniform(1e-4, 1e-3, n)
        self.t, self.dt, self.dt_velocity = 0.0, 2e-7, 1.9e-7


class NumpyBoundary:
    """``VelocityBoundary``'s step of the NumPy code."""

    def __init__(self, nodes, velocity, components):
        self.b = VelocityBoundary("reference", nodes, velocity, components)
        self.flat = self.b._flat
        self.impulse, self.work, self.reaction = np.zeros(3), 0.0, None

    def constrain(self, state):
        b, rows = self.b, self.flat
        target = b.prescribed.predict(state.t, state.dt)[b.axes]
        if self.reaction is not None:
            self.work += 0.5 * float(np.sum(self.reaction * state.v.reshape(-1)[rows]))
        v_old = state.v.reshape(-1)[rows]
        m = state.mass[b.nodes][:, None]
        a = state.a.reshape(-1)
        reaction = m * (target - v_old - state.dt_velocity * a[rows])
        a[rows] = (target - v_old) / state.dt_velocity
        self.work += 0.5 * float(np.sum(reaction * v_old))
        self.reaction = reaction
        self.impulse[b.axes] += reaction.sum(axis=0)


@pytest.mark.parametrize("components", ["xyz", "z", "xz"])
@pytest.mark.parametrize(
    "velocity", [[0.0, 0.0, 0.0], [[0.0, 1.0, -2.0, 3.0], [1e-6, -4.0, 5.0, 0.5]]]
)
@pytest.mark.parametrize("count", [130, 3000])  # sums in C; more than NumPy's buffer (xyz)
def test_boundary_pass_is_numpys(components, velocity, count):
    state, reference = State(4000), State(4000)
    reference.v, reference.a = state.v.copy(), state.a.copy()
    nodes = np.sort(RNG.choice(len(state.mass), count, replace=False))
    reference.mass = state.mass
    compiled = VelocityBoundary("compiled", nodes, velocity, components)
    numpy = NumpyBoundary(nodes, velocity, components)
    for step in range(3):
        compiled.constrain(state)
        numpy.constrain(reference)
        np.testing.assert_array_equal(state.a, reference.a)
        np.testing.assert_array_equal(compiled._reaction, numpy.reaction)
        np.testing.assert_array_equal(compiled.impulse, numpy.impulse)
        assert compiled.work == numpy.work
        # The step's update, then whatever else moves the nodes before the next step.
        for s in (state, reference):
            s.v += s.dt_velocity * s.a
            s.v[::7] *= 0.5
            s.a[:] = np.arange(s.a.size).reshape(s.a.shape) * 1e3
            s.t += s.dt
        if step == 1:  # as after a resume: the latest reaction is the checkpoint's
            compiled.restore_state({k: v.copy() for k, v in compiled.checkpoint_state().items()})
    compiled.settle(state)
    numpy.constrain(reference)  # books the latest half the same way
    assert compiled.work != 0.0
