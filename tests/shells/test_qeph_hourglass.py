"""QEPH's physical hourglass stiffness (element.formulation = "qeph", Radioss's Ishell 24;
shell_quad.c, quad_hourglass_qeph), one quadrilateral driven through the kernel on NumPy
arrays, against the strain energy of each hourglass mode worked by hand.

The hourglass modes of an a x c rectangle (centroid at the origin) are the bilinear
fields x y / (a c / 4) times the nodal pattern h = (1, -1, 1, -1); one in-plane point
sees none of them. Their physical energies, in plane stress and Mindlin plates (the
element keeps the normal strains and curvatures of the mode, as QEPH does):
- membrane, vx = s h_I: eps_xx = 4 s y / (a c), U = E' t int eps_xx^2 / 2 dA, so the
  generalized force on s is K s with K = 4/3 E' t c / a (vy: 4/3 E' t a / c);
- bending, theta_y = s h_I: kappa_xx = 4 s y / (a c), K = 4/3 D c / a, D = E' t^3 / 12;
- transverse shear, vz = s h_I with no rotations: gamma_xz = 4 s y / (a c),
  gamma_yz = 4 s x / (a c), U = k G t int (gamma_xz^2 + gamma_yz^2) / 2 dA, so
  K = 4/3 k G t (c / a + a / c);
the internal nodal forces of a step are h_I / 4 K dt s for the first two (the mode's pattern) and
h_I K dt s / 4 summed as sum_I h_I f_I = K dt s for the shear. A constant twist
(w = alpha x y with the rotations of zero transverse shear) is physical, not an
hourglass mode: no hourglass stress; nor does any rigid motion make one. QEPH's viscous
hourglass forces (its numerical damping dn) are checked against its rule by hand.

On a body: the dented plate of test_hourglass_yield with QEPH's hourglass and its yield
closes its books to round-off (the hourglass energy is the forces' work), 1 and 2 ranks
give the same energies to 1e-10, a resumed run equals the uninterrupted one bit for bit;
the spinning plate of test_shell_runs stores nothing with
it (that file).
"""

import math
from types import SimpleNamespace

import numpy as np
import pytest
from conftest import run
from mpi4py import MPI
from test_hourglass_yield import dent_scene
from test_hourglass_yield import test_a_resumed_dent_equals_the_uninterrupted_run as resumed

from rwall_fem.shells.elements import ShellKernel, ShellTechnology

comm = MPI.COMM_WORLD

E, NU, RHO, T = 210e9, 0.3, 7850.0, 1.5e-3
EP, G, SHEAR = E / (1 - NU**2), E / (2 * (1 + NU)), 5.0 / 6.0
D = EP * T**3 / 12
ELASTIC = SimpleNamespace(model="linear_elastic", plastic=False, young=E, poisson=NU,
                          density=RHO, failure=None, heating=None)  # fmt: skip
A, C = 0.01, 0.004  # the rectangle's sides along x and y, m
RECTANGLE = np.array([[-A / 2, -C / 2, 0.0], [A / 2, -C / 2, 0.0], [A / 2, C / 2, 0.0],
                      [-A / 2, C / 2, 0.0]])  # fmt: skip
H = np.array([1.0, -1.0, 1.0, -1.0])
DT, S = 1e-9, 0.3  # the step (s) and the mode's rate (m/s or rad/s): a tiny motion


def one_step(velocity, spin, dn=0.0):
    """The nodal forces and moments of one step of the given nodal velocities and
    angular velocities (4 x 3) from rest, the hourglass energy, and the kernel; QEPH's
    numerical damping dn (0: the elastic forces alone)."""
    technology = ShellTechnology.choose("quadrilateral", formulation="qeph",
                                        hourglass=(0.0, 0.0, 0.0))  # fmt: skip
    k = ShellKernel(ELASTIC, technology, np.array([[0, 1, 2, 3]], np.int32), T)
    k.shell.qeph_dn = dn
    f, m, energy = np.zeros((4, 3)), np.zeros((4, 3)), np.zeros(4)
    k.run(DT, RECTANGLE, DT * velocity, velocity, spin, f, m, energy=energy)
    return f, m, energy, k


