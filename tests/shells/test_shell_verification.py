"""Bodies of shells against closed forms of plate theory: bending vibration and plasticity.

- A simply supported square plate (1 m x 1 m x 10 mm steel, E 200 GPa, nu 0.3, rho 8000)
  started in the velocity of its first mode: the period of its centre is Navier's
  1 / f11, f11 = (pi / 2) (2 / a^2) sqrt(D / (rho t)) = 47.53 Hz, within 2 %.
- A strip pulled in-plane follows the uniaxial curve of its hardening law (0.5 %), and one
  bent by its end rotations tends to the plastic moment sigma_y t^2 / 4 per width times
  the through-thickness rule's own limit (0.816, 0.943, 0.973 with 3, 5, 7 points).
- The thick plate of NAFEMS FV52's data (10 x 10 x 1 m) as a shell: its first period is
  Mindlin's (shear factor 5/6, rotary inertia; hard simple support) within 3 %, and so
  NAFEMS's f1 = 45.897 Hz. (FV52 itself is a solid supported along its bottom edges;
  45.897 Hz equals the Mindlin plate's frequency to 0.1 %, which the test also checks.)
"""

import copy
import math

import numpy as np
import pytest
from mpi4py import MPI

from rwall_fem import build_simulation, parse_scene

comm = MPI.COMM_WORLD
NAFEMS = {"model": "linear_elastic", "density": 8000.0, "young": 200e9, "poisson": 0.3}


class _Centre:
    """Records this rank's sum of the z displacements (m) of the nodes at ``point`` (x, y)
    every step; :meth:`mean` reduces them over the ranks once, at the end."""

    def __init__(self, sim, point):
        X = sim.state.X
        self.rows = np.flatnonzero(np.hypot(X[:, 0] - point[0], X[:, 1] - point[1]) < 1e-9)
        self.count = comm.allreduce(len(self.rows))
        self.times, self.sums = [], []

    def due(self, s):
        return True

    def record(self, sim, s):
        self.times.append(s.t)
        self.sums.append(float(s.u[self.rows, 2].sum()))

    def close(self, sim):
        pass

    def mean(self) -> tuple[np.ndarray, np.ndarray]:
        """The times (s) and the nodes' mean z displacement (m)."""
        return np.array(self.times), comm.allreduce(np.array(self.sums)) / self.count


def _kinetic(sim) -> float:
    """1/2 sum m v^2 + 1/2 sum I w^2 (J) of the velocities held now."""
    s, body = sim.state, sim.internal
    local = 0.5 * np.sum(s.mass[:, None] * s.v**2)
    local += 0.5 * np.sum(body.inertia[:, 1:2] * body.w.owned**2)
    return comm.allreduce(float(local))


def _first_period(directory, a, t, h, hard, cell="quadrilateral", periods=1.1):
    """The period (s) of the centre of the square plate a x a x t (m) of NAFEMS's steel,
    cells of h (m), its edges' translations held (and, if ``hard``, the rotation about each
    edge's in-plane normal, the hinge about the edge left free: the hard simple support),
    started at the velocity V sin(pi x / a) sin(pi y / a) with the matching angular
    velocity, V such that the amplitude is t / 100 (larger ones stiffen the plate: its
    edges are held in-plane). The centre's displacement is a sin(omega t): the period is
    the mean of twice its downward crossing of zero (T/2) and its upward one (T)."""
    raw = {
        "run": {"end_time": 1.0, "dt_scale": 0.9},
        "mesh": {"shape": "plate", "size": [a, a, t], "element_size": h,
                 "cell": cell},
        "material": dict(NAFEMS),
        "output": {"frames": 0, "plot": False},
        "boundary": [
            {"group": side, "components": "xyz", **({"rotations": axis} if hard else {})}
            for side, axis in (("side_x0", "x"), ("side_x1", "x"), ("side_y0", "y"),
                               ("side_y1", "y"))
        ],
    }  # fmt: skip
    sim = build_simulation(parse_scene(copy.deepcopy(raw), source="test"), comm, directory)
    s, body = sim.state, sim.internal
    k = math.pi / a
    x, y = s.X[:, 0], s.X[:, 1]
    edge = np.isclose(x, 0) | np.isclose(x, a) | np.isclose(y, 0) | np.isclose(y, a)
    speed = 0.01 * t * 2 * math.pi * navier_frequency(a, t)  # m/s, amplitude t / 100
    s.v[:, 2] = np.where(edge, 0.0, speed * np.sin(k * x) * np.sin(k * y))
    w = body.w.owned
    n = len(w)
    w[:, 0] = speed * k * np.sin(k * x[:n]) * np.cos(k * y[:n])  # d v_z / dy
    w[:, 1] = -speed * k * np.cos(k * x[:n]) * np.sin(k * y[:n])  # -d v_z / dx
    sim.history.balance.initial = _kinetic(sim)
    probe = _Centre(sim, (a / 2, a / 2))
    assert probe.count == 1
    sim.recorders.append(probe)
    sim.end_time = periods * 2 * math.pi / (math.pi**2 * 2 / a**2 * math.sqrt(
        NAFEMS["young"] * t**2 / (12 * (1 - NAFEMS["poisson"] ** 2) * NAFEMS["density"])))
    assert sim.run() == "done"
    times, z = probe.mean()
    down = np.flatnonzero((z[:-1] > 0) & (z[1:] <= 0))
    up = np.flatnonzero((z[:-1] < 0) & (z[1:] >= 0))
    crossings = [times[i] + (times[i + 1] - times[i]) * z[i] / (z[i] - z[i + 1])
                 for i in (down[0], up[0])]  # fmt: skip
    assert sim.history.summary["energy"]["max_balance_error"] <= 1e-10
    return 0.5 * (2 * crossings[0] + crossings[1])


