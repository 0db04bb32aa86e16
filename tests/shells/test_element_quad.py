"""The Belytschko-Lin-Tsay quadrilateral kernel on NumPy arrays (no solver, no mesh).

References independent of the code: rigid motions (exact discrete rotations, whose mid-step
velocity is exactly rigid by the Cayley transform) strain nothing; the nodal forces of any
stress are in equilibrium (zero resultant force and moment); a linear displacement gives
the same membrane stress C eps in every cell of an irregular patch and no force on its
interior node; a cantilever under an end moment bends to the curvature M / (E I).
"""

import math
from types import SimpleNamespace

import numpy as np
import pytest

from rwall_fem.shells.elements import ShellKernel, ShellTechnology

E, NU, RHO, T = 210e9, 0.3, 7850.0, 0.01
ELASTIC = SimpleNamespace(model="linear_elastic", plastic=False, young=E, poisson=NU, density=RHO)
J2 = SimpleNamespace(model="elastic_plastic", plastic=True, young=E, poisson=NU, density=RHO,
                     hardening="power", yield_stress=300e6, hardening_coefficient=500e6,
                     hardening_exponent=0.3, strain_rate_coefficient=0.0,
                     reference_strain_rate=1.0, failure=None, heating=None)  # fmt: skip
WARPED = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.12], [1.1, 0.9, 0.0], [0.0, 1.2, 0.12]])


def rotation(axis, angle):
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    K = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + math.sin(angle) * K + (1 - math.cos(angle)) * K @ K


def patch(n=3, warp=0.1, seed=1):
    """An n x n patch of irregular, warped quadrilaterals on [0, 1]^2 (counter-clockwise)."""
    rng = np.random.default_rng(seed)
    s = np.linspace(0.0, 1.0, n + 1)
    X = np.array([[x, y, 0.0] for y in s for x in s])
    inner = (X[:, 0] > 0) & (X[:, 0] < 1) & (X[:, 1] > 0) & (X[:, 1] < 1)
    X[inner, :2] += rng.uniform(-0.2, 0.2, (inner.sum(), 2)) / n
    X[:, 2] = warp * rng.uniform(-1, 1, len(X)) / n
    row = n + 1
    cells = [[j * row + i, j * row + i + 1, (j + 1) * row + i + 1, (j + 1) * row + i]
             for j in range(n) for i in range(n)]  # fmt: skip
    return X, np.array(cells, dtype=np.int32)


def rigid_run(kernel, X, steps=60, angle=3.0, dt=1e-4):
    """Move the nodes rigidly through ``angle`` rad about a skew axis while translating,
    in ``steps`` steps; returns the largest |f|, |m| and the energies of all steps."""
    axis, speed = [1.0, 2.0, 3.0], np.array([30.0, -20.0, 50.0])
    centre = X.mean(axis=0)
    previous = X.copy()
    worst, energy = 0.0, np.zeros(4)
    for n in range(1, steps + 1):
        R = rotation(axis, angle * n / steps)
        x = (X - centre) @ R.T + centre + speed * n * dt
        v = (x - previous) / dt
        Rp = rotation(axis, angle * (n - 1) / steps)
        W = 2.0 / dt * (R - Rp) @ np.linalg.inv(R + Rp)  # skew: the Cayley transform
        w = np.tile([W[2, 1], W[0, 2], W[1, 0]], (len(X), 1))
        f, m = np.zeros_like(X), np.zeros_like(X)
        e, _ = kernel.run(dt, X, x - X, v, w, f, m, energy=energy)
        worst = max(worst, np.abs(f).max(), np.abs(m).max())
        previous = x
    return worst, energy


@pytest.mark.parametrize("stiffness", [(0.0, 0.0), (0.1, 0.0), (0.1, 0.01)],
                         ids=["viscous", "elastic-hourglass", "drilling"])  # fmt: skip
@pytest.mark.parametrize("material", [ELASTIC, J2], ids=["elastic", "j2"])
@pytest.mark.parametrize("n", [1, 3])
def test_rigid_motion_strains_nothing(material, n, stiffness):
    """A cell (n = 1, warped) and an irregular warped patch translated and turned through
    3 rad: no force, no moment, no energy (relative to those of a strain of 1e-3); with
    the elastic hourglass forces and the drilling springs too."""
    X, cells = (WARPED, np.array([[0, 1, 2, 3]], np.int32)) if n == 1 else patch(n)
    technology = ShellTechnology.choose("quadrilateral", hourglass_stiffness=stiffness[0],
                                        drilling_stiffness=stiffness[1])  # fmt: skip
    kernel = ShellKernel(material, technology, cells, T)
    worst, energy = rigid_run(kernel, X)
    force_scale = E * T * 1e-3 * 1.0  # N: a membrane strain of 1e-3 over a 1 m edge
    energy_scale = 0.5 * E * 1e-6 * T * 1.0
    assert worst <= 1e-12 * force_scale
    assert abs(energy[0]) <= 1e-12 * energy_scale
    assert abs(energy[1]) <= 1e-12 * energy_scale
    assert abs(energy[2]) <= 1e-12 * energy_scale


