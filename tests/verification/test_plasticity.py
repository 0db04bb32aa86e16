"""Elasto-plastic impact: the kernels' J2 plasticity in elements, against independent references.

- Kinematics: under a homogeneous deformation every technology's stress equals the
  material-point update driven by the exact increment gradient dF F_mid^-1 (to 1e-12),
  and a large rigid rotation superposed on compression to 50 % leaves the stress
  invariants as they were (objectivity of the Hughes-Winget rotation): the Mises stress
  and the plastic strain to 1e-5 (6.5e-7 and 4e-6 seen over 400 increments of 5 mrad),
  the pressure to 1e-5 of the bulk modulus (the mid-point increment's volume error:
  1.7e-6 seen).
- Uniaxial strain (a laterally confined column onto a rigid wall): 1-D plastic wave
  theory gives the elastic precursor (speed c_L, Hugoniot elastic limit
  sigma_HEL = sigma_y (1 - nu)/(1 - 2 nu), particle velocity u_HEL = sigma_HEL/(rho c_L))
  and the plastic wave (speed c_p = sqrt((K + 4/3 G_t)/rho), G_t = G H/(3 G + H)); the
  wall stress behind both is sigma_HEL + rho c_p (v0 - u_HEL).
- The Taylor anvil test (copper rod, 32.4 mm x 3.2 mm radius, 227 m/s; E 117 GPa,
  nu 0.35, rho 8930, yield 400 MPa, linear hardening 100 MPa, 80 us): published final
  length 21.42-21.66 mm and mushroom (footprint) radius 7.0-7.22 mm (Simo 1992: 7.12 mm;
  Zienkiewicz et al. 1998: 7.11 mm; Foulk et al. 2021, converged: 7.22 mm; final
  lengths 21.42-21.43 mm converged, 21.47-21.66 mm on coarse meshes).
"""

import math

import numpy as np
import pytest
from mpi4py import MPI

from rwall_fem import _compat, build_simulation, parse_scene
from rwall_fem.elements import ElementForce, GhostedField, Technology
from rwall_fem.kernels import load
from rwall_fem.solver import State

COPPER = {
    "model": "elastic_plastic", "density": 8930.0, "young": 117e9, "poisson": 0.35,
    "hardening": "linear", "yield_stress": 400e6, "hardening_modulus": 100e6,
}  # fmt: skip


def copper():
    raw = {
        "run": {"end_time": 1e-5},
        "mesh": {"shape": "bar", "size": [0.01] * 3, "element_size": 0.01},
        "material": COPPER,
    }
    return parse_scene(raw, source="test").material


def mises(s) -> float:
    """Von Mises stress (Pa) of stress slots (xx, yy, zz, xy, yz, xz)."""
    pressure = np.mean(s[:3])
    return math.sqrt(1.5 * (np.sum((s[:3] - pressure) ** 2) + 2 * np.sum(s[3:] ** 2)))


def homogeneous(technology, rotate: bool, steps: int = 400):
    """Drive one element force through x = F(t) X, F = R(t) U(t): compression to 50 % with
    lateral expansion, and (``rotate``) a rotation of 2 rad about z and 1 rad about x.
    Returns the stress slots and plastic strain of the first cell, and those of the
    material-point update driven by dF F_mid^-1."""
    from dolfinx import mesh

    kind = getattr(mesh.CellType, technology.cell)
    msh = mesh.create_unit_cube(MPI.COMM_WORLD, 2, 2, 2, kind)
    V = _compat.vector_space(msh)
    n = V.dofmap.index_map.size_local
    X = V.tabulate_dof_coordinates()[:n].copy()
    u, v = GhostedField(V), GhostedField(V)
    force = ElementForce(V, copper(), technology, u, v)
    state = State(X=X, mass=np.ones(n), dt=1e-6, u=u.owned, v=v.owned)

    def F(t):
        s = 1.0 - 0.5 * t
        stretch = np.diag([1.02 * s**-0.5, s**-0.5, s])
        if not rotate:
            return stretch
        a, b = 2.0 * t, 1.0 * t
        Rz = np.array([[math.cos(a), -math.sin(a), 0], [math.sin(a), math.cos(a), 0], [0, 0, 1]])
        Rx = np.array([[1, 0, 0], [0, math.cos(b), -math.sin(b)], [0, math.sin(b), math.cos(b)]])
        return Rz @ Rx @ stretch

    ffi, lib = load()
    sigma, eps_p, T = ffi.new("double[6]"), ffi.new("double *"), ffi.new("double *")
    times = np.linspace(0.0, 1.0, steps + 1)
    for k, t in enumerate(times):
        now = F(t)
        u.owned[:] = X @ (now - np.eye(3)).T
        v.owned[:] = 0.0
        if k:
            before = F(times[k - 1])
            v.owned[:] = X @ ((now - before) / state.dt).T
            dL = (now - before) @ np.linalg.inv(0.5 * (now + before))
            lib.plastic_point(force.params, sigma, eps_p, T, ffi.new("double[9]", list(dL.flat)))
        state.dt_previous = state.dt if k else 0.0  # the step that brought u here
        force.accelerate(state)
    return force.history[:6, 0], force.history[6, 0], np.array(list(sigma)), eps_p[0]