def mindlin_frequency(a, t, material=NAFEMS, shear_factor=5 / 6) -> float:
    """The first frequency (Hz) of the hard simply supported square Mindlin plate a x a x t
    (m): the lower root in omega^2 of
    (k G t K^2 - rho t omega^2)(D K^2 + k G t - rho t^3 omega^2 / 12) = (k G t K)^2,
    K^2 = 2 pi^2 / a^2 (Mindlin 1951; Kirchhoff's Navier frequency as G -> infinity)."""
    E, nu, rho = material["young"], material["poisson"], material["density"]
    kG = shear_factor * E / (2 * (1 + nu)) * t
    D = E * t**3 / (12 * (1 - nu**2))
    K2 = 2 * math.pi**2 / a**2
    A = rho * t * rho * t**3 / 12
    B = -(kG * K2 * rho * t**3 / 12 + rho * t * (D * K2 + kG))
    C = kG * K2 * (D * K2 + kG) - kG**2 * K2
    return math.sqrt((-B - math.sqrt(B * B - 4 * A * C)) / (2 * A)) / (2 * math.pi)


def navier_frequency(a, t, material=NAFEMS) -> float:
    """Navier's f11 (Hz) of the simply supported square Kirchhoff plate a x a x t (m)."""
    E, nu, rho = material["young"], material["poisson"], material["density"]
    D = E * t**3 / (12 * (1 - nu**2))
    return math.pi / 2 * 2 / a**2 * math.sqrt(D / (rho * t))


@pytest.mark.parametrize("cell, h", [("quadrilateral", 0.05), ("triangle", 0.1)])
def test_a_simply_supported_thin_plate_vibrates_at_navier_frequency(shared_dir, cell, h):
    """The period of the 1 m x 1 m x 10 mm plate is 1 / f11 within 2 % on 20 x 20
    quadrilaterals and on 10 x 10 squares halved into triangles, the edges' translations
    held and their rotations free. Measured: quadrilaterals +3.4 % (10 x 10), +1.1 %
    (20 x 20), +0.6 % (40 x 40); triangles +0.2 % (10 x 10 and 20 x 20). Of these, the
    scaled rotational inertia m (A / 6 + t^2 / 12) accounts for about (A / 12) K^2,
    K^2 = 2 pi^2 / a^2: with the lamina's m t^2 / 12 alone (and a step 18 times smaller)
    the quadrilaterals give +1.7 % and +0.7 % (their own flexibility), the triangles
    -0.6 %."""
    f11 = navier_frequency(1.0, 0.01)
    assert f11 == pytest.approx(47.53, abs=0.005)
    period = _first_period(shared_dir, 1.0, 0.01, h, hard=False, cell=cell)
    print(f"thin plate, {cell}, h {h}: period {period:.5e} s against 1/f11 {1 / f11:.5e} s "
          f"({period * f11 - 1:+.2%})")
    assert period == pytest.approx(1 / f11, rel=0.02)


@pytest.mark.parametrize("cell, h", [("quadrilateral", 0.5), ("triangle", 1.0)])
def test_nafems_fv52_thick_plate_as_a_shell(shared_dir, cell, h):
    """The period of the 10 x 10 x 1 m plate is Mindlin's 1 / f1 (and NAFEMS's 1 / 45.897 Hz)
    within 3 % on 20 x 20 quadrilaterals (measured +0.6 %; +2.4 % at 10 x 10) and 10 x 10
    squares halved into triangles (+0.2 %), with the hard simple support (with the
    rotations free, the soft support's boundary layer makes the plate much more flexible,
    as a Mindlin plate's)."""
    f1 = mindlin_frequency(10.0, 1.0)
    assert f1 == pytest.approx(45.897, rel=1e-3)  # NAFEMS's answer for the solid plate
    period = _first_period(shared_dir, 10.0, 1.0, h, hard=True, cell=cell)
    print(f"FV52, {cell}, h {h}: period {period:.5e} s against 1/f1 {1 / f1:.5e} s "
          f"({period * f1 - 1:+.2%}), 1/45.897 Hz: {period * 45.897 - 1:+.2%}")
    assert period == pytest.approx(1 / f1, rel=0.03)