def test_warping_correction_against_plain_bt():
    """The warped cell turned rigidly: plain BT takes the warped nodes' in-plane velocities
    for an hourglass motion (hourglass energy, forces out of moment equilibrium); the
    BWC projection does not."""
    cells = np.array([[0, 1, 2, 3]], np.int32)
    results = {}
    for formulation in ("bwc", "bt"):
        kernel = ShellKernel(ELASTIC, ShellTechnology.choose("quadrilateral", formulation),
                             cells, T)  # fmt: skip
        results[formulation] = rigid_run(kernel, WARPED)
    scale_f, scale_e = E * T * 1e-3, 0.5 * E * 1e-6 * T
    assert results["bwc"][0] <= 1e-12 * scale_f and abs(results["bwc"][1][1]) <= 1e-12 * scale_e
    assert results["bt"][1][1] > 1e-3 * scale_e  # plain BT dissipates in a rigid rotation
    assert results["bt"][0] > 1e-3 * scale_f


@pytest.mark.parametrize("formulation", ["bwc", "bt"])
def test_forces_of_any_motion_are_in_equilibrium(formulation):
    """Random resultants, drilling moments and random nodal velocities on the warped cell:
    zero resultant force and moment (nodal moments included) with the projection; plain BT's
    hourglass forces of the in-plane velocities at the warped nodes' heights leave a
    moment."""
    cells = np.array([[0, 1, 2, 3]], np.int32)
    technology = ShellTechnology.choose("quadrilateral", formulation, drilling_stiffness=0.01)
    kernel = ShellKernel(ELASTIC, technology, cells, T)
    rng = np.random.default_rng(3)
    kernel.history[:, 0] = rng.normal(size=12) * 1e5
    v, w = rng.normal(size=(4, 3)), rng.normal(size=(4, 3))
    f, m = np.zeros((4, 3)), np.zeros((4, 3))
    zero = np.zeros((4, 3))  # dt = 0: the mid-step configuration (the hourglass forces')
    x = WARPED  # is the current one (the resultants' forces')
    kernel.run(0.0, WARPED, zero, v, w, f, m)
    scale = np.abs(f).max()
    moment = np.abs((np.cross(x, f) + m).sum(axis=0)).max()
    assert np.abs(f.sum(axis=0)).max() <= 1e-13 * scale
    if formulation == "bwc":
        assert moment <= 1e-13 * scale
    else:
        assert moment > 1e-3 * scale


def test_membrane_patch():
    """A linear displacement of an irregular flat patch: every cell has the membrane
    stress t C eps (its invariants: the frames differ from cell to cell) and the interior
    nodes carry no force but the second-order one of the co-rotational frames (each cell's
    e1 follows its own xi line, which turns with the strain: relative |G| at most)."""
    X, cells = patch(3, warp=0.0, seed=4)
    kernel = ShellKernel(ELASTIC, ShellTechnology.choose("quadrilateral"), cells, T)
    G = np.array([[1.0, 0.4, 0.0], [-0.2, 0.5, 0.0], [0.0, 0.0, 0.0]]) * 1e-4
    dt = 1e-3
    v = X @ G.T / dt  # u = G X over one step
    f, m = np.zeros_like(X), np.zeros_like(X)
    kernel.run(dt, X, v * dt, v, np.zeros_like(X), f, m)
    # the mid-step configuration is (I + G/2) X: the velocity gradient there
    L = (G @ np.linalg.inv(np.eye(3) + G / 2))[:2, :2]
    eps = 0.5 * (L + L.T)
    c = E / (1 - NU**2)
    sigma = c * ((1 - NU) * eps + NU * np.trace(eps) * np.eye(2))
    N = kernel.history[0:3]
    trace, det = N[0] + N[1], N[0] * N[1] - N[2] ** 2
    exact = T * sigma
    np.testing.assert_allclose(trace, np.trace(exact), rtol=1e-12)
    np.testing.assert_allclose(det, np.linalg.det(exact), rtol=1e-11)
    inner = (X[:, 0] > 0) & (X[:, 0] < 1) & (X[:, 1] > 0) & (X[:, 1] < 1)
    assert np.abs(f[inner]).max() <= np.abs(G).max() * np.abs(f).max()


