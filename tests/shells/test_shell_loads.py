"""Loads, added masses and damping on shells (rwall_fem/shells/loads.py), against closed
forms.

- A free plate under a uniform pressure translates as a rigid body (the corner and edge
  nodes take the shares of the pressure their masses have): its momentum grows as p A t
  along -z (the cells' normal is +z), the pressure's work books its kinetic energy;
- a total force on an edge: the momentum grows as F t, whatever the nodes' masses;
- an added mass joins the body's mass (summary, momentum under gravity: (m + m_a) g t);
- mass-proportional damping of a plate translating and spinning about its normal (no
  drilling stiffness: a uniform spin strains nothing): v and w decay by (1 - alpha dt)
  each step, exactly, and damping_work books what the kinetic energies lose.

The balance closes to 1e-12 in every run.
"""

import numpy as np
import pytest
from conftest import run
from mpi4py import MPI

comm = MPI.COMM_WORLD
STEEL = {"model": "linear_elastic", "density": 7800.0, "young": 2.1e11, "poisson": 0.3}
SIZE = (0.04, 0.02, 0.002)
MASS = STEEL["density"] * SIZE[0] * SIZE[1] * SIZE[2]


def plate(cell="quadrilateral", end_time=2e-5, **extra):
    raw = {
        "run": {"end_time": end_time},
        "mesh": {"shape": "plate", "size": list(SIZE), "element_size": 0.005, "cell": cell},
        "material": dict(STEEL),
        "output": {"frames": 0, "plot": False},
    }
    return raw | extra


def _momentum_time(sim) -> float:
    """How long the forces of steps 0 .. n have acted on the velocities v^{n+1/2} of the
    summary's momentum (s): t^n + dt^{n+1/2} (the initial velocity is v^{-1/2})."""
    return sim.state.t + sim.state.dt


@pytest.mark.parametrize("cell", ["quadrilateral", "triangle"])
def test_a_pressure_pushes_a_free_plate_as_a_rigid_body(cell, shared_dir):
    p = 2e5
    sim = run(plate(cell, load=[{"kind": "pressure", "group": ["body"], "pressure": p}]),
              shared_dir)  # fmt: skip
    summary = sim.history.summary
    expected = p * SIZE[0] * SIZE[1] * _momentum_time(sim)
    momentum = np.array(summary["final_momentum"])
    print(f"{cell}: momentum {momentum} against (0, 0, {-expected:.6e})")
    assert momentum[2] == pytest.approx(-expected, rel=1e-12)
    assert np.abs(momentum[:2]).max() <= 1e-12 * expected
    strain = abs(summary["energy"]["internal"])
    assert strain <= 1e-12 * summary["energy"]["kinetic"]  # a rigid translation
    assert summary["energy"]["max_balance_error"] <= 1e-12


def test_a_force_on_an_edge_and_an_added_mass(shared_dir):
    F, added = np.array([3.0, 0.0, -5.0]), 2e-3
    raw = plate(load=[{"kind": "force", "group": ["side_x1"], "force": F.tolist(), "per": "set"}],
                added_mass=[{"group": ["side_x0"], "mass": added, "per": "set"}])  # fmt: skip
    sim = run(raw, shared_dir)
    summary = sim.history.summary
    assert summary["mass"] == pytest.approx(MASS + added, rel=1e-12)
    momentum = np.array(summary["final_momentum"])
    expected = F * _momentum_time(sim)
    assert np.allclose(momentum, expected, rtol=1e-12, atol=1e-12 * np.abs(expected).max())
    assert summary["energy"]["external_work"] > 0.0
    assert summary["energy"]["max_balance_error"] <= 1e-12
    g = np.array([0.0, 0.0, -9.81])
    raw = plate(gravity={"acceleration": g.tolist()},
                added_mass=[{"group": ["side_x0"], "mass": added, "per": "set"}])  # fmt: skip
    sim = run(raw, shared_dir / "gravity")
    momentum = np.array(sim.history.summary["final_momentum"])
    expected = (MASS + added) * g * _momentum_time(sim)
    assert np.allclose(momentum, expected, rtol=1e-12, atol=1e-12 * np.abs(expected).max())


def test_mass_proportional_damping_of_translations_and_rotations(shared_dir):
    from rwall_fem import build_simulation, parse_scene

    alpha, v0, w0 = 2e4, np.array([0.0, 3.0, -2.0]), 40.0  # 1/s: 1.5 % per step
    raw = plate(damping={"alpha": alpha}, initial={"velocity": v0.tolist()})
    sim = build_simulation(parse_scene(raw, source="test"), comm, shared_dir)
    body, s = sim.internal, sim.state
    body.w.owned[:, 2] = w0  # about the normal: no drilling stiffness, nothing strains
    sim.history.balance.initial = 0.5 * comm.allreduce(
        float(np.sum(s.mass) * v0 @ v0 + np.sum(body.inertia[:, 1]) * w0**2))  # fmt: skip
    assert sim.run() == "done"
    decay = (1.0 - alpha * s.dt) ** (s.step + 1)  # each update: v' = (1 - alpha dt) v
    print(f"damping: {s.step + 1} updates, decay {decay:.6f}; v {s.v[0]}, w {body.w.owned[0]}")
    assert np.allclose(s.v, v0 * decay, rtol=1e-12, atol=1e-12 * np.abs(v0).max())
    assert np.allclose(body.w.owned[:, 2], w0 * decay, rtol=1e-12)
    assert np.abs(body.w.owned[:, :2]).max() <= 1e-12 * w0
    energy = sim.history.summary["energy"]
    print(f"damping: damping_work {energy['damping_work']:.6e} J, rotational kinetic "
          f"{energy['rotational_kinetic']:.4e} J, balance {energy['max_balance_error']:.2e}")
    assert energy["damping_work"] < 0.0
    assert energy["max_balance_error"] <= 1e-12