def pattern(column, values):
    out = np.zeros((4, 3))
    out[:, column] = values
    return out


@pytest.mark.parametrize("column, stiffness", [(0, 4 / 3 * EP * T * C / A),
                                               (1, 4 / 3 * EP * T * A / C)],
                         ids=["x", "y"])  # fmt: skip
def test_membrane_modes_take_their_plane_stress_energy(column, stiffness):
    """The internal forces f_I = h_I K dt s / 4 within 1e-6 (the
    cell moves by 1e-10 of its size in the step), and the hourglass energy of the step is
    the work K (dt s)^2 / 2."""
    f, m, energy, _ = one_step(pattern(column, S * H), np.zeros((4, 3)))
    expected = H / 4 * stiffness * DT * S
    assert f[:, column] == pytest.approx(expected, rel=1e-6)
    assert np.abs(np.delete(f, column, axis=1)).max() <= 1e-6 * np.abs(expected).max()
    assert energy[1] == pytest.approx(0.5 * stiffness * (DT * S) ** 2, rel=1e-6)


@pytest.mark.parametrize("column, stiffness", [(1, 4 / 3 * D * C / A),
                                               (0, 4 / 3 * D * A / C)],
                         ids=["theta_y", "theta_x"])  # fmt: skip
def test_bending_modes_take_their_plate_energy(column, stiffness):
    """theta_y = s h_I bends along x (kappa_xx), theta_x = s h_I along y: m_I = h_I K dt s
    / 4 within 1e-6, and no force."""
    f, m, energy, _ = one_step(np.zeros((4, 3)), pattern(column, S * H))
    expected = H / 4 * stiffness * DT * S
    assert m[:, column] == pytest.approx(expected, rel=1e-6)
    assert np.abs(f).max() <= 1e-6 * np.abs(expected).max() / C
    assert energy[1] == pytest.approx(0.5 * stiffness * (DT * S) ** 2, rel=1e-6)


def test_the_transverse_shear_mode_takes_its_mindlin_energy():
    """vz = s h_I with no rotation: sum_I h_I fz_I = K dt s with
    K = 4/3 k G t (c / a + a / c), within 1e-6; the fz_I follow h_I."""
    f, m, energy, _ = one_step(pattern(2, S * H), np.zeros((4, 3)))
    stiffness = 4 / 3 * SHEAR * G * T * (C / A + A / C)
    assert H @ f[:, 2] == pytest.approx(stiffness * DT * S, rel=1e-6)
    assert f[:, 2] == pytest.approx(H * stiffness * DT * S / 4, rel=1e-6)
    assert energy[1] == pytest.approx(0.5 * stiffness * (DT * S) ** 2, rel=1e-6)


def test_the_viscous_forces_follow_qeph_damping():
    """QEPH's viscous hourglass forces (CZFINTN1, dn = 0.015) worked by hand on the
    rectangle's membrane x mode (MY34 = c / 2, MY23 = MX34 = 0):
    F = t dn sqrt(rho A) / A sqrt(E') 16/3 (c / 2)^2 s on top of the elastic K dt s,
    within 1e-6; the step's hourglass energy grows by F_viscous dt s."""
    dn = 0.015
    f0, _, e0, _ = one_step(pattern(0, S * H), np.zeros((4, 3)))
    f, _, e, _ = one_step(pattern(0, S * H), np.zeros((4, 3)), dn=dn)
    area = A * C
    viscous = T * dn * math.sqrt(RHO * area) / area * math.sqrt(EP) * 16 / 3 * (C / 2) ** 2 * S
    assert f[:, 0] - f0[:, 0] == pytest.approx(H / 4 * viscous, rel=1e-6)
    assert e[1] - e0[1] == pytest.approx(viscous * DT * S, rel=1e-6)