TECHNOLOGIES = [
    Technology.choose("tetrahedron"),
    Technology.choose("hexahedron", "full"),
    Technology.choose("hexahedron", "reduced", "physical", plastic=True),
]


@pytest.mark.parametrize("technology", TECHNOLOGIES, ids=lambda t: t.describe())
def test_homogeneous_large_strain_and_rotation(technology):
    plain = homogeneous(technology, rotate=False)
    turned = homogeneous(technology, rotate=True)
    for stress, eps_p, point_stress, point_eps_p in (plain, turned):
        assert np.abs(stress - point_stress).max() < 1e-12 * mises(point_stress)
        assert abs(eps_p - point_eps_p) < 1e-12 * point_eps_p
    assert plain[1] > 0.68  # compression to 50 %: eps_p = ln 2 less the elastic part
    assert abs(mises(turned[0]) - mises(plain[0])) < 1e-5 * mises(plain[0])
    bulk = COPPER["young"] / (3 * (1 - 2 * COPPER["poisson"]))
    assert abs(np.mean(turned[0][:3]) - np.mean(plain[0][:3])) < 1e-5 * bulk
    assert abs(turned[1] - plain[1]) < 1e-5 * plain[1]


def column(v0=100.0, layers=200, h=0.25e-3, end=1.15):
    """A copper column of ``layers`` cells of side h (m), held laterally (uniaxial strain),
    onto a fixed plane at v0 (m/s), run to ``end`` times the precursor's transit L/c_L."""
    E, nu, rho = COPPER["young"], COPPER["poisson"], COPPER["density"]
    c_L = math.sqrt(E * (1 - nu) / ((1 + nu) * (1 - 2 * nu) * rho))
    length = layers * h
    raw = {
        "run": {"end_time": end * length / c_L},
        "mesh": {"shape": "bar", "size": [h, h, length], "element_size": h},
        "material": COPPER,
        "initial": {"velocity": [0.0, 0.0, -v0]},
        "boundary": [{"group": "sides", "components": "xy"}],
        "wall": [{"kind": "plane", "point": [0.0, 0.0, 0.0], "normal_point": [0.0, 0.0, 1.0]}],
        "output": {"plot": False},
    }
    return raw, length, c_L


class TopVelocity:
    """Recorder of the mean z velocity v^{n-1/2} (m/s) of the column's top face."""

    def __init__(self, sim, top: float):
        s = sim.state
        self.comm, self.top = sim.comm, np.flatnonzero(np.isclose(s.X[:, 2], top))
        self.t, self.v = [], []
        sim.recorders.append(self)

    def due(self, s):
        return True

    def record(self, sim, s):
        total = self.comm.allreduce(np.array([s.v[self.top, 2].sum(), len(self.top)]))
        self.t.append(s.t)
        self.v.append(total[0] / total[1])

    def close(self, sim):
        self.t, self.v = np.array(self.t), np.array(self.v)


def test_plastic_wave_in_uniaxial_strain(shared_dir):
    """Wall stress within 1 % of 1-D theory (0.14 % seen); the top face moves at -v0 until
    the precursor arrives (at 0.9 L/c_L, to 1e-6: the front's foot is a few cells wide)
    and then at -v0 + 2 u_HEL (at 1.1 L/c_L, before the plastic front at L/c_p = 1.2 L/c_L;
    to 5 % of 2 u_HEL, 1.9 % seen)."""
    v0 = 100.0
    raw, length, c_L = column(v0)
    E, nu, rho = COPPER["young"], COPPER["poisson"], COPPER["density"]
    sigma_y, H = COPPER["yield_stress"], COPPER["hardening_modulus"]
    G, K = E / (2 * (1 + nu)), E / (3 * (1 - 2 * nu))
    c_p = math.sqrt((K + 4 / 3 * G * H / (3 * G + H)) / rho)
    sigma_hel = sigma_y * (1 - nu) / (1 - 2 * nu)
    u_hel = sigma_hel / (rho * c_L)
    expected = sigma_hel + rho * c_p * (v0 - u_hel)

    sim = build_simulation(parse_scene(raw, source="test"), MPI.COMM_WORLD, shared_dir)
    top = TopVelocity(sim, length)
    assert sim.run() == "done"
    rows = sim.history.wall(0)
    from rwall_fem.output.wall_table import WALL_COLUMNS

    t, force = rows[:, 0], -rows[:, WALL_COLUMNS.index("normal_force_z")]
    plateau = (t > 0.2 * length / c_L) & (t < 0.7 * length / c_L)
    h = raw["mesh"]["element_size"]
    assert force[plateau].mean() / h**2 == pytest.approx(expected, rel=0.01)
    before = np.interp(0.9 * length / c_L, top.t, top.v)
    after = np.interp(1.1 * length / c_L, top.t, top.v)
    assert abs(before + v0) < 1e-6 * v0
    assert after + v0 == pytest.approx(2 * u_hel, rel=0.05)
    assert sim.history.summary["energy"]["max_balance_error"] < 1e-12


