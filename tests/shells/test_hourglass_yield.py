"""QEPH's yielding hourglass forces (element.hourglass_yield; shell_quad.c,
qeph_hourglass_yield), one quadrilateral driven through the kernel on NumPy arrays.

The reference is OpenRadioss's rule (CZFINTN1, czfintn.F) worked by hand on a square cell
of side a, whose membrane hourglass force Q grows by k dq per step elastically, with
k = hk (4/3) E' t and the hourglass stress V = 2 E' Q / (k a) (Radioss's VGLAS):
- a pure hourglass motion strains no point (one in-plane point), so the cell yields only
  when 0.85^2 (1 + nu + nu^2) V^2 > sigma_y^2; from that step on 0.001 of each increment is
  kept, so Q saturates at the yield value k u_c plus 0.001 k (u - u_c), and unloading is
  elastic (full k); the booked hourglass energy is the work of Q, its part not stored
  Q^2 / (2 k) the area of the path by hand;
- while every point flows (a uniform stretch past yield), each increment is scaled by
  the points' mean E_t / E = H / (H + E) of the linear hardening H.

On a body (a plate of shells dented by a sphere wall): the books close to round-off (the
hourglass energy is the forces' work, its dissipated part included), 1 and 2 ranks give the
same energies to 1e-10, and a run resumed from its checkpoint equals the uninterrupted one
bit for bit (the yield keeps no state beside the hourglass forces).
"""

import copy
import math
from types import SimpleNamespace

import numpy as np
import pytest
from conftest import StopAt, run
from mpi4py import MPI

from rwall_fem import build_simulation, parse_scene
from rwall_fem.shells.elements import ShellKernel, ShellTechnology

comm = MPI.COMM_WORLD

E, NU, RHO, T, A_SIDE = 210e9, 0.3, 7850.0, 1.5e-3, 0.01
EP = E / (1 - NU**2)
SIGMA_Y, H = 300e6, 300e6  # the peer tube deck's hardening: 300 MPa + 300 MPa eps_p
J2 = SimpleNamespace(model="elastic_plastic", plastic=True, young=E, poisson=NU, density=RHO,
                     hardening="power", yield_stress=SIGMA_Y, hardening_coefficient=H,
                     hardening_exponent=1.0, strain_rate_coefficient=0.0,
                     reference_strain_rate=1.0, failure=None, heating=None)  # fmt: skip
HK = 0.05
SQUARE = np.array([[0.0, 0.0, 0.0], [A_SIDE, 0.0, 0.0], [A_SIDE, A_SIDE, 0.0],
                   [0.0, A_SIDE, 0.0]])  # fmt: skip
HOURGLASS = np.array([1.0, -1.0, 1.0, -1.0])  # the x-mode's nodal pattern (4 x y / a^2)


def kernel(hourglass_yield=True):
    technology = ShellTechnology.choose("quadrilateral", hourglass=(0.0, 0.0, 0.0),
                                        hourglass_stiffness=HK,
                                        hourglass_yield=hourglass_yield)  # fmt: skip
    return ShellKernel(J2, technology, np.array([[0, 1, 2, 3]], np.int32), T)


def drive(k, u, velocity, steps, dt, energy):
    """``steps`` steps of nodal velocity ``velocity`` (4 x 3); returns the new u and the
    membrane x-mode hourglass force after each step."""
    forces = []
    slot = k.shell.hourglass_slot
    for _ in range(steps):
        u = u + dt * velocity
        f, m = np.zeros((4, 3)), np.zeros((4, 3))
        k.run(dt, SQUARE, u, velocity, np.zeros((4, 3)), f, m, energy=energy)
        forces.append(k.history[slot, 0])
    return u, np.array(forces)