@pytest.mark.parametrize("material", [ELASTIC, J2], ids=["elastic", "j2-5-points"])
def test_cantilever_under_end_moment(material):
    """A strip clamped at x = 0 (1 m x 0.1 m x 10 mm, 8 cells) under an end moment M,
    relaxed dynamically: the moment resultant is M / width in every cell and the tip
    deflection is that of the circular arc of curvature M / (E I), (1 - cos theta) / kappa,
    within 1 % (the one-point cell has the exact bending stiffness of its nodal
    rotations). The J2 strip stays elastic (sigma_max = 6 M / (w t^2) = 63 MPa)."""
    length, width, cells_along = 1.0, 0.1, 8
    xs = np.linspace(0.0, length, cells_along + 1)
    X = np.array([[x, y, 0.0] for x in xs for y in (0.0, width)])
    cells = np.array([[2 * i, 2 * i + 2, 2 * i + 3, 2 * i + 1] for i in range(cells_along)],
                     dtype=np.int32)  # fmt: skip
    kernel = ShellKernel(material, ShellTechnology.choose("quadrilateral"), cells, T)
    inertia_area = width * T**3 / 12
    theta_tip = 0.05
    moment = theta_tip * E * inertia_area / length
    n = len(X)
    area = length / cells_along * width
    mass = np.full(n, RHO * T * area / 2)
    mass[[0, 1, -2, -1]] /= 2
    inertia = mass * (area / 9 + T * T / 12)
    external = np.zeros((n, 3))
    external[-2:, 1] = -moment / 2
    fixed = X[:, 0] == 0.0
    dt = 0.5 * min(length / cells_along, width) / math.sqrt(E / (RHO * (1 - NU**2)))
    omega = 1.875**2 * math.sqrt(E * inertia_area / (RHO * width * T * length**4))
    damping = 2.0 * omega  # critical for the first mode
    u, v, w = np.zeros((n, 3)), np.zeros((n, 3)), np.zeros((n, 3))
    steps = int(2.5 * 2 * math.pi / omega / dt)
    for step in range(steps):
        f, m = np.zeros((n, 3)), np.zeros((n, 3))
        kernel.run(dt if step else 0.0, X, u, v, w, f, m, estimate=False)
        a, alpha = -f / mass[:, None], (external - m) / inertia[:, None]
        a[fixed] = alpha[fixed] = 0.0
        v = (v * (1 - damping * dt / 2) + dt * a) / (1 + damping * dt / 2)
        w = (w * (1 - damping * dt / 2) + dt * alpha) / (1 + damping * dt / 2)
        u += dt * v
    kappa = moment / (E * inertia_area)
    N, M, _ = kernel.resultants()
    np.testing.assert_allclose(-M[0], moment / width, rtol=1e-3)
    tip = (X[-2:] + u[-2:]).mean(axis=0)
    assert tip[2] == pytest.approx((1 - math.cos(theta_tip)) / kappa, rel=1e-2)
    assert tip[0] == pytest.approx(math.sin(theta_tip) / kappa, rel=1e-4)


def test_characteristic_length():
    """Radioss's L_c: max(A / longest diagonal, shortest side or diagonal)."""
    X = np.array([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [2.0, 1.0, 0.0], [0.0, 1.0, 0.0]])
    kernel = ShellKernel(ELASTIC, ShellTechnology.choose("quadrilateral"),
                         np.array([[0, 1, 2, 3]], np.int32), T)  # fmt: skip
    area, length = kernel.sizes(X)
    assert area[0] == pytest.approx(2.0, rel=1e-14)
    assert length[0] == pytest.approx(max(2.0 / math.sqrt(5.0), 1.0), rel=1e-14)


@pytest.mark.parametrize("sides, warp", [((1.0, 1.0), 0.3), ((2.0, 1.0), 0.45), ((1.0, 1.0), 0.0)])
def test_characteristic_length_of_a_warped_cell(sides, warp):
    """CDLEN3 works on the cell's projection onto its mid-plane (cderi3.F's X2..Y4): a
    rectangle a x b whose corners are lifted +w, -w, +w, -w off it has the rectangle's
    L_c = max(a b / (a^2 + b^2)^(1/2), min(a, b)), not the longer one of its sides in
    space ((min(a, b)^2 + 4 w^2)^(1/2)), wherever it is in space."""
    a, b = sides
    X = np.array([[0.0, 0.0, warp], [a, 0.0, -warp], [a, b, warp], [0.0, b, -warp]])
    X = X @ rotation([1.0, -2.0, 0.5], 1.1).T + [0.5, 2.0, -1.0]
    kernel = ShellKernel(ELASTIC, ShellTechnology.choose("quadrilateral"),
                         np.array([[0, 1, 2, 3]], np.int32), T)  # fmt: skip
    area, length = kernel.sizes(X)
    assert area[0] == pytest.approx(a * b, rel=1e-13)
    assert length[0] == pytest.approx(max(a * b / math.hypot(a, b), min(a, b)), rel=1e-13)


