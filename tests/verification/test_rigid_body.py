"""Rigid bodies ([[rigid_body]], Radioss /RBODY) against closed forms and the books.

- a rigid block falls under gravity onto a fixed plane: free flight is central
  differences' own closed form for constant acceleration (to round-off), the impact stops
  the body within the step as the kinematic wall stops a node (no node behind the wall,
  the normal velocity 0, the wall's impulse M v and its work -1/2 M v^2, the balance to
  round-off), and then the wall carries the weight; spinning, it lands on an edge and
  the books still close to round-off (the wall's work on the body's nodes is booked at
  the body's velocities V + omega x a, which its kinetic energy takes);
- a body spinning freely about a principal axis turns at constant omega (the nodes on
  the exact rotation exp(omega t)); about no principal axis its angular momentum stays
  constant to round-off and its kinetic energy within 2e-6;
- a deformable bar with a rigid end of mass M strikes a wall: until the wave reflected at
  the end returns, the end's velocity is the closed form of a mass on a bar, v0 - 2 v0
  exp(-(t - L/c)/tau) with tau = M / (rho c A), and the wall's force is rho c A v0.

Every test runs serially and on 2 ranks (the bodies span the partition).
"""

import math

import numpy as np
import pytest
from conftest import COLUMN, StopAt, run
from mpi4py import MPI

from rwall_fem import build_simulation, parse_scene
from rwall_fem.rigid_body import rotation
from rwall_fem.study.cases import SOFT

# The free spin's kinetic energy, relative: 5.1e-7 measured over 1500 steps at |omega| dt
# = 4.3e-3 (1.3e-7 over 3000 steps at half the step: the scheme's error, second order; the
# angular momentum is exact).
KINETIC_DRIFT = 2e-6
STEEL = {"model": "linear_elastic", "density": 7850.0, "young": 210e9, "poisson": 0.0}


class RigidProbe:
    """Samples the first rigid body each step: t^n, V^{n+1/2} (after the step's update) and
    the smallest height of the body's nodes at t^n (m)."""

    def __init__(self, sim):
        self.body = sim.rigid_bodies[0]
        self.comm = sim.comm
        self.t, self.v, self.low = [], [], []
        sim.recorders.append(self)

    def due(self, s):
        return True

    def record(self, sim, s):
        self.t.append(s.t)
        self.v.append(self.body.previous[0].copy())  # V^{n-1/2}: this step is not yet updated
        z = (s.X[:, 2] + s.u[:, 2]).min(initial=np.inf)
        self.low.append(self.comm.allreduce(float(z), op=MPI.MIN))

    def close(self, sim):
        self.t, self.v, self.low = map(np.array, (self.t, self.v, self.low))


def _run_probed(raw, directory):
    sim = build_simulation(parse_scene(raw, source="test"), MPI.COMM_WORLD, directory)
    probe = RigidProbe(sim)
    sim.run()
    return sim, probe


def test_rigid_block_falls_on_a_wall(shared_dir):
    g, v0, gap, dt = 9.81, 0.2, 1e-3, 4e-5
    raw = {
        "run": {"end_time": 0.014, "dt": dt},
        "mesh": {"shape": "bar", "origin": [0.0, 0.0, gap], "size": [0.01, 0.01, 0.01],
                 "element_size": 0.0025, "cell": "hexahedron"},
        "material": SOFT,
        "initial": {"velocity": [0.0, 0.0, -v0]},
        "gravity": {"acceleration": [0.0, 0.0, -g]},
        "wall": [{"kind": "plane", "point": [0, 0, 0], "normal_point": [0, 0, 1]}],
        "rigid_body": [{"box": {"low": [-1, -1, -1], "high": [1, 1, 1]}}],
        "output": {"plot": False, "history_interval": 1},
    }  # fmt: skip
    sim, probe = _run_probed(raw, shared_dir)
    body, s = sim.rigid_bodies[0], sim.history.summary
    M = body.mass
    assert math.isclose(M, SOFT["density"] * 1e-6, rel_tol=1e-12)  # the nodes' lumped masses
    # Free flight: V^{n-1/2} = -v0 - g n dt, h^n = gap - v0 n dt - g dt^2 n (n + 1)/2.
    n = np.arange(len(probe.t))
    free = np.abs(probe.low - (gap - v0 * n * dt - g * dt**2 * n * (n + 1) / 2)) < 1e-15
    flight = n[probe.low > 2 * v0 * dt]  # steps before the body reaches the wall's reach
    assert np.allclose(probe.v[flight, 2], -v0 - g * n[flight] * dt, rtol=0, atol=1e-12)
    assert free[flight].all()
    # The impact: within one step the body stops; no node ever goes behind the wall.
    hit = int(np.argmax(np.abs(probe.v[1:, 2]) < 1e-9)) + 1
    v_hit = -probe.v[hit - 1, 2]
    assert probe.low.min() >= -1e-15
    # It stops at most one step of travel short of the wall, and falls that gap again
    # under its weight before the wall holds it again (as it holds a node).
    assert abs(probe.v[hit, 2]) < 1e-9 * v0
    assert np.abs(probe.v[hit:, 2]).max() < math.sqrt(2 * g * v_hit * dt) + g * dt
    assert np.abs(probe.v[:, :2]).max() < 1e-12 * v0
    # Momentum: the wall's impulse on the body takes M v and then the weight.
    wall_push = -np.array(s["walls"][0]["normal_impulse"])  # on the body, N s
    change = np.array(s["final_momentum"]) - np.array(s["initial_momentum"])
    T = s["time"] + s["dt"]  # the momentum is that of v^{n+1/2}
    weight = M * np.array([0.0, 0.0, -g]) * T
    assert np.allclose(change, wall_push + weight, rtol=0, atol=1e-12 * M * v0)
    # Energy: the stop destroys 1/2 M v^2 (wall work), and so does each stop at rest; the
    # balance closes to round-off.
    energy = s["energy"]
    # The stop takes I = M (v + g dt), the predicted velocity, working on v^{n-1/2} = v.
    E = 0.5 * M * v_hit * (v_hit + g * dt)
    fallen = probe.low[hit] - probe.low[-1]  # resting, it falls the gaps the wall leaves
    assert math.isclose(-energy["wall_work"], E + M * g * fallen, rel_tol=1e-9)
    assert abs(energy["rigid_body"]) < 1e-12 * E and abs(energy["kinetic"]) < 1e-12 * E
    assert energy["max_balance_error"] < 1e-10