def test_pure_hourglass_mode_saturates_at_radioss_yield():
    """Loading: elastic up to the step whose hourglass stress passes
    sigma_y / (0.85 sqrt(1 + nu + nu^2)), then 0.001 of each increment; unloading elastic;
    the force and the energy the hourglass work leaves (not stored) against the hand
    values within 1e-5 (the cell's shape changes by 1e-3 over the run)."""
    k_m = HK * 4.0 / 3.0 * EP * T
    u_yield = SIGMA_Y / (0.85 * math.sqrt(1 + NU + NU**2)) * A_SIDE / (2 * EP)
    dt, speed = 1e-7, 0.37  # du = 3.7e-8 m per step, u_yield / du = 175.6
    du = speed * dt
    velocity = np.zeros((4, 3))
    velocity[:, 0] = speed * HOURGLASS
    k, energy = kernel(), np.zeros(4)
    elastic_steps = math.floor(u_yield / du)
    loading = 3 * elastic_steps
    u, forces = drive(k, np.zeros((4, 3)), velocity, loading, dt, energy)
    # by hand: full increments before the crossing step, 0.001 of the rest
    by_hand = np.array([k_m * du * min(n, elastic_steps) + 1e-3 * k_m * du
                        * max(0, n - elastic_steps) for n in range(1, loading + 1)])  # fmt: skip
    assert forces == pytest.approx(by_hand, rel=1e-5)
    q_top = by_hand[-1]
    work = 0.5 * k_m * (elastic_steps * du) ** 2 + sum(
        (by_hand[n - 1] + 0.5e-3 * k_m * du) * du for n in range(elastic_steps + 1, loading + 1)
    )
    assert energy[1] == pytest.approx(work, rel=1e-5)
    assert energy[2] == 0.0  # no point flowed
    # unloading: the full stiffness back (the old force's work on the increment < 0)
    back = elastic_steps // 2
    u, unloading = drive(k, u, -velocity, back, dt, energy)
    assert unloading == pytest.approx(q_top - k_m * du * np.arange(1, back + 1), rel=1e-5)
    dissipated = energy[1] - unloading[-1] ** 2 / (2 * k_m)
    assert dissipated == pytest.approx(work - q_top**2 / (2 * k_m), rel=1e-5)
    assert dissipated > 0.5 * work


def test_elastic_hourglass_without_yield():
    """hourglass_yield off: the same drive stays elastic (Q = k u) however far."""
    k_m = HK * 4.0 / 3.0 * EP * T
    dt, speed = 1e-7, 0.37
    velocity = np.zeros((4, 3))
    velocity[:, 0] = speed * HOURGLASS
    k, energy = kernel(hourglass_yield=False), np.zeros(4)
    _, forces = drive(k, np.zeros((4, 3)), velocity, 500, dt, energy)
    assert forces[-1] == pytest.approx(k_m * speed * dt * 500, rel=1e-5)
    assert energy[1] == pytest.approx(forces[-1] ** 2 / (2 * k_m), rel=1e-5)


def test_flowing_points_keep_the_tangent_share():
    """A uniform stretch in x (ydot = 0) past yield with the hourglass mode on top: while the
    points flow, each hourglass increment is H / (H + E) of the elastic one (that of the
    same drive with hourglass_yield off), within 1e-9."""
    dt, rate, speed = 1e-7, 200.0, 0.01
    velocity = np.zeros((4, 3))
    velocity[:, 0] = rate * SQUARE[:, 0] + speed * HOURGLASS
    runs = []
    for hourglass_yield in (True, False):
        k, energy = kernel(hourglass_yield), np.zeros(4)
        u, increments, flowing = np.zeros((4, 3)), [], []
        previous = 0.0
        for _ in range(200):  # strain 4e-3: yield at 1.3e-3 (plane strain in y)
            u = u + dt * velocity
            before = energy[2]
            f, m = np.zeros((4, 3)), np.zeros((4, 3))
            k.run(dt, SQUARE, u, velocity, np.zeros((4, 3)), f, m, energy=energy)
            q = k.history[k.shell.hourglass_slot, 0]
            increments.append(q - previous)
            flowing.append(energy[2] > before)
            previous = q
        runs.append((np.array(increments), np.array(flowing)))
    (yielding, flows), (elastic, _) = runs
    assert flows.sum() > 100
    assert yielding[~flows] == pytest.approx(elastic[~flows], rel=1e-12)
    assert yielding[flows] / elastic[flows] == pytest.approx(H / (H + E), rel=1e-9)


