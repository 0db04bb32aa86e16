"""J2 plasticity at one material point (the kernels' radial return) against closed forms.

Linear isotropic hardening sigma_y = A + H eps_p, small increments applied in
proportional (radial) paths, for which the radial return is exact: the closed
forms of uniaxial stress, uniaxial strain and shear hold to 1e-10 (relative),
the consistency condition q = sigma_y(eps_p) holds after every plastic step,
and unloading follows the elastic slope. The hardening laws (power, table,
Johnson-Cook) are checked on their own closed forms at a point.
"""

import math

import numpy as np
import pytest

from rwall_fem.kernels import load

E, NU = 200e9, 0.3
MU, LMBDA = E / (2 * (1 + NU)), E * NU / ((1 + NU) * (1 - 2 * NU))
BULK = LMBDA + 2 * MU / 3
A, H = 250e6, 1e9  # Pa
TOL = 1e-10


class Point:
    """A material point driven by increments of the displacement gradient."""

    def __init__(self, **law):
        self.ffi, self.lib = load()
        self.p = self.ffi.new("element_params *")
        self.p.lmbda, self.p.mu, self.p.dt = LMBDA, MU, 1e-6
        self.p.density, self.p.yield_stress, self.p.hardening_modulus = 7850.0, A, H
        for key, value in law.items():
            if key == "table":
                self.p.table_size = len(value)
                for i, (e, s) in enumerate(value):
                    self.p.table_strain[i], self.p.table_stress[i] = e, s
            else:
                setattr(self.p, key, value)
        self.sigma = self.ffi.new("double[6]")
        self.eps_p = self.ffi.new("double *")
        self.T = self.ffi.new("double *", 293.0)

    def step(self, dL) -> float:
        """Apply one increment (3 x 3); returns the dissipation density (J/m^3)."""
        return self.lib.plastic_point(
            self.p, self.sigma, self.eps_p, self.T, self.ffi.new("double[9]", list(np.ravel(dL)))
        )

    @property
    def stress(self) -> np.ndarray:
        xx, yy, zz, xy, yz, xz = self.sigma
        return np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])

    @property
    def mises(self) -> float:
        s = self.stress - np.trace(self.stress) / 3 * np.eye(3)
        return math.sqrt(1.5 * np.sum(s * s))


def test_uniaxial_strain():
    """eps_x only: sigma_x - sigma_y = A + H eps_p with eps_p = (2 mu eps - A)/(3 mu + H)
    past eps_Y = A / (2 mu); pressure K eps; dissipation sum = int sigma_y d eps_p."""
    point, steps, total = Point(), 400, 8e-3
    dissipated = 0.0
    for _ in range(steps):
        dissipated += point.step(np.diag([total / steps, 0.0, 0.0]))
        if point.eps_p[0] > 0.0:
            assert abs(point.mises - (A + H * point.eps_p[0])) < TOL * A
    eps_p = (2 * MU * total - A) / (3 * MU + H)
    sigma = point.stress
    assert abs(point.eps_p[0] - eps_p) < TOL * eps_p
    assert abs(sigma[0, 0] - sigma[1, 1] - (A + H * eps_p)) < TOL * A
    assert abs(np.trace(sigma) / 3 - BULK * total) < TOL * BULK * total
    assert abs(sigma[1, 1] - sigma[2, 2]) < TOL * A
    # Backward Euler books sigma_y at the end of each step: within one step's hardening.
    assert abs(dissipated - (A * eps_p + 0.5 * H * eps_p**2)) < H * eps_p * eps_p / steps


def test_uniaxial_stress():
    """Strain increments of uniaxial stress (lateral ones from the closed form): the
    lateral stresses stay zero and sigma_x follows A + E_t (eps - eps_Y), E_t = E H/(E + H)."""
    point, steps, total = Point(), 400, 1e-2
    eps_y = A / E
    sigma_prev = eps_p_prev = 0.0
    for k in range(1, steps + 1):
        eps = total * k / steps
        sigma = E * eps if eps <= eps_y else A + E * H / (E + H) * (eps - eps_y)
        eps_p = max(0.0, (sigma - A) / H)
        lateral = -NU * (sigma - sigma_prev) / E - 0.5 * (eps_p - eps_p_prev)
        point.step(np.diag([total / steps, lateral, lateral]))
        sigma_prev, eps_p_prev = sigma, eps_p
    assert abs(point.stress[0, 0] - sigma) < TOL * sigma
    assert np.abs(point.stress[1:, 1:]).max() < TOL * sigma
    assert abs(point.eps_p[0] - eps_p) < TOL * eps_p