def qeph_length(x, y, dn=0.015):
    """QEPH's L_c (OpenRadioss's CZCORC1 and CNDT3) of a flat cell with corners (x, y)."""
    x, y = np.asarray(x) - np.mean(x), np.asarray(y) - np.mean(y)
    area = 0.5 * ((x[2] - x[0]) * (y[3] - y[1]) - (x[3] - x[1]) * (y[2] - y[0]))
    half13, half24 = np.hypot(x[0] - x[2], y[0] - y[2]) / 2, np.hypot(x[1] - x[3], y[1] - y[3]) / 2
    h = max(abs(x[1] * y[3] - y[1] * x[3]), abs(x[0] * y[2] - y[0] * x[2])) / area
    c1 = math.hypot(x[1] + x[2] - x[0] - x[3], y[1] + y[2] - y[0] - y[3])
    c2 = math.hypot(x[2] + x[3] - x[0] - x[1], y[2] + y[3] - y[0] - y[1])
    f = 3.413 * max(0.0, 4 * area / (c1 * c2) - 0.7071)
    shape = 2 * (1 + min(0.5, (max(c1, c2) / min(c1, c2) - 1) / 4)) * (0.78 + 0.22 * f**3)
    length = area / math.sqrt(shape * (1.25 + h) * max(half13, half24) ** 2)
    return length * (math.sqrt(1 + dn**2) - dn)


@pytest.mark.parametrize("corners, closed", [
    # a square of side 1: L_c = 1 / (2 (0.78 + 0.22 f^3) 5/4 / 2)^(1/2), f = 3.413 (1 - 0.7071)
    ([(0, 0), (1, 0), (1, 1), (0, 1)],
     1 / math.sqrt(2 * (0.78 + 0.22 * (3.413 * 0.2929) ** 3) * 1.25 / 2)),
    # a 2 x 1 rectangle: aspect factor 1 + (2 - 1) / 4, half diagonal sqrt(5) / 2
    ([(0, 0), (2, 0), (2, 1), (0, 1)],
     2 / math.sqrt(2 * 1.25 * (0.78 + 0.22 * (3.413 * 0.2929) ** 3) * 1.25 * 1.25)),
    ([(0, 0), (2, 0), (1.5, 1), (0.5, 1)], None),  # a trapezoid: h > 0
    ([(0, 0), (1, 0.1), (1.3, 0.8), (-0.2, 1.1)], None),
])  # fmt: skip
def test_qeph_characteristic_length(corners, closed):
    """QEPH's L_c (Ishell 24), rotated and moved in space: the closed form of a square
    (0.894 of its side, times sqrt(1 + dn^2) - dn = 0.9851) and a rectangle, and
    OpenRadioss's formula on cells that are not parallelograms."""
    x, y = np.array(corners, dtype=float).T
    expected = qeph_length(x, y)
    if closed is not None:
        assert expected == pytest.approx(closed * (math.sqrt(1 + 0.015**2) - 0.015), rel=1e-12)
    X = np.column_stack([x, y, np.zeros(4)]) @ rotation([1.0, 2.0, 3.0], 0.7).T + [3.0, -1.0, 2.0]
    cells = np.array([[0, 1, 2, 3]], np.int32)
    qeph = ShellKernel(ELASTIC, ShellTechnology.choose("quadrilateral", step_length="qeph"),
                       cells, T)  # fmt: skip
    area, length = qeph.sizes(X)
    assert length[0] == pytest.approx(expected, rel=1e-12)
    if closed is not None:  # on rectangles QEPH's step is the shorter (not on every cell)
        bt = ShellKernel(ELASTIC, ShellTechnology.choose("quadrilateral"), cells, T)
        assert bt.sizes(X)[1][0] > length[0]


def test_qeph_step_length_is_for_quadrilaterals():
    assert ShellTechnology.choose("triangle", step_length="qeph").step_length == "bt"
    with pytest.raises(ValueError, match="element.step_length"):
        ShellTechnology.choose("quadrilateral", step_length="diagonal")