def dent_scene():
    """A 20 x 20 mm steel plate of 1 mm quadrilateral shells (1 mm thick), its edges held,
    dented at 150 m/s by a 10 mm sphere wall of 20 g; QEPH's hourglass (Ishell 24's
    reading: hk 0.01365, hourglass_yield)."""
    return {
        "run": {"end_time": 3e-5},
        "mesh": {"shape": "plate", "size": [0.02, 0.02, 1e-3], "element_size": 1e-3,
                 "cell": "quadrilateral"},
        "material": {"model": "elastic_plastic", "density": 7850.0, "young": 210e9,
                     "poisson": 0.3, "hardening": "linear", "yield_stress": 300e6,
                     "hardening_modulus": 300e6},
        "element": {"hourglass_stiffness": 0.01365, "hourglass_yield": True},
        "boundary": [{"group": side, "velocity": [0.0, 0.0, 0.0]}
                     for side in ("side_x0", "side_x1", "side_y0", "side_y1")],
        "wall": [{"kind": "sphere", "point": [0.0101, 0.0099, 0.0055], "diameter": 0.01,
                  "motion": {"mass": 0.02, "velocity": [0.0, 0.0, -150.0]}}],
        "output": {"plot": False, "frames": 0, "history_interval": 5},
    }  # fmt: skip


def test_a_dented_plate_closes_its_books_on_any_ranks(shared_dir, tmp_path_factory):
    sim = run(dent_scene(), shared_dir)
    energy = sim.history.summary["energy"]
    print(f"dent: hourglass {energy['hourglass']:.4e} J, plastic "
          f"{sim.history.summary['plastic_work']:.4e} J, balance "
          f"{energy['max_balance_error']:.2e}")
    assert sim.history.summary["plastic_work"] > 0.0
    assert energy["hourglass"] > 0.0
    assert energy["max_balance_error"] <= 1e-12
    serial = None
    if comm.size > 1 and comm.rank == 0:
        alone = run(dent_scene(), tmp_path_factory.mktemp("serial"), comm=MPI.COMM_SELF)
        serial = alone.history.energy
    if comm.size > 1:
        table = comm.bcast(serial, root=0)
        mine = sim.history.energy
        assert mine.shape == table.shape
        assert np.abs(mine[:, 1:] - table[:, 1:]).max() <= 1e-10 * np.abs(table[:, 1:]).max()


def test_a_resumed_dent_equals_the_uninterrupted_run(shared_dir, monkeypatch):
    import rwall_fem.output.history

    raw = dent_scene()
    raw["output"] |= {"checkpoint_steps": 7}
    whole = build_simulation(parse_scene(copy.deepcopy(raw), source="test"), comm,
                             shared_dir / "whole")  # fmt: skip
    assert whole.run() == "done"
    out = shared_dir / "stopped"
    sim = build_simulation(parse_scene(copy.deepcopy(raw), source="test"), comm, out)
    sim.recorders.append(StopAt(60))
    monkeypatch.setattr(rwall_fem.output.history, "POLL_SECONDS", 1e9)
    assert sim.run().startswith("stopped: step ")
    comm.Barrier()
    sim = build_simulation(parse_scene(copy.deepcopy(raw), source="test"), comm, out)
    sim.checkpoints.resume(sim)
    assert sim.run() == "done"
    comm.Barrier()
    assert np.array_equal(sim.state.u, whole.state.u)
    assert np.array_equal(sim.state.v, whole.state.v)
    assert np.array_equal(sim.internal.elements[0].kernel.history,
                          whole.internal.elements[0].kernel.history)  # fmt: skip
    if comm.rank == 0:
        assert (out / "energy.csv").read_text() == (shared_dir / "whole" / "energy.csv").read_text()