def test_a_constant_twist_and_rigid_motions_make_no_hourglass_stress():
    """w = alpha x y with theta_x = alpha x, theta_y = -alpha y (zero transverse shear,
    constant twist: Mindlin's own field), a rigid rotation about x and one about z: the
    twelve hourglass stresses stay below 1e-9 of those of the shear mode of the same
    rate."""
    _, _, _, ref = one_step(pattern(2, S * H), np.zeros((4, 3)))
    slot = ref.shell.hourglass_slot
    scale = np.abs(ref.history[slot:slot + 12, 0]).max()
    x, y = RECTANGLE[:, 0], RECTANGLE[:, 1]
    alpha = 4 * S / (A * C)
    motions = {
        "twist": (pattern(2, alpha * x * y),
                  np.column_stack([alpha * x, -alpha * y, 0 * x])),
        "rotation x": (pattern(2, S / C * y), pattern(0, np.full(4, S / C))),
        "rotation z": (np.column_stack([-S / C * y, S / C * x, 0 * x]),
                       pattern(2, np.full(4, S / C))),
    }  # fmt: skip
    for name, (velocity, spin) in motions.items():
        _, _, _, k = one_step(velocity, spin)
        stresses = np.abs(k.history[slot:slot + 12, 0]).max()
        assert stresses <= 1e-9 * scale, name


def test_a_dented_plate_with_qeph_closes_its_books_on_any_ranks(shared_dir, tmp_path_factory):
    """The dent with formulation "qeph" and its yield: hourglass energy booked (> 0), the
    balance within 1e-12 of the impact energy, 2 ranks equal 1 to 1e-10."""
    raw = dent_scene()
    raw["element"] = {"formulation": "qeph", "hourglass_yield": True}
    sim = run(raw, shared_dir)
    energy = sim.history.summary["energy"]
    print(f"qeph dent: hourglass {energy['hourglass']:.4e} J, plastic "
          f"{sim.history.summary['plastic_work']:.4e} J, balance "
          f"{energy['max_balance_error']:.2e}")
    assert sim.history.summary["plastic_work"] > 0.0
    assert energy["hourglass"] > 0.0
    assert energy["max_balance_error"] <= 1e-12
    serial = None
    if comm.size > 1 and comm.rank == 0:
        alone = run(raw, tmp_path_factory.mktemp("serial"), comm=MPI.COMM_SELF)
        serial = alone.history.energy
    if comm.size > 1:
        table = comm.bcast(serial, root=0)
        mine = sim.history.energy
        assert mine.shape == table.shape
        assert np.abs(mine[:, 1:] - table[:, 1:]).max() <= 1e-10 * np.abs(table[:, 1:]).max()
    assert math.isfinite(energy["hourglass"])


def test_a_resumed_qeph_dent_equals_the_uninterrupted_run(shared_dir, monkeypatch):
    """The dent's resume test with QEPH's twelve hourglass stresses in the state: the
    resumed run equals the uninterrupted one bit for bit."""
    import test_hourglass_yield

    def qeph_scene():
        raw = dent_scene()
        raw["element"] = {"formulation": "qeph", "hourglass_yield": True}
        return raw

    monkeypatch.setattr(test_hourglass_yield, "dent_scene", qeph_scene)
    resumed(shared_dir, monkeypatch)


def test_a_warped_cell_in_rigid_rotation_makes_no_hourglass_stress():
    """A warped cell (nodes 0.4 mm off its plane, alternately up and down) spinning about
    an arbitrary axis: the twelve hourglass stresses stay below 1e-9 of the shear mode's
    (the rates are those of the BWC-projected velocities)."""
    _, _, _, ref = one_step(pattern(2, S * H), np.zeros((4, 3)))
    slot = ref.shell.hourglass_slot
    scale = np.abs(ref.history[slot:slot + 12, 0]).max()
    technology = ShellTechnology.choose("quadrilateral", formulation="qeph",
                                        hourglass=(0.0, 0.0, 0.0))  # fmt: skip
    k = ShellKernel(ELASTIC, technology, np.array([[0, 1, 2, 3]], np.int32), T)
    warped = RECTANGLE + np.outer(H, [0.0, 0.0, 4e-4])
    omega = S / C * np.array([0.3, -0.7, 0.5])
    velocity = np.cross(omega, warped - warped.mean(axis=0))
    spin = np.tile(omega, (4, 1))
    f, m, energy = np.zeros((4, 3)), np.zeros((4, 3)), np.zeros(4)
    # u = dt v / 2: the mid-step configuration x - dt v / 2, where the kernel takes its
    # rates, is the warped one, in which the motion is rigid
    k.run(DT, warped, 0.5 * DT * velocity, velocity, spin, f, m, energy=energy)
    assert np.abs(k.history[slot:slot + 12, 0]).max() <= 1e-9 * scale


