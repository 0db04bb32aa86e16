"""The flow-stress cap (``material.max_flow_stress``, Radioss LAW2's SIG_max0) against
its definition: sigma_y = min(law(eps_p), cap) times Johnson-Cook's rate and thermal
factors, with no hardening where the cap holds.

- A solid bar (1 x 1 x 4 one-point hexahedra) and a shell strip (4 x 1 quadrilaterals, 5
  points) pulled along their length by a prescribed end velocity, far past the plastic
  strain at which the law reaches the cap: while a point flows on the cap, its von Mises
  stress equals the cap to 1e-9 (the radial return puts it on the yield surface to
  round-off), no point ever exceeds it, and the plastic strain keeps growing. Linear
  hardening (the closed-form return crossing the cap inside a step) and power hardening
  (Newton's iterations over the kink).
- One material point driven at a constant strain rate with Johnson-Cook's rate term: the
  flow stress on the cap is cap (1 + C ln(rate / rate_0)) (the cap applies before the
  factor, Radioss's ICC 1), to 1e-9.
"""

import copy
import math

import numpy as np
import pytest
from mpi4py import MPI

from rwall_fem import build_simulation, parse_scene
from rwall_fem.kernels import load

comm = MPI.COMM_WORLD
STEEL = {"model": "elastic_plastic", "density": 7850.0, "young": 210e9, "poisson": 0.3}
LAWS = {
    "linear": {"hardening": "linear", "yield_stress": 200e6, "hardening_modulus": 2e9},
    "power": {"hardening": "power", "yield_stress": 200e6, "hardening_coefficient": 400e6,
              "hardening_exponent": 0.5},  # fmt: skip
}
CAP = 230e6
# the plastic strain where each law reaches the cap
CAPPED_AT = {"linear": (CAP - 200e6) / 2e9, "power": ((CAP - 200e6) / 400e6) ** 2}
SPEED, LENGTH = 2.0, 0.008  # m/s of the pulled end, m


def mises(s) -> np.ndarray:
    """Von Mises stress (Pa) of stress rows (xx, yy, zz, xy, yz, xz) or plane (xx, yy, xy)."""
    if len(s) == 3:
        return np.sqrt(s[0] ** 2 + s[1] ** 2 - s[0] * s[1] + 3 * s[2] ** 2)
    p = s[:3].mean(axis=0)
    return np.sqrt(1.5 * (np.sum((s[:3] - p) ** 2, axis=0) + 2 * np.sum(s[3:] ** 2, axis=0)))


class Points:
    """Recorder of every point's von Mises stress, plastic strain and axial stress each step
    (this rank's cells)."""

    def __init__(self, shells: bool):
        self.shells, self.q, self.eps_p, self.axial = shells, [], [], []

    def due(self, s):
        return True

    def record(self, sim, s):
        force = sim.internal.elements[0]
        if self.shells:
            sig = force.kernel.point_stresses()  # (points, 3, cells)
            self.q.append(np.concatenate([mises(p) for p in sig]))
            self.eps_p.append(force.plastic_strains().ravel())
            self.axial.append(sig[:, 0].ravel())
        else:
            self.q.append(mises(force.history[:6]))
            self.eps_p.append(force.history[6].copy())
            self.axial.append(force.history[2].copy())

    def close(self, sim):
        self.q, self.eps_p, self.axial = map(np.array, (self.q, self.eps_p, self.axial))


def pulled(shells: bool, law: str, directory, cap=CAP):
    """Pull the bar (along z) or strip (along x), the end's velocity ramped up to SPEED over a
    quarter of the run (no shock), to a nominal strain of 0.07."""
    end = 0.08 * LENGTH / SPEED
    material = STEEL | LAWS[law] | ({"max_flow_stress": cap} if cap else {})
    if shells:
        mesh = {"shape": "plate", "size": [LENGTH, 0.002, 0.001], "element_size": 0.002,
                "cell": "quadrilateral"}  # fmt: skip
        ends, axis = ("side_x0", "side_x1"), "x"
    else:
        mesh = {"shape": "bar", "size": [0.002, 0.002, LENGTH], "element_size": 0.002}
        ends, axis = ("bottom", "top"), "z"
    ramp = [[0.0, 0.0, 0.0, 0.0], [0.25 * end] + [SPEED if a == axis else 0.0 for a in "xyz"]]
    raw = {
        "run": {"end_time": end, "dt_scale": 0.9},
        "mesh": mesh,
        "material": material,
        "boundary": [
            {"group": ends[0], "velocity": [0.0, 0.0, 0.0], "components": axis},
            {"group": ends[1], "velocity": ramp, "components": axis},
        ],
        "output": {"frames": 0, "plot": False},
    }
    sim = build_simulation(parse_scene(copy.deepcopy(raw), source="test"), comm, directory)
    points = Points(shells)
    sim.recorders.append(points)
    sim.run()
    return sim, points