# --- plasticity ----------------------------------------------------------------------

SIGMA_Y = 250e6  # Pa
LAWS = {
    "linear": {"hardening": "linear", "yield_stress": SIGMA_Y, "hardening_modulus": 1e9},
    "power": {"hardening": "power", "yield_stress": SIGMA_Y, "hardening_coefficient": 400e6,
              "hardening_exponent": 0.3},
}  # fmt: skip


def uniaxial_stress(strain: float, law: dict, E: float) -> float:
    """The uniaxial stress (Pa) at the true strain ``strain`` of the hardening ``law``:
    sigma = sigma_y(eps_p) with eps_p = strain - sigma / E, by bisection."""
    A = law["yield_stress"]
    if strain * E <= A:
        return E * strain

    def flow(eps_p):
        if law["hardening"] == "linear":
            return A + law["hardening_modulus"] * eps_p
        return A + law["hardening_coefficient"] * eps_p ** law["hardening_exponent"]

    low, high = A, E * strain  # the residual flow(strain - s / E) - s changes sign between
    for _ in range(100):
        mid = 0.5 * (low + high)
        low, high = (mid, high) if flow(strain - mid / E) > mid else (low, mid)
    return 0.5 * (low + high)


class _Strip:
    """Records, every ``every`` steps, the true strain ln(1 + u_end / L) of the strip's end
    x = ``length`` and its cells' mean membrane stress N_xx / t (Pa) and largest spread."""

    def __init__(self, sim, length, every):
        self.end = np.flatnonzero(np.isclose(sim.state.X[:, 0], length))
        self.count = comm.allreduce(len(self.end))
        self.length, self.every, self.rows = length, every, []

    def due(self, s):
        return s.step % self.every == 0

    def record(self, sim, s):
        kernel = sim.internal.elements[0].kernel
        N = kernel.resultants()[0] / kernel.thickness  # (3, cells), Pa
        cells = comm.allreduce(N.shape[1])
        mean = comm.allreduce(float(N[0].sum())) / cells
        spread = comm.allreduce(float(np.abs(N[0] - mean).max(initial=0.0)), op=MPI.MAX)
        lateral = comm.allreduce(float(np.abs(N[1]).max(initial=0.0)), op=MPI.MAX)
        u = comm.allreduce(float(s.u[self.end, 0].sum())) / self.count
        self.rows.append((math.log1p(u / self.length), mean, spread, lateral))

    def close(self, sim):
        pass


@pytest.mark.parametrize("law", ["linear", "power"])
def test_a_strip_pulled_in_plane_follows_the_uniaxial_curve(shared_dir, law):
    """A steel strip 100 x 10 x 2 mm (10 x 1 cells of 10 mm, 5 points), stretched
    homogeneously (its velocity V x / L from the start, the ends' x velocities held at 0
    and V = 1 m/s, the sides free) to a true strain of 3 %: its membrane stress is the
    uniaxial curve of the hardening law, sigma = sigma_y(eps - sigma / E), within 0.5 %
    (and within 0.5 % of sigma_y while elastic), the same in every cell, and N_yy = 0.
    Measured: 9e-4 (linear, at the yield point, where the sides' contraction rate changes
    and the strip's width rings: N_yy / t 0.2 % of sigma_y), 1e-5 (power); the engineering
    strain in place of the true one would be 0.2 % and 0.3 % off at 3 %."""
    length, width, t, speed = 0.1, 0.01, 0.002, 1.0
    material = {"model": "elastic_plastic", "density": 7800.0, "young": 2.1e11,
                "poisson": 0.3} | LAWS[law]  # fmt: skip
    raw = {
        "run": {"end_time": 1.0, "dt_scale": 0.9},
        "mesh": {"shape": "plate", "size": [length, width, t], "element_size": 0.01,
                 "cell": "quadrilateral"},
        "material": material,
        "output": {"frames": 0, "plot": False},
        "boundary": [
            {"group": "side_x0", "velocity": [0.0, 0.0, 0.0], "components": "x"},
            {"group": "side_x1", "velocity": [speed, 0.0, 0.0], "components": "x"},
        ],
    }  # fmt: skip
    sim = build_simulation(parse_scene(copy.deepcopy(raw), source="test"), comm, shared_dir)
    s = sim.state
    s.v[:, 0] = speed * s.X[:, 0] / length
    s.v[:, 1] = -0.3 * speed * (s.X[:, 1] - width / 2) / length  # the elastic contraction
    sim.history.balance.initial = _kinetic(sim)
    probe = _Strip(sim, length, every=50)
    sim.recorders.append(probe)
    sim.end_time = math.expm1(0.03) * length / speed
    assert sim.run() == "done"
    rows = np.array(probe.rows)
    E = material["young"]
    expected = np.array([uniaxial_stress(eps, LAWS[law], E) for eps in rows[:, 0]])
    error = np.abs(rows[:, 1] - expected) / np.maximum(expected, SIGMA_Y)
    worst = int(error.argmax())
    print(f"uniaxial {law}: {len(rows)} points to eps {rows[-1, 0]:.4f}, largest error "
          f"{error[worst]:.2e} at eps {rows[worst, 0]:.4f} ({rows[worst, 1]:.5e} against "
          f"{expected[worst]:.5e} Pa); spread {rows[:, 2].max():.1e} Pa, N_yy / t "
          f"{rows[:, 3].max():.1e} Pa")
    assert rows[-1, 0] >= 0.029
    assert rows[-1, 1] > 1.1 * SIGMA_Y  # well into the plastic range
    assert error.max() <= 5e-3
    assert rows[:, 2].max() <= 1e-3 * SIGMA_Y
    assert rows[:, 3].max() <= 5e-3 * SIGMA_Y