def test_shear_and_elastic_unloading():
    """Pure shear eps_xy = gamma / 2 (no spin): tau = mu gamma up to A / sqrt 3, then
    sqrt(3) tau = A + H eps_p with eps_p = (sqrt(3) mu gamma - A)/(3 mu + H); unloading by
    d gamma changes tau by mu d gamma, eps_p unchanged."""
    point, steps, gamma = Point(), 300, 6e-3
    for _ in range(steps):
        d = gamma / steps / 2
        point.step([[0.0, d, 0.0], [d, 0.0, 0.0], [0.0, 0.0, 0.0]])
    eps_p = (math.sqrt(3) * MU * gamma - A) / (3 * MU + H)
    tau = (A + H * eps_p) / math.sqrt(3)
    assert abs(point.eps_p[0] - eps_p) < TOL * eps_p
    assert abs(point.stress[0, 1] - tau) < TOL * tau
    back = 1e-3
    point.step([[0.0, -back / 2, 0.0], [-back / 2, 0.0, 0.0], [0.0, 0.0, 0.0]])
    assert abs(point.stress[0, 1] - (tau - MU * back)) < TOL * tau
    assert point.eps_p[0] == pytest.approx(eps_p, rel=TOL)


@pytest.mark.parametrize(
    ("law", "flow"),
    [
        (
            {"hardening": 1, "hardening_coefficient": 300e6, "hardening_exponent": 0.4},
            lambda e: A + 300e6 * e**0.4,
        ),
        (
            {"hardening": 2, "table": [(0.0, A), (0.01, 300e6), (0.05, 340e6)]},
            lambda e: np.interp(e, [0.0, 0.01, 0.05], [A, 300e6, 340e6]),
        ),
    ],
    ids=["power", "table"],
)
def test_consistency_of_nonlinear_hardening(law, flow):
    """After every plastic step the Mises stress equals the flow stress at the new
    plastic strain (Newton's iteration converged), in uniaxial strain to 5 %."""
    point = Point(**law)
    for _ in range(500):
        point.step(np.diag([1e-4, 0.0, 0.0]))
        if point.eps_p[0] > 0.0:
            assert abs(point.mises - flow(point.eps_p[0])) < TOL * A
    assert point.eps_p[0] > 0.02


def test_johnson_cook_rate_and_heating():
    """Johnson-Cook with C = 0.025 at a strain rate 1e4 times the reference: the flow stress
    is (A + B eps^n)(1 + C ln 1e4)(1 - T*^m); adiabatic heating raises T by
    beta sigma_y d eps_p / (rho c) per step."""
    law = {
        "hardening": 3, "hardening_coefficient": 292e6, "hardening_exponent": 0.31,
        "rate_coefficient": 0.025, "reference_rate": 1.0, "thermal": 1,
        "thermal_exponent": 1.09, "melting_temperature": 1356.0, "room_temperature": 293.0,
        "specific_heat": 383.0, "taylor_quinney": 0.9,
    }  # fmt: skip
    point = Point(**law)
    point.p.yield_stress = 90e6
    rate = 1e4  # equivalent deviatoric strain rate of uniaxial strain: (2/3) eps_x_dot
    increment = 1.5 * rate * point.p.dt
    for _ in range(200):
        T_before = point.T[0]
        dissipation = point.step(np.diag([increment, 0.0, 0.0]))
        if dissipation > 0.0:
            star = (T_before - 293.0) / (1356.0 - 293.0)
            flow = (90e6 + 292e6 * point.eps_p[0] ** 0.31) * (1 + 0.025 * math.log(rate))
            assert abs(point.mises - flow * (1 - star**1.09)) < TOL * 90e6
            assert point.T[0] - T_before == pytest.approx(0.9 * dissipation / (7850 * 383), rel=TOL)
    assert point.T[0] > 300.0