def test_spinning_rigid_block_lands_on_an_edge(shared_dir):
    """omega dt = 8e-4; the edge's impact reverses the spin. At the nodes' velocities (the
    chords of the finite rotation) the wall's work would miss the body's by O(dt omega^2
    |a| |I|): 5e-4 of the energy here, 1.8e-5 with a steel cube at 100 rad/s."""
    v0, omega, gap = 1.0, 20.0, 5e-4
    raw = {
        "run": {"end_time": 0.004, "dt": 4e-5},
        "mesh": {"shape": "bar", "origin": [0.0, 0.0, gap], "size": [0.01, 0.01, 0.01],
                 "element_size": 0.0025, "cell": "hexahedron"},
        "material": SOFT,
        "initial": {"velocity": [0.0, 0.0, -v0]},
        "wall": [{"kind": "plane", "point": [0, 0, 0], "normal_point": [0, 0, 1]}],
        "rigid_body": [{"box": {"low": [-1, -1, -1], "high": [1, 1, 1]},
                        "angular_velocity": [0.0, omega, 0.0]}],
        "output": {"plot": False, "history_interval": 1},
    }  # fmt: skip
    sim = run(raw, shared_dir)
    (body,) = sim.rigid_bodies
    energy = sim.history.summary["energy"]
    print(f"spinning block: wall work {energy['wall_work']:.4e} J, omega {body.omega}, "
          f"balance {energy['max_balance_error']:.2e}")
    assert energy["wall_work"] < -0.25 * body.mass * v0**2  # it struck the wall
    assert body.omega[1] < -0.5 * omega  # on an edge: the impact reversed the spin
    assert energy["max_balance_error"] < 1e-12


def _spinning(omega, end_time, shared_dir, model="saint_venant_kirchhoff"):
    """A soft brick (c about 37 m/s: a step of 4e-5 s) of ``model`` turning at ``omega``
    (rad/s); its cells are all inside the body: not computed."""
    raw = {
        "run": {"end_time": end_time, "dt": 4e-5},
        "mesh": {"shape": "bar", "origin": [0.0, 0.0, 0.0], "size": [0.004, 0.006, 0.01],
                 "element_size": 0.002, "cell": "hexahedron"},
        "material": dict(SOFT, model=model),
        "rigid_body": [{"box": {"low": [-1, -1, -1], "high": [1, 1, 1]}}],
        "output": {"plot": False},
    }  # fmt: skip
    raw["rigid_body"][0]["angular_velocity"] = list(omega)
    return run(raw, shared_dir)