@pytest.mark.parametrize("points", [3, 5, 7])
def test_a_strip_bent_by_its_end_rotations_tends_to_the_plastic_moment(shared_dir, points):
    """A perfectly plastic strip 100 x 20 x 10 mm (10 x 2 cells of 10 mm), its ends' z held
    and their rotations about y prescribed at -+Omega (the rotations held, their angular
    velocity set: the Python API; a scene holds rotations at 0 only), started in the
    matching uniform curvature rate (w_y = kappa' (x - L/2), v_z from it), free across, bent
    to 20 times the yield curvature 2 sigma_y / (E t): the moment per width M_xx of every
    cell tends to sigma_y t^2 / 4 times the thickness rule's own limit 4 sum w |zeta|
    (0.816, 0.943, 0.973 with 3, 5, 7 points; the element test measured the same), within
    0.5 % of it; the continuum's M = (1 - (kappa_y / kappa)^2 / 3) sigma_y t^2 / 4 is 0.1 %
    below its limit there."""
    from rwall_fem.shells.elements import thickness_rule

    length, width, t, E = 0.1, 0.02, 0.01, 2.1e11
    material = {"model": "elastic_plastic", "density": 7800.0, "young": E, "poisson": 0.3,
                "hardening": "linear", "yield_stress": SIGMA_Y, "hardening_modulus": 0.0}
    raw = {
        "run": {"end_time": 1.0, "dt_scale": 0.9},
        "mesh": {"shape": "plate", "size": [length, width, t], "element_size": 0.01,
                 "cell": "quadrilateral"},
        "material": material,
        "element": {"points": points},
        "output": {"frames": 0, "plot": False},
        "boundary": [{"group": side, "components": "z", "rotations": "y"}
                     for side in ("side_x0", "side_x1")],
    }  # fmt: skip
    raw["run"]["max_energy_error"] = 1e300  # the prescribed rotations' work is not booked
    sim = build_simulation(parse_scene(copy.deepcopy(raw), source="test"), comm, shared_dir)
    s, body = sim.state, sim.internal
    yield_curvature = 2 * SIGMA_Y / (E * t)
    duration = 2e-3
    rate = 20 * yield_curvature / duration  # 1/(m s)
    x = s.X[:, 0] - length / 2
    s.v[:, 2] = 0.5 * rate * ((length / 2) ** 2 - x**2)
    body.w.owned[:, 1] = rate * x[: len(body.w.owned)]
    sim.end_time = duration
    assert sim.run() == "done"
    M = body.elements[0].kernel.resultants()[1]  # (3, cells), N m/m
    plastic = SIGMA_Y * t * t / 4
    zeta, weight = thickness_rule(points)
    rule = 4 * weight @ np.abs(zeta)
    low = comm.allreduce(float(M[0].min(initial=np.inf)), op=MPI.MIN) / plastic
    high = comm.allreduce(float(M[0].max(initial=-np.inf)), op=MPI.MAX) / plastic
    across = comm.allreduce(float(np.abs(M[1]).max(initial=0.0)), op=MPI.MAX) / plastic
    print(f"bent, {points} points: M_xx / (sigma_y t^2 / 4) {low:.4f} to {high:.4f} "
          f"(rule {rule:.4f}, continuum error {low - 1:+.1%}), |M_yy| {across:.1e}")
    assert low == pytest.approx(rule, rel=5e-3) and high == pytest.approx(rule, rel=5e-3)
    assert across <= 0.02
