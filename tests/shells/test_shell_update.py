"""The compiled update of a shell body (``shell_central_difference``, ``kernels/update.c``):
translations and rotations in one sweep over the nodes.

References: the translations are the solids' pass (:class:`~rwall_fem.solver.CentralDifference`)
bit for bit, since both run the same per-node arithmetic in the same order; the rotations
are w + dt_v alpha, which the pass rounds as NumPy does (no fused multiply-add), so bit
for bit too; its sums are exactly rounded sums (``math.fsum``) to the round-off of a sum
of a few hundred terms. Over 10^5 variable steps, a node's rotations under a constant
moment follow the closed form w(t) = w0 - M t / I (central differences are exact for a
constant acceleration) and the moment's work booked at mid-step velocities is the
rotational kinetic energy lost, 1/2 I (|w0|^2 - |w|^2), both to the round-off of 10^5
additions; without a moment the angular velocity does not change at all. Each rank runs
its own nodes: the same on any number of ranks.
"""

import math

import numpy as np
import pytest

from rwall_fem.shells.update import ShellUpdate
from rwall_fem.solver import CentralDifference, State


class _Body:
    """The internal force of a test: given nodal forces (N) and moments (N m) on ``n``
    nodes of rotational inertia ``inertia`` (kg m^2), alpha = -M / I, and a book of the
    sums the update hands over."""

    books_work = True
    labels = None

    def __init__(self, force, moments, inertia, w0):
        n = len(inertia)
        self.nodal_force = force
        self.moments = moments
        self.inertia = np.column_stack([np.ones(n), inertia])
        self.alpha = -moments / inertia[:, None]
        self.w = type("Field", (), {"owned": np.array(w0, dtype=float)})()
        self.rotational_kinetic, self.rotational_sums = 0.0, (0.0, 0.0)
        self.booked = []
        self.work = 0.0

    def book(self, state, first, second):
        self.booked.append((first, second))
        self.work += 0.5 * state.dt_velocity * (first + second + sum(self.rotational_sums))


def _nodes(n, seed):
    rng = np.random.default_rng(seed)
    mass = rng.uniform(1e-3, 2e-3, n)
    inertia = rng.uniform(1e-8, 3e-8, n)
    return rng, mass, inertia


def _state(rng, mass, dt):
    n = len(mass)
    state = State(X=rng.uniform(-0.1, 0.1, (n, 3)), mass=mass.copy(), dt=dt)
    state.u[:] = rng.uniform(-1e-3, 1e-3, (n, 3))
    state.v[:] = rng.uniform(-5.0, 5.0, (n, 3))
    state.a[:] = rng.uniform(-1e6, 1e6, (n, 3))
    return state


def test_one_sweep_is_the_solids_translations_and_the_rotations_closed_form():
    """One step of 300 nodes, a varying step (dt_v != dt), a rigid body's nodes not turning:
    u, v, K, the momentum integral and the booked work are the solids' pass's bit for bit;
    w^{n+1/2} = w + dt_v alpha bit for bit; the rotations' books are the exact sums."""
    n, dt = 300, 2e-7
    rng, mass, inertia = _nodes(n, 7)
    force = rng.uniform(-50.0, 50.0, (n, 3))
    moments = rng.uniform(-1e-3, 1e-3, (n, 3))
    w0 = rng.uniform(-300.0, 300.0, (n, 3))
    shell_state = _state(np.random.default_rng(1), mass, dt)
    solid_state = _state(np.random.default_rng(1), mass, dt)
    for s in (shell_state, solid_state):
        s.dt_previous = 1.5e-7  # dt_v = 1.75e-7
    body, solid = _Body(force, moments, inertia, w0), _Body(force, moments, inertia, w0)
    turning = np.ones(n)
    turning[::7] = 0.0  # a rigid body's nodes: their rotations' energy is its
    update = ShellUpdate(shell_state, body)
    body.turning = turning  # after the update was built: it binds it at its next call
    update(shell_state)
    CentralDifference(solid_state, solid)(solid_state)

    for name in ("u", "v", "momentum_integral"):
        assert np.array_equal(getattr(shell_state, name), getattr(solid_state, name)), name
    assert shell_state.kinetic == solid_state.kinetic
    assert body.booked == solid.booked
    dt_v = shell_state.dt_velocity
    assert np.array_equal(body.w.owned, w0 + dt_v * body.alpha)
    w1 = body.w.owned
    kinetic = 0.5 * math.fsum((inertia * turning)[:, None].repeat(3, 1).ravel()
                              * w0.ravel() * w1.ravel())  # fmt: skip
    first = math.fsum((moments * w0).ravel())
    second = math.fsum((moments * w1).ravel())
    # Sums of 900 terms of both signs, accumulated in order: a few hundred ulps of the
    # largest partial sum at most.
    scale = 0.5 * float(np.sum(inertia[:, None] * np.abs(w0 * w1)))
    assert abs(body.rotational_kinetic - kinetic) <= 1e-13 * scale
    m_scale = float(np.sum(np.abs(moments * w0)) + np.sum(np.abs(moments * w1)))
    assert abs(body.rotational_sums[0] - first) <= 1e-13 * m_scale
    assert abs(body.rotational_sums[1] - second) <= 1e-13 * m_scale
    # The rigid body's nodes turn (the body sets their alpha) but book no kinetic energy:
    # the turning given after the update was built is taken.
    every = 0.5 * math.fsum((inertia[:, None] * w0 * w1).ravel())
    assert abs(body.rotational_kinetic - every) > 0.05 * scale