@pytest.mark.parametrize("law", sorted(LAWS))
@pytest.mark.parametrize("shells", [False, True], ids=["solid_bar", "shell_strip"])
def test_pulled_past_the_cap_the_stress_stays_at_it(shells, law, tmp_path_factory):
    directory = tmp_path_factory.mktemp("cap") if comm.rank == 0 else None
    sim, points = pulled(shells, law, comm.bcast(directory, root=0))
    q, eps_p, axial = points.q, points.eps_p, points.axial
    flowing = np.zeros_like(eps_p, dtype=bool)
    flowing[1:] = eps_p[1:] > eps_p[:-1]  # the points that flowed in this step
    on_cap = flowing & (eps_p > CAPPED_AT[law])
    highest = comm.allreduce(q.max(initial=0.0), op=MPI.MAX)
    error = comm.allreduce(np.abs(q[on_cap] - CAP).max(initial=0.0), op=MPI.MAX)
    largest = comm.allreduce(eps_p[-1].max(initial=0.0), op=MPI.MAX)
    steps_on_cap = comm.allreduce(int(on_cap.any(axis=1).sum()), op=MPI.MAX)
    axial_error = comm.allreduce(np.abs(axial[on_cap] - CAP).max(initial=0.0), op=MPI.MAX)
    if comm.rank == 0:
        print(f"{'shell' if shells else 'solid'} {law}: largest eps_p {largest:.4f} "
              f"({largest / CAPPED_AT[law]:.1f} x the cap's), {steps_on_cap} steps flowing on "
              f"the cap, |q - cap| / cap {error / CAP:.2e}, highest q / cap "
              f"{highest / CAP:.12f}, axial stress - cap {axial_error / CAP:.2e} of it")
    assert highest <= CAP * (1 + 1e-9)
    assert steps_on_cap > 50
    assert error <= 1e-9 * CAP
    assert largest > 3 * CAPPED_AT[law]  # the strain grew at the capped stress
    assert axial_error <= 0.01 * CAP  # uniaxial but for the lateral inertia (5e-3 seen)
    assert sim.history.summary["energy"]["max_balance_error"] <= 1e-6


def test_without_the_cap_the_same_pull_hardens_above_it(tmp_path_factory):
    """The reference the cap changes: the same bar hardens past the cap without it."""
    directory = tmp_path_factory.mktemp("nocap") if comm.rank == 0 else None
    _, points = pulled(False, "linear", comm.bcast(directory, root=0), cap=None)
    highest = comm.allreduce(points.q.max(initial=0.0), op=MPI.MAX)
    largest = comm.allreduce(points.eps_p[-1].max(initial=0.0), op=MPI.MAX)
    assert highest == pytest.approx(200e6 + 2e9 * largest, rel=1e-3)
    assert highest > 1.1 * CAP


def test_the_cap_applies_before_the_rate_factor():
    """One point pulled at a constant deviatoric rate, Johnson-Cook A 200 MPa, B 400 MPa,
    n 0.5, C 0.05, rate_0 1/s: once on the cap the flow stress is cap (1 + C ln(rate))."""
    ffi, lib = load()
    p = ffi.new("element_params *")
    E, nu = 210e9, 0.3
    p.lmbda, p.mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
    p.density, p.dt = 7850.0, 1e-6
    p.hardening = 3  # JOHNSON_COOK
    p.yield_stress, p.hardening_coefficient, p.hardening_exponent = 200e6, 400e6, 0.5
    p.rate_coefficient, p.reference_rate = 0.05, 1.0
    p.max_flow_stress = CAP
    sigma, eps_p, T = ffi.new("double[6]"), ffi.new("double *"), ffi.new("double *")
    de = 1e-4  # an isochoric stretch dL = diag(de, -de/2, -de/2) per step of 1 us
    dL = ffi.new("double[9]", [de, 0, 0, 0, -de / 2, 0, 0, 0, -de / 2])
    rate = math.sqrt(2 / 3 * 1.5 * de**2) / p.dt  # the equivalent deviatoric rate, 1/s
    for _ in range(2000):
        lib.plastic_point(p, sigma, eps_p, T, dL)
    s = np.array(list(sigma))
    assert eps_p[0] > 10 * CAPPED_AT["power"]
    assert mises(s) == pytest.approx(CAP * (1 + 0.05 * math.log(rate)), rel=1e-9)
