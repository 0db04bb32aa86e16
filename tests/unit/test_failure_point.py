"""The damage of the failure criteria, point by point, against the formula written out here.

Every element technology is driven through the same homogeneous deformation (stretching
with a shear, then compression, at 2e4 /s), so that each integration point sees the
increments the material-point update sees (tests/verification/test_plasticity.py shows
the stresses agree to 1e-12). The damage the kernels accumulate is compared with
D = sum d / eps_f evaluated here from each step's plastic increment d, stress, strain rate
and temperature, eps_f = [D1 + D2 exp(D3 sigma*)] [1 + D4 ln max(rate / rate_0, 1)]
[1 + D5 T*]: to 1e-12, with every term in play (Weldox 460 E's constants, a D5 of 0.5 and
adiabatic heating), and for the constant criterion D = eps_p / eps_f.
"""

import math

import numpy as np
import pytest
from mpi4py import MPI

from rwall_fem import _compat, parse_scene
from rwall_fem.elements import ElementForce, GhostedField, Technology
from rwall_fem.kernels import load
from rwall_fem.solver import State

WELDOX = {
    "model": "johnson_cook", "density": 7850.0, "young": 200e9, "poisson": 0.33,
    "yield_stress": 490e6, "hardening_coefficient": 807e6, "hardening_exponent": 0.73,
    "strain_rate_coefficient": 0.0114, "reference_strain_rate": 5e-4,
    "heating": {"softening_exponent": 0.94, "melting_temperature": 1800.0,
                "specific_heat": 452.0},
}  # fmt: skip
CRITERIA = {
    "johnson_cook": {"criterion": "johnson_cook", "d1": 0.0705, "d2": 1.732, "d3": -0.54,
                     "d4": -0.015, "d5": 0.5},
    "plastic_strain": {"criterion": "plastic_strain", "plastic_strain": 0.8},
}  # fmt: skip
TECHNOLOGIES = [
    Technology.choose("tetrahedron"),
    Technology.choose("hexahedron", "full"),
    Technology.choose("hexahedron", "reduced", "physical", plastic=True),
]


def material(criterion):
    raw = {
        "run": {"end_time": 1e-5},
        "mesh": {"shape": "bar", "size": [0.01] * 3, "element_size": 0.01},
        "material": WELDOX | {"failure": CRITERIA[criterion]},
    }
    return parse_scene(raw, source="test").material


def F(t: float) -> np.ndarray:
    """Stretching along z with a shear, then compression back past the start."""
    s = 1.0 + 0.3 * math.sin(math.pi * t) - 0.15 * t
    return np.diag([s**-0.5, s**-0.5, s]) + np.array([[0, 0, 0.1 * t], [0, 0, 0], [0, 0, 0]])


def driven(technology, criterion, steps=300, dt=1e-6):
    """The kernels' damage of the first cell (its points) after ``steps`` steps of F, and
    the damage of the formula from the material-point update of the same increments."""
    from dolfinx import mesh

    m = material(criterion)
    msh = mesh.create_unit_cube(MPI.COMM_WORLD, 2, 2, 2, getattr(mesh.CellType, technology.cell))
    V = _compat.vector_space(msh)
    n = V.dofmap.index_map.size_local
    X = V.tabulate_dof_coordinates()[:n].copy()
    u, v = GhostedField(V), GhostedField(V)
    force = ElementForce(V, m, technology, u, v)
    state = State(X=X, mass=np.ones(n), dt=dt, u=u.owned, v=v.owned)
    ffi, lib = load()
    sigma, eps_p, T = ffi.new("double[6]"), ffi.new("double *"), ffi.new("double *")
    T[0] = m.heating.room_temperature
    damage, f = 0.0, m.failure
    times = np.linspace(0.0, 1.0, steps + 1)
    for k, t in enumerate(times):
        now = F(t)
        u.owned[:] = X @ (now - np.eye(3)).T
        v.owned[:] = 0.0
        if k:
            before = F(times[k - 1])
            v.owned[:] = X @ ((now - before) / dt).T
            dL = (now - before) @ np.linalg.inv(0.5 * (now + before))
            old = eps_p[0]
            force.params.dt = dt  # the rate of the step, as the kernels will take it
            lib.plastic_point(force.params, sigma, eps_p, T, ffi.new("double[9]", list(dL.flat)))
            d = eps_p[0] - old
            if d > 0.0:
                damage += d / failure_strain(f, m, np.array(list(sigma)), dL, dt, T[0])
        state.dt_previous = dt if k else 0.0
        force.accelerate(state)
    return force.damage[:, 0], damage, eps_p[0]


def failure_strain(f, m, s, dL, dt, T) -> float:
    """eps_f of the criterion ``f`` at the stress slots ``s`` (Pa) after a step of increment
    gradient dL over dt (s), at temperature T (K)."""
    if f.criterion == "plastic_strain":
        return f.plastic_strain
    pressure = s[:3].mean()
    mises = math.sqrt(1.5 * (np.sum((s[:3] - pressure) ** 2) + 2 * np.sum(s[3:] ** 2)))
    de = 0.5 * (dL + dL.T)
    deviator = de - np.trace(de) / 3 * np.eye(3)
    rate = math.sqrt(2.0 / 3.0 * np.sum(deviator**2)) / dt
    h = m.heating
    star = min(max((T - h.room_temperature) / (h.melting_temperature - h.room_temperature), 0), 1)
    return (
        (f.d1 + f.d2 * math.exp(f.d3 * pressure / mises))
        * (1 + f.d4 * math.log(max(rate / f.reference_strain_rate, 1.0)))
        * (1 + f.d5 * star)
    )


@pytest.mark.parametrize("criterion", CRITERIA)
@pytest.mark.parametrize("technology", TECHNOLOGIES, ids=lambda t: t.describe())
def test_damage_is_the_formula(technology, criterion):
    damage, expected, eps_p = driven(technology, criterion)
    assert 0.3 < expected < 1.0  # far into the criterion, before the cell fails
    assert np.abs(damage - expected).max() <= 1e-12 * expected
    if criterion == "plastic_strain":
        assert expected == pytest.approx(eps_p / CRITERIA[criterion]["plastic_strain"], rel=1e-13)
