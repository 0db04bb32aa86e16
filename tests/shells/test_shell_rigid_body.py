"""Rigid bodies of shell nodes (rwall_fem/shells/rigid.py): the body carries the nodes'
rotations and rotational inertia.

- A whole plate of shells made rigid, spinning about an axis that is not principal: its
  angular momentum (the nodes' masses and their rotational inertia sum I) is kept to
  round-off, every node turns with the body (w = omega), the cells strain nothing, and
  the body's kinetic energy drifts as a solid rigid body's under precession (within the
  2e-6 of tests/verification/test_rigid_body.py; seen 1e-8, the balance's error).
- A plate with one end rigid, spinning and falling onto a plane wall: the rigid nodes
  keep w = omega and the balance closes within omega dt of the body's rotational energy.
  That error is the body's integrator's, not the shells' (a solid block with a rigid end
  shows the same): the shadow rotational energy 1/4 (L^- . omega^+ + L^+ . omega^-),
  omega = R J0^-1 R^T L at mid-step rotations, is exact for a steady L only to the
  precession error (2e-15 here without the wall); an impulse dL from the wall in one
  step leaves 1/4 L . (J^-1(n+3/2) - J^-1(n+1/2)) dL, and the inertia turns by omega dt
  over a step, so the error is first order in omega dt: |error| <= omega dt |L| |dL|
  (1/J_min - 1/J_max) / 2 <= omega dt E_rot when the wall stops the spin. Measured
  0.03 omega dt E_rot at dt_scale 0.9, 0.45 and 0.225, and 0.006-0.009 at 200 and 300
  rad/s (5e-12 without the wall, 3e-15 without the spin).
"""

import copy

import numpy as np
import pytest
from conftest import run
from mpi4py import MPI

from rwall_fem import build_simulation, parse_scene

comm = MPI.COMM_WORLD
STEEL = {"model": "linear_elastic", "density": 7800.0, "young": 2.1e11, "poisson": 0.3}


def plate(**extra):
    raw = {
        "run": {"end_time": 3e-5},
        "mesh": {"shape": "plate", "size": [0.04, 0.02, 0.002], "element_size": 0.005,
                 "cell": "quadrilateral"},
        "material": dict(STEEL),
        "output": {"frames": 0, "plot": False},
    }  # fmt: skip
    return raw | extra


def test_a_rigid_plate_of_shells_keeps_its_angular_momentum(shared_dir):
    omega = [300.0, -200.0, 500.0]
    raw = plate(rigid_body=[{"box": {"low": [-1, -1, -1], "high": [1, 1, 1]},
                             "angular_velocity": omega}])  # fmt: skip
    sim = build_simulation(parse_scene(copy.deepcopy(raw), source="test"), comm, shared_dir)
    (body,) = sim.rigid_bodies
    s, shells = sim.state, sim.internal
    # J about the centre: the nodes' point masses and their rotational inertia.
    c = body.center0
    arms = s.X - c
    second = np.einsum("i,ij,ik->jk", s.mass, arms, arms)
    J = comm.allreduce(np.trace(second) * np.eye(3) - second)
    J += comm.allreduce(float(shells.inertia[:, 1].sum())) * np.eye(3)
    L0 = J @ np.array(omega)
    assert np.allclose(body.angular_momentum, L0, rtol=1e-12)
    assert sim.run() == "done"
    L = body.angular_momentum
    print(f"rigid plate: L {L} against {L0}, omega {body.omega}")
    assert np.allclose(L, L0, rtol=1e-12, atol=1e-12 * np.abs(L0).max())
    assert np.allclose(shells.w.owned, body.omega, rtol=1e-12, atol=0)
    energy = sim.history.summary["energy"]
    K0 = 0.5 * float(np.array(omega) @ L0)
    K = sim.history.energy[:, sim.history.balance.columns.index("rigid_body")]
    print(f"rigid plate: kinetic drift {np.abs(K - K0).max() / K0:.2e}, internal "
          f"{energy['internal']:.2e} J, balance {energy['max_balance_error']:.2e}")
    assert energy["rotational_kinetic"] == 0.0  # the nodes' rotations are the body's
    assert abs(energy["internal"]) <= 1e-12 * K0  # a rigid motion strains no shell
    assert np.abs(K - K0).max() <= 2e-6 * K0  # the solids' bound (tests/verification)
    assert energy["max_balance_error"] <= 1e-7


def test_a_plate_with_a_rigid_end_falls_on_a_wall(shared_dir):
    raw = plate(rigid_body=[{"box": {"low": [0.03, -1, -1], "high": [1, 1, 1]},
                             "angular_velocity": [0.0, 100.0, 0.0]}],
                initial={"velocity": [0.0, 0.0, -5.0]},
                wall=[{"kind": "plane", "point": [0.0, 0.0, 9.5e-4],
                       "normal_point": [0.0, 0.0, 1.0]}])  # fmt: skip
    sim = run(raw, shared_dir)
    (body,) = sim.rigid_bodies
    energy = sim.history.summary["energy"]
    print(f"rigid end: balance {energy['max_balance_error']:.2e}, wall work "
          f"{energy['wall_work']:.3e} J, internal {energy['internal']:.3e} J")
    assert energy["wall_work"] < 0.0
    assert energy["internal"] > 0.0
    omega = np.array([0.0, 100.0, 0.0])
    spin = 0.5 * float(omega @ body.inertia0 @ omega)  # E_rot at the start, J
    history = sim.history
    dt = float(history.energy[:, history.balance.columns.index("dt")].max())
    error = energy["max_balance_error"] * history.balance.reference  # J
    print(f"rigid end: error {error:.2e} J = {error / (100.0 * dt * spin):.3f} omega dt E_rot")
    assert error <= 100.0 * dt * spin  # the spin's first-order error at the impact
    w = sim.internal.w.owned[body.nodes]
    assert np.allclose(w, body.omega, rtol=1e-12, atol=0)
