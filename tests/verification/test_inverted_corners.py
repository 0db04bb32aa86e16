"""Corners of one-point hexahedra that turn inside out (issue 28, class 5).

A one-point hexahedron computes its force at its centre, whose Jacobian can stay positive
while a corner turns inside out. The kernels test the eight corner Jacobians too
(``kernels/step.h``, ``hex8_corners_inverted``). References: the closed-form Jacobian of a
cube with one corner pushed in along its diagonal (det J at that corner is (1 - 3 s)
h^3 / 8 for a push of s h on each axis, at the centre (1 - 3 s / 4) h^3 / 8:
for s = 0.6 the corner is inverted, the centre is not); a sheared cube (det J = h^3 / 8
everywhere) is not inverted.
"""

import copy

import numpy as np
import pytest
from conftest import bar_scene, block_scene, run
from mpi4py import MPI

from rwall_fem import build_simulation, parse_scene

J2 = {"model": "elastic_plastic", "density": 7850.0, "young": 210e9, "poisson": 0.3,
      "hardening": "linear", "yield_stress": 400e6, "hardening_modulus": 1e9}  # fmt: skip
JC = {"model": "johnson_cook", "density": 7850.0, "young": 210e9, "poisson": 0.3,
      "yield_stress": 490e6, "hardening_coefficient": 383e6, "hardening_exponent": 0.45,
      "strain_rate_coefficient": 0.0123, "reference_strain_rate": 1.0}  # fmt: skip


def one_cell(material, directory):
    """A 10 mm cube of one one-point hexahedron (physical hourglass control)."""
    raw = block_scene(size=0.01, h=0.01)
    raw["material"] = dict(material)
    raw["output"] |= {"frames": 0}
    return build_simulation(parse_scene(copy.deepcopy(raw), source="test"), MPI.COMM_WORLD,
                            directory)  # fmt: skip


def inverted_after(sim, displacement) -> int:
    """How many cells the kernels find inverted with the nodes displaced by
    ``displacement(X)`` (m), over the ranks."""
    s = sim.state
    s.u[:] = displacement(s.X[: len(s.u)])
    sim.internal.accelerate(s)
    return MPI.COMM_WORLD.allreduce(int(sim.internal.step[5]))


@pytest.mark.parametrize("material", [dict(J2), {"model": "saint_venant_kirchhoff",
                         "density": 7850.0, "young": 210e9, "poisson": 0.3}],
                         ids=["elasto-plastic", "total Lagrangian"])  # fmt: skip
def test_a_corner_pushed_through_its_cell_is_inverted_though_the_centre_is_not(
    material, shared_dir
):
    h, s = 0.01, 0.6
    corner = (1 - 3 * s) * h**3 / 8
    centre = (1 - 3 * s / 4) * h**3 / 8
    assert corner < 0.0 < centre  # the references: the centre alone would miss it
    sim = one_cell(material, shared_dir)

    def pushed(X):
        u = np.zeros_like(X)
        u[np.all(np.abs(X) < 1e-9 * h, axis=1)] = s * h
        return u

    assert inverted_after(sim, pushed) == 1

    def sheared(X):  # det J = h^3 / 8 at every point
        u = np.zeros_like(X)
        u[:, 0] = 0.5 * X[:, 2]
        return u

    assert inverted_after(sim, sheared) == 0
    assert inverted_after(sim, lambda X: np.zeros_like(X)) == 0


@pytest.mark.parametrize("material", [J2, JC], ids=["J2", "Johnson-Cook"])
def test_a_coarse_bar_at_3000_m_s_stops_when_its_corners_invert(material, shared_dir):
    """The issue's bar: 320 one-point hexahedra at 3 km/s on a plane wall; the corners of
    the cells at the impact face turn inside out within the first microseconds (the bar
    travels 4.5 mm, over two layers, in 1.5 us): the run stops there, naming the cell
    (at the wall) and the time, instead of ending 'done'."""
    raw = bar_scene(speed=3000.0, end_time=1e-5)
    raw["mesh"] |= {"size": [0.008, 0.008, 0.04], "element_size": 0.002}
    raw["material"] = dict(material)
    sim = run(raw, shared_dir)
    assert sim.status.startswith("stopped: step ") and " inverted at t = " in sim.status
    assert "at a corner" in sim.status
    assert sim.state.t < 3e-6
    z = float(sim.status.split("cell at (")[1].split(")")[0].split(",")[2])
    assert z < 0.002  # a cell of the first layer, at the wall


def test_erode_takes_the_cells_whose_corners_invert(shared_dir):
    """With run.dt_min_action = "erode" the cells that invert are eroded instead: the run
    ends, with eroded cells, and the energy books still close."""
    raw = bar_scene(speed=3000.0, end_time=3e-6)
    raw["mesh"] |= {"size": [0.008, 0.008, 0.04], "element_size": 0.002}
    raw["material"] = dict(J2)
    raw["run"] |= {"dt_min": 1e-10, "dt_min_action": "erode"}
    sim = run(raw, shared_dir)
    assert sim.status == "done"
    summary = sim.history.summary
    assert summary["erosion"]["eroded_cells"] > 0
    assert summary["energy"]["max_balance_error"] <= 1e-6
