"""Rigid bodies of shell nodes (rwall_fem/shells/rigid.py): the body carries the nodes'
rotations and rotational inertia.

- A whole plate of shells made rigid, spinning about an axis that is not principal: its
  angular momentum (the nodes' masses and their rotational inertia sum I) is kept to
  round-off, every node turns with the body (w = omega), the cells strain nothing, and
  the body's kinetic energy drifts as a solid rigid body's under precession (within the
  2e-6 of tests/verification/test_rigid_body.py; seen 1e-8, the balance's error).
- A plate with one end rigid, spinning and falling onto a plane wall: the rigid nodes
  keep w = omega, and the balance's error is second order in the step. The wall's work
  on the body is booked at the body's velocities V + omega x a (rwall_fem/rigid_contact.py),
  which closes a wholly rigid body on a wall to round-off (tests/verification); what is
  left is the cells' work on the body's nodes, done at their velocities, the chords of
  the body's finite rotation: the halves v^{n-1/2}, v^{n+1/2} differ from V + omega x a^n
  by -+ dt/2 omega x (omega x a), which cancel but for the change of omega over a step:
  O(dt^3) a step, O(dt^2) over the run. Measured at dt_scale 0.9, 0.45, 0.225: 1.1e-9,
  2.2e-10, 5.1e-11 (halving divides it by 5.2 and 4.3; 5.5e-9 before the wall's
  booking at the body's velocities; 6e-12 without the wall, 3e-15 without the spin).
  A solid block with a rigid spinning end does the same (4.6e-8 at 0.9, 1.9e-6 before).
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
    errors = []
    for scale in (0.9, 0.45, 0.225):
        raw["run"]["dt_scale"] = scale
        sim = run(raw, shared_dir)
        energy = sim.history.summary["energy"]
        errors.append(energy["max_balance_error"])
        print(f"rigid end, dt_scale {scale}: balance {errors[-1]:.2e}, wall work "
              f"{energy['wall_work']:.3e} J, internal {energy['internal']:.3e} J")
        assert energy["wall_work"] < 0.0
        assert energy["internal"] > 0.0
        (body,) = sim.rigid_bodies
        w = sim.internal.w.owned[body.nodes]
        assert np.allclose(w, body.omega, rtol=1e-12, atol=0)
    # Second order: each halving of the step divides the error by about 4 (seen 5.2, 4.3).
    assert errors[1] <= errors[0] / 3 and errors[2] <= errors[1] / 3
    assert errors[0] <= 1e-8  # (seen 1.1e-9)
