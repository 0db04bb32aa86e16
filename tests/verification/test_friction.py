"""Tangential behaviour: Coulomb friction by impulses, tied contact (docs/theory.md).

References are rigid-body closed forms: on an incline of angle theta a block
slides at g (sin theta - mu cos theta) when tan theta > mu and does not creep
when tan theta <= mu; a belt moving at V drags a block at mu g until it
reaches V; a belt accelerating as k t holds the block until k t = mu g, then
the block slips with acceleration mu g. The soft block rings elastically
under the sudden load; friction capped node by node must still give the
right mean force (docs/theory.md, "Tangential behaviour"), so velocities are compared
within 2 %.
"""

import math

import numpy as np
import pytest
from conftest import block_scene, run_probed

G, MU = 9.81, 0.3
FLOOR = {"kind": "plane", "point": [0.0, 0.0, 0.0], "normal_point": [0.0, 0.0, 1.0]}


def floor(**keys):
    return [FLOOR | keys]


def incline(tan_theta):
    theta = math.atan(tan_theta)
    return [G * math.sin(theta), 0.0, -G * math.cos(theta)], theta


@pytest.mark.parametrize("friction_filter", [None, {"steps": 20}])
def test_block_slides_down_steep_incline(friction_filter, shared_dir):
    gravity, theta = incline(0.5)
    wall = floor(slide="friction", friction=MU)
    if friction_filter:
        wall[0]["friction_filter"] = friction_filter
    sim, probe = run_probed(block_scene(gravity=gravity, wall=wall), shared_dir)
    expected = G * (math.sin(theta) - MU * math.cos(theta)) * probe.t[-1]
    assert probe.v[-1, 0] == pytest.approx(expected, rel=0.02)
    assert abs(probe.v[-1, 1]) < 1e-9 * probe.v[-1, 0]
    assert sim.history.summary["energy"]["max_balance_error"] < 1e-10
    friction_work = sim.history.summary["walls"][0]["friction_work"]
    sliding = probe.x[-1, 0] - probe.x[0, 0]
    mass = probe.mass
    # Work of the Coulomb force mu m g cos(theta) over the slide, within the same 2 %.
    assert -friction_work == pytest.approx(MU * mass * G * math.cos(theta) * sliding, rel=0.02)


def test_block_does_not_creep_on_shallow_incline(shared_dir):
    gravity, theta = incline(0.25)  # tan(theta) < mu: it must stick
    sim, probe = run_probed(
        block_scene(gravity=gravity, wall=floor(slide=2, friction=MU)), shared_dir
    )
    # Elastic shear deflection: 3.5 um; without friction the block would slide 5 cm.
    x = probe.x[:, 0] - probe.x[0, 0]
    assert abs(x[-1]) < 1e-5
    late = probe.t > 0.5 * probe.t[-1]
    assert np.ptp(x[late]) < 1e-6  # no creep once the ringing has settled
    assert np.abs(probe.v[late, 0]).max() < 1e-4


def test_conveyor_drags_block_at_mu_g(shared_dir):
    belt = 0.3  # m/s: reached after belt / (mu g) = 0.10 s
    wall = floor(slide="friction", friction=MU, motion={"velocity": [belt, 0.0, 0.0]})
    sim, probe = run_probed(block_scene(gravity=[0, 0, -G], wall=wall), shared_dir)
    t, v = probe.t, probe.v[:, 0]
    speeding = t < 0.8 * belt / (MU * G)
    assert v[speeding] == pytest.approx(MU * G * t[speeding], rel=0.02, abs=0.02 * belt)
    assert v[t > 1.3 * belt / (MU * G)] == pytest.approx(belt, rel=0.01)
    assert sim.history.summary["energy"]["max_balance_error"] < 1e-10