def test_spin_about_a_principal_axis_is_the_exact_rotation(shared_dir):
    omega = np.array([0.0, 0.0, 120.0])  # rad/s: about 1.1 turns in the run
    sim = _spinning(omega, 0.06, shared_dir)
    s, body = sim.state, sim.rigid_bodies[0]
    T = s.t + s.dt  # the positions are u^{n+1}
    R = rotation(omega * T)
    x = body.center0 + (s.X - body.center0) @ R.T
    assert np.abs(s.X + s.u - x).max() < 1e-12 * 0.01
    assert np.allclose(body.omega, omega, rtol=0, atol=1e-12 * 120)
    energy = sim.history.energy
    names = sim.history.balance.columns
    K = energy[:, names.index("rigid_body")]
    assert np.ptp(K) < 1e-10 * K[0]
    assert sim.history.summary["energy"]["max_balance_error"] < 1e-9


@pytest.mark.parametrize("model", ["saint_venant_kirchhoff", "linear_elastic"])
def test_spin_about_no_principal_axis_keeps_its_angular_momentum(model, shared_dir):
    """(Computed, the cells of a small-strain material would take half the kinetic energy
    and turn L within a turn: they are not.)"""
    omega = np.array([40.0, 60.0, 80.0])  # rad/s, |omega| dt about 4e-3
    sim = _spinning(omega, 0.06, shared_dir, model)
    assert sim.history.summary["rigid_cells"] == 2 * 3 * 5
    assert sim.history.summary["energy"]["internal"] == 0.0
    body = sim.rigid_bodies[0]
    L0 = body.inertia0 @ omega
    assert np.abs(body.angular_momentum - L0).max() < 1e-11 * np.linalg.norm(L0)
    # The nodes turn with the body: their own angular momentum about c is the body's to
    # the order of the chord velocities (|omega| dt ~ 4e-3).
    s = sim.state
    m = s.mass[:, None]
    x = s.X + s.u - s.dt * s.v / 2  # at mid-step
    local = np.sum(np.cross(x - body.center + s.dt * body.velocity / 2, m * s.v), axis=0)
    nodes = sim.comm.allreduce(local)
    assert np.linalg.norm(nodes - L0) < 5e-3 * np.linalg.norm(L0)
    names = sim.history.balance.columns
    K = sim.history.energy[:, names.index("rigid_body")]
    K0 = 0.5 * omega @ L0
    assert np.abs(K - K0).max() < KINETIC_DRIFT * K0
    # The body precessed: omega is not where it started.
    assert np.linalg.norm(body.omega - omega) > 0.01 * np.linalg.norm(omega)


def test_bar_with_a_rigid_end_mass(shared_dir):
    """A steel bar (nu = 0, 40 layers) whose top face is a rigid body with added mass
    equal to the bar's strikes a fixed plane at v0."""
    h, layers, v0 = 1e-3, 40, 5.0
    L, A = layers * h, h * h
    rho, E = STEEL["density"], STEEL["young"]
    c = math.sqrt(E / rho)
    added = rho * A * L
    raw = {
        "run": {"end_time": 3.0 * L / c},
        "mesh": {"shape": "bar", "origin": [0, 0, 0], "size": [h, h, L], "element_size": h,
                 "cell": "hexahedron"},
        "material": STEEL,
        "initial": {"velocity": [0.0, 0.0, -v0]},
        "wall": [{"kind": "plane", "point": [0, 0, 0], "normal_point": [0, 0, 1]}],
        "rigid_body": [{"sets": ["top"], "mass": added}],
        "output": {"plot": False, "history_interval": 1},
    }  # fmt: skip
    sim, probe = _run_probed(raw, shared_dir)
    body = sim.rigid_bodies[0]
    M = body.mass
    assert math.isclose(M, added + rho * A * h / 2, rel_tol=1e-12)  # + the top layer's nodes
    tau = M / (rho * c * A)
    t = probe.t[1:]  # the mid-step times of V^{n-1/2}
    mid = t - np.diff(probe.t, prepend=0.0)[1:] / 2
    V = -probe.v[1:, 2]  # toward the wall
    exact = np.where(mid < L / c, v0, -v0 + 2 * v0 * np.exp(-(mid - L / c) / tau))
    window = (mid > 1.15 * L / c) & (mid < 2.9 * L / c)
    assert np.abs(V[window] - exact[window]).max() < 0.02 * v0  # 0.0093 v0 measured
    assert np.abs(V[mid < 0.9 * L / c] - v0).max() < 1e-12 * v0  # the wave has not arrived
    # The wall's push up to 2 L / c, against rho c A v0 (2 L / c): impulse_z is cumulative.
    rows = sim.history.wall(0)
    before = rows[rows[:, COLUMN["time"]] <= 1.95 * L / c]
    push = -before[-1, COLUMN["impulse_z"]]
    assert math.isclose(push, rho * c * A * v0 * before[-1, 0], rel_tol=0.015)  # 0.0064
    s = sim.history.summary
    assert s["energy"]["max_balance_error"] < 1e-10
    change = np.array(s["final_momentum"]) - np.array(s["initial_momentum"])
    push = -np.array(s["walls"][0]["normal_impulse"])
    assert np.allclose(change, push, rtol=0, atol=1e-10 * M * v0)