def taylor_rod(element_size=0.8e-3, dt_scale=0.9, time_step="adaptive"):
    return {
        "run": {"end_time": 80e-6, "dt_scale": dt_scale, "time_step": time_step},
        "mesh": {
            "shape": "round_bar", "radius": 3.2e-3, "length": 32.4e-3,
            "element_size": element_size,
        },
        "material": COPPER,
        "initial": {"velocity": [0.0, 0.0, -227.0]},
        "wall": [{"kind": "plane", "point": [0.0, 0.0, 0.0], "normal_point": [0.0, 0.0, 1.0]}],
        "output": {"plot": False, "history_interval": 50},
    }  # fmt: skip


def shape(sim) -> tuple[float, float]:
    """The rod's final length and mushroom radius (mm): its extents along and across."""
    (low, high) = sim.history.summary["deformed_bounds"]
    return (high[2] - low[2]) * 1e3, max(high[0], -low[0], high[1], -low[1]) * 1e3


@pytest.fixture(scope="module")
def taylor(tmp_path_factory):
    """The Taylor rod at 0.8 mm (4 cells across the radius), one-point hexahedra, with the
    adaptive step at dt_scale 0.9 (its step falls from 58 to 11 ns)."""
    directory = tmp_path_factory.mktemp("taylor") if MPI.COMM_WORLD.rank == 0 else None
    directory = MPI.COMM_WORLD.bcast(directory, root=0)
    sim = build_simulation(parse_scene(taylor_rod(), source="test"), MPI.COMM_WORLD, directory)
    assert sim.run() == "done"
    return sim


def test_taylor_rod(taylor):
    """The final length within the published 21.42-21.66 mm widened by 1 % (21.52 mm seen),
    the mushroom radius within 7.0-7.22 mm widened by 3 % (6.90 mm seen: the coarse
    footprint), the largest plastic strain in 2.5-3.3 (2.73 seen), the balance closed (the
    internal energy is booked at mid-step: exact for any steps) and no node behind the
    wall."""
    summary = taylor.history.summary
    length, radius = shape(taylor)
    assert 21.42 * 0.99 <= length <= 21.66 * 1.01
    assert 7.0 * 0.97 <= radius <= 7.22 * 1.03
    assert 2.5 <= summary["max_plastic_strain"] <= 3.3
    assert summary["energy"]["max_balance_error"] < 1e-10
    assert summary["deformed_bounds"][0][2] > -1e-9
    # Nearly all the impact energy is dissipated plastically.
    assert summary["plastic_work"] > 0.95 * summary["energy"]["initial"]
    steps = summary["time_step"]
    assert steps["first"] > 4.0 * steps["smallest"]


@pytest.mark.serial
def test_taylor_rod_adaptive_equals_a_small_fixed_step(taylor, tmp_path):
    """The same mesh with the fixed step of the old rule, dt_scale 0.05 of the limit at
    rest (chosen for the most crushed cell; 2.7x the steps): final length, mushroom radius
    and largest plastic strain agree within 0.5 %."""
    raw = taylor_rod(dt_scale=0.05, time_step="fixed")
    fixed = build_simulation(parse_scene(raw, source="test"), MPI.COMM_SELF, tmp_path)
    assert fixed.run() == "done"
    assert fixed.state.step > 2.5 * taylor.state.step
    for a, f in zip(shape(taylor), shape(fixed), strict=True):
        assert a == pytest.approx(f, rel=5e-3)
    strains = (s.history.summary["max_plastic_strain"] for s in (taylor, fixed))
    assert next(strains) == pytest.approx(next(strains), rel=5e-3)