def test_accelerating_belt_holds_then_slips(shared_dir):
    k = 30.0  # m/s^3: the belt's acceleration is k t; slip starts at mu g / k = 0.098 s
    times = np.linspace(0.0, 0.2, 201)
    table = [[t, 0.5 * k * t * t, 0.0, 0.0] for t in times]
    wall = floor(slide="friction", friction=MU, motion={"velocity": table})
    sim, probe = run_probed(block_scene(gravity=[0, 0, -G], wall=wall), shared_dir)
    t, v = probe.t, probe.v[:, 0]
    onset = MU * G / k
    stick = (t > 0.2 * onset) & (t < 0.8 * onset)
    assert v[stick] == pytest.approx(0.5 * k * t[stick] ** 2, rel=0.03, abs=2e-3)
    expected_end = 0.5 * k * onset**2 + MU * G * (t[-1] - onset)
    assert v[-1] == pytest.approx(expected_end, rel=0.02)


def test_tied_face_follows_a_prescribed_wall(shared_dir):
    belt = [0.2, -0.1, 0.0]  # reached in 30 ms: a sudden start would make the block jump
    ramp = [[0.0, 0.0, 0.0, 0.0], [0.03, *belt], [1.0, *belt]]
    wall = floor(slide="tied", motion={"velocity": ramp})
    sim, probe = run_probed(block_scene(gravity=[0, 0, -G], wall=wall, end_time=0.05), shared_dir)
    s, w = sim.state, sim.constraints[0]
    assert w.comm.allreduce(len(w.touching)) > 0
    # The last update gave the nodes in contact exactly the wall's velocity, all components.
    assert np.allclose(s.v[w.touching], belt, rtol=0, atol=1e-12)
    assert probe.v[-1, :2] == pytest.approx(belt[:2], abs=0.1 * np.linalg.norm(belt))


def test_tied_face_follows_a_main_node_wall(shared_dir):
    velocity = [0.5, 0.2, 0.0]
    wall = floor(slide="tied", motion={"mass": 1e-2, "velocity": velocity})
    scene = block_scene(gravity=[0, 0, -G], wall=wall, end_time=0.05, velocity=velocity)
    sim, probe = run_probed(scene, shared_dir)
    s, w = sim.state, sim.constraints[0]
    assert w.comm.allreduce(len(w.touching)) > 0
    assert np.allclose(s.v[w.touching], w.motion.velocity, rtol=0, atol=1e-12)
    assert w.motion.velocity[2] < 0  # the block's weight pushes the free wall down
    summary = sim.history.summary
    p0, p1 = np.array(summary["initial_momentum"]), np.array(summary["final_momentum"])
    # Gravity acts on the body only: the tangential momentum is conserved, exactly but for
    # the round-off of sum(K u) (2e-12 seen).
    assert np.allclose(p1[:2], p0[:2], rtol=0, atol=1e-11 * np.linalg.norm(p0))
    pushed = np.array(summary["walls"][0]["impulse"])
    gained = w.motion.mass * (w.motion.velocity - velocity)
    assert np.allclose(gained, pushed, rtol=0, atol=1e-13 * np.abs(pushed).max())
    assert summary["energy"]["max_balance_error"] < 1e-10


def test_sticking_nodes_follow_a_main_node_wall(shared_dir):
    """mu = 1 and a block moving with its wall: every node in contact sticks and has
    exactly the wall's velocity, although the wall itself is pushed by the block."""
    velocity = [0.4, -0.3, 0.0]
    wall = floor(slide="friction", friction=1.0, motion={"mass": 1e-2, "velocity": velocity})
    scene = block_scene(gravity=[0, 0, -G], wall=wall, end_time=0.05, velocity=velocity)
    sim, probe = run_probed(scene, shared_dir)
    s, w = sim.state, sim.constraints[0]
    assert w.comm.allreduce(len(w.touching)) > 0
    assert np.allclose(s.v[w.touching], w.motion.velocity, rtol=0, atol=1e-12)
    assert sim.history.summary["walls"][0]["friction_work"] == pytest.approx(0.0, abs=1e-15)