def test_friction_wall_gives_its_impulses_to_the_body(shared_dir):
    """A rigid block lands obliquely on a Coulomb plane: the wall treats the nodes with
    their own masses and the body takes those impulses as they are (Radioss's way with a
    wall's secondary nodes of a rigid body): the momentum books close to round-off, the
    body is stopped over a few steps, not within one, and slides and tips on."""
    raw = {
        "run": {"end_time": 0.01, "dt": 4e-5},
        "mesh": {"shape": "bar", "origin": [0.0, 0.0, 1e-4], "size": [0.01, 0.01, 0.01],
                 "element_size": 0.0025, "cell": "hexahedron"},
        "material": SOFT,
        "initial": {"velocity": [1.0, 0.0, -0.2]},
        "wall": [{"kind": "plane", "point": [0, 0, 0], "normal_point": [0, 0, 1],
                  "slide": "friction", "friction": 0.3}],
        "rigid_body": [{"box": {"low": [-1, -1, -1], "high": [1, 1, 1]}}],
        "output": {"plot": False},
    }  # fmt: skip
    sim, probe = _run_probed(raw, shared_dir)
    s, body = sim.history.summary, sim.rigid_bodies[0]
    w = s["walls"][0]
    push = -np.array(w["normal_impulse"]) - np.array(w["tangential_impulse"])
    change = np.array(s["final_momentum"]) - np.array(s["initial_momentum"])
    assert np.allclose(change, push, rtol=0, atol=1e-12 * body.mass)
    assert math.isclose(push[2], body.mass * 0.2, rel_tol=1e-3)  # the normal velocity taken
    assert 0.2 * push[2] < -push[0] < 0.4 * push[2]  # friction, about mu N
    assert abs(body.velocity[2]) < 1e-3 and body.velocity[0] > 0.8  # stopped, sliding
    assert probe.low.min() > -0.2 * 1e-3  # the creep: about M / m_bottom steps of travel
    assert s["energy"]["max_balance_error"] < 1e-6


def test_a_resumed_run_equals_an_uninterrupted_one(shared_dir, monkeypatch):
    """A spinning rigid end on a soft bar falls under gravity onto a plane; stopped by
    SIGTERM while in contact and resumed from its checkpoint, the run ends bit for bit as
    the one that never stopped."""
    import rwall_fem.output.history

    raw = {
        "run": {"end_time": 0.006, "dt": 4e-5},
        "mesh": {"shape": "bar", "origin": [0.0, 0.0, 2e-4], "size": [0.005, 0.005, 0.01],
                 "element_size": 0.0025, "cell": "hexahedron"},
        "material": SOFT,
        "initial": {"velocity": [0.1, 0.0, -0.2]},
        "gravity": {"acceleration": [0.0, 0.0, -9.81]},
        "wall": [{"kind": "plane", "point": [0, 0, 0], "normal_point": [0, 0, 1]}],
        "rigid_body": [{"sets": ["bottom"], "mass": 2e-4, "angular_velocity": [0, 0, 20.0]}],
        "output": {"plot": False, "history_interval": 1, "checkpoint_steps": 10},
    }  # fmt: skip
    root = shared_dir
    whole = build_simulation(parse_scene(raw, source="test"), MPI.COMM_WORLD, root / "whole")
    assert whole.run() == "done"
    wall = whole.history.summary["walls"][0]
    stop = int(wall["first_contact"] / 4e-5) + 3  # in contact
    assert wall["last_contact"] > (stop + 1) * 4e-5
    monkeypatch.setattr(rwall_fem.output.history, "POLL_SECONDS", 1e9)
    sim = build_simulation(parse_scene(raw, source="test"), MPI.COMM_WORLD, root / "cut")
    sim.recorders.append(StopAt(stop))
    assert sim.run().startswith("stopped")
    MPI.COMM_WORLD.Barrier()
    sim = build_simulation(parse_scene(raw, source="test"), MPI.COMM_WORLD, root / "cut")
    sim.checkpoints.resume(sim)
    assert sim.run() == "done"
    MPI.COMM_WORLD.Barrier()
    assert np.array_equal(sim.state.u, whole.state.u)
    assert np.array_equal(sim.state.v, whole.state.v)
    a, b = whole.rigid_bodies[0], sim.rigid_bodies[0]
    assert np.array_equal(a.R, b.R) and np.array_equal(a.angular_momentum, b.angular_momentum)
    if MPI.COMM_WORLD.rank == 0:
        for name in ("energy.csv", "walls.csv"):
            assert (root / "cut" / name).read_text() == (root / "whole" / name).read_text()