@pytest.mark.parametrize("moment", [0.0, 2e-3])
def test_a_node_spun_for_1e5_steps(moment):
    """A node spinning at 500 rad/s about a skew axis, under a constant moment across it
    (or none), 10^5 steps alternating between two sizes: w(t) = w0 - M t / I, and the
    moment's work at mid-step velocities is the rotational kinetic energy lost. Without a
    moment, w stays w0 exactly and K = 1/2 I |w0|^2 at every step."""
    steps = 100_000
    inertia = np.array([2e-8])
    w0 = 500.0 * np.array([1.0, 2.0, 2.0]) / 3.0
    m = moment * np.array([2.0, -1.0, 0.0]) / math.sqrt(5.0)
    body = _Body(np.zeros((1, 3)), m[None, :], inertia, [w0])
    state = State(X=np.zeros((1, 3)), mass=np.ones(1), dt=1e-7)
    update = ShellUpdate(state, body)
    kinetic0 = 0.5 * inertia[0] * float(w0 @ w0)
    elapsed, largest = 0.0, kinetic0  # the sum of the velocity steps (s); the largest K (J)
    for step in range(steps):
        state.dt = 1e-7 if step % 2 == 0 else 1.2e-7
        update(state)
        dt_v = state.dt_velocity
        elapsed += dt_v
        largest = max(largest, body.rotational_kinetic)
        if moment == 0.0:
            assert body.rotational_kinetic == pytest.approx(kinetic0, rel=1e-15, abs=0.0)
        state.dt_previous, state.step, state.t = state.dt, step + 1, state.t + state.dt
    w = body.w.owned[0]
    if moment == 0.0:
        assert np.array_equal(w, w0)
        return
    alpha = -m / inertia[0]
    exact = w0 + elapsed * alpha
    assert np.linalg.norm(exact - w0) > np.linalg.norm(w0)  # turned well off w0
    # 10^5 roundings of w + dt_v alpha: 1e5 ulps of |w| at most.
    assert np.allclose(w, exact, rtol=0.0, atol=1e5 * 2.3e-16 * np.linalg.norm(w))
    # K^n = 1/2 I w^{n-1/2} . w^{n+1/2} (the shadow kinetic energy) ...
    shadow = 0.5 * inertia[0] * float((w - dt_v * alpha) @ w)
    assert body.rotational_kinetic == pytest.approx(shadow, rel=1e-13)
    # ... is K0 less the work of the moment booked up to the first half of step n
    # (body.work holds both halves: less the second, dt_v/2 M . w^{n+1/2}); to the
    # round-off of 10^5 additions of the work, 1e5 ulps of the largest K.
    work = body.work - 0.5 * dt_v * float(m @ w)
    assert abs(body.rotational_kinetic - kinetic0 + work) <= 1e5 * 2.3e-16 * largest