def test_qeph_refuses_the_bwc_hourglass_stiffness_and_triangles():
    """formulation "qeph" has its own hourglass stiffness: hourglass_stiffness beside it is
    refused in one line naming the key; on triangles the formulation is refused."""
    with pytest.raises(ValueError, match=r"^element\.hourglass_stiffness: not with"):
        ShellTechnology.choose("quadrilateral", formulation="qeph", hourglass_stiffness=0.5)
    with pytest.raises(ValueError, match=r"^element\.formulation: 'qeph' is not for triangle"):
        ShellTechnology.choose("triangle", formulation="qeph")


@pytest.mark.parametrize("hardening", ["linear", "power"])
def test_the_plain_qeph_kernel_equals_the_general_one(hardening):
    """QEPH's cells without options run through shell_quad compiled apart with those settings
    as constants (shell_quad.c, qeph_plain); the same cells with a flow-stress cap that is
    never reached (1e30 Pa) run through the general kernel. Over 100 steps of a random
    motion that makes some points flow and leaves others elastic, the forces, moments,
    energies, step notes and state are the same to round-off: within 1e-13 of each
    quantity's largest magnitude (measured: 2.3e-16; the plain kernel's full batches load
    and store as runs of consecutive cells, and GCC contracts some of their products into
    other fused multiply-adds)."""
    n = 6
    grid = np.arange(n + 1) * 2.5e-3
    X = np.array([[x, y, 0.0] for y in grid for x in grid])
    cells = np.array([[j * (n + 1) + i, j * (n + 1) + i + 1, (j + 1) * (n + 1) + i + 1,
                       (j + 1) * (n + 1) + i] for j in range(n) for i in range(n)], np.int32)
    material = SimpleNamespace(model="elastic_plastic", plastic=True, young=E, poisson=NU,
                               density=RHO, hardening=hardening, yield_stress=300e6,
                               hardening_modulus=1e9, hardening_coefficient=500e6,
                               hardening_exponent=0.3, strain_rate_coefficient=0.0,
                               reference_strain_rate=1.0, failure=None, heating=None)
    technology = ShellTechnology.choose("quadrilateral", formulation="qeph",
                                        hourglass=(0.0, 0.0, 0.0), step_length="qeph",
                                        hourglass_yield=True)  # fmt: skip
    rng = np.random.default_rng(3)
    v, w = rng.normal(size=X.shape) * 0.3, rng.normal(size=X.shape) * 30
    results = []
    for cap in (math.inf, 1e30):
        k = ShellKernel(material, technology, cells, T, max_flow_stress=cap)
        u = np.zeros_like(X)
        out = []
        for _ in range(100):
            f, m = np.zeros_like(X), np.zeros_like(X)
            energy, step = k.run(1e-7, X, u, v, w, f, m)
            out.append(np.concatenate([f.ravel(), m.ravel(), energy, step]))
            u += 1e-7 * v
        results.append((np.array(out), k.history.copy(), k.plastic_strains()))
    (plain, plain_state, eps), (general, general_state, _) = results
    assert 0.1 < np.mean(eps > 0) < 0.9  # some points flowed, others did not
    assert np.all(np.abs(plain - general) <= 1e-13 * np.abs(general).max(axis=0))
    assert np.all(np.abs(plain_state - general_state)
                  <= 1e-13 * np.abs(general_state).max(axis=1, keepdims=True))
