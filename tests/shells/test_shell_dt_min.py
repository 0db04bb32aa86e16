"""run.dt_min controls on shells: a steel strip of shells (20 x 2 cells of 1 mm, 1 mm
thick) driven edge-on into a plane wall at 200 m/s, whose crushed cells take the step from
178 ns (126 ns on triangles) to 82 ns (80 ns) without control. With ``dt_min = 110 ns``:

- ``dt_min_action = "erode"``: the step never goes below dt_min; the cells that would take
  it there erode, their energy booked (eroded_internal), and the balance closes to
  round-off as for solids (tests/verification/test_failure.py);
- ``"mass_scaling"``: the step holds at dt_min; the crushed cells get the mass that holds
  it, their nodes' rotational inertia growing in proportion (so that the rotations, held
  at the membrane's step by their inertia, do not set a smaller one: I / m of every node
  stays what it was), and the balance closes counting the kinetic energy the joining
  masses cost (translations and rotations).

The same answers on 1 and 2 ranks (the number of eroded or scaled cells, the energies to
1e-10).
"""

import copy

import numpy as np
import pytest
from conftest import run
from mpi4py import MPI

from rwall_fem import build_simulation, parse_scene

comm = MPI.COMM_WORLD
STEEL = {
    "model": "elastic_plastic", "density": 7850.0, "young": 200e9, "poisson": 0.3,
    "hardening": "linear", "yield_stress": 400e6, "hardening_modulus": 1e9,
}  # fmt: skip
DT_MIN = 1.1e-7


def crush_scene(cell, **run_keys):
    return {
        "run": {"end_time": 2e-5, **run_keys},
        "mesh": {"shape": "plate", "size": [0.02, 0.002, 1e-3], "element_size": 1e-3,
                 "cell": cell},
        "material": STEEL,
        "initial": {"velocity": [-200.0, 0.0, 0.0]},
        "wall": [{"kind": "plane", "point": [0.0, 0.0, 0.0], "normal_point": [1.0, 0.0, 0.0]}],
        "output": {"plot": False, "frames": 0},
    }  # fmt: skip


def _same_on_one_rank(sim, raw, directory, key):
    """The run on this communicator against the serial one: ``key`` of the summary and
    the energies of energy.csv (to 1e-10)."""
    if comm.size == 1:
        return
    serial = None
    if comm.rank == 0:
        alone = run(raw, directory, comm=MPI.COMM_SELF)
        serial = (key(alone.history.summary), alone.history.energy)
    value, table = comm.bcast(serial, root=0)
    assert key(sim.history.summary) == value
    mine = sim.history.energy
    assert mine.shape == table.shape
    assert np.abs(mine[:, 1:] - table[:, 1:]).max() <= 1e-10 * np.abs(table[:, 1:]).max()


@pytest.mark.parametrize("cell", ["quadrilateral", "triangle"])
def test_dt_min_erodes_the_crushed_shells(cell, shared_dir, tmp_path_factory):
    raw = crush_scene(cell)
    free = run(raw, shared_dir / "free").history.summary["time_step"]["smallest"]
    assert free < 0.8 * DT_MIN  # without control the step falls below dt_min
    raw = crush_scene(cell, dt_min=DT_MIN, dt_min_action="erode")
    sim = run(raw, shared_dir / "erode")
    summary = sim.history.summary
    energy = summary["energy"]
    print(f"{cell}: free {free:.4g} s; erode: smallest {summary['time_step']['smallest']:.4g} s,"
          f" {summary['erosion']['eroded_cells']} cells, balance {energy['max_balance_error']:.2e}")
    assert summary["status"] == "done"
    assert summary["time_step"]["smallest"] >= DT_MIN
    assert 0 < summary["erosion"]["eroded_cells"] < 40
    assert energy["eroded_internal"] > 0.0
    assert energy["max_balance_error"] <= 1e-12
    other = comm.bcast(tmp_path_factory.mktemp("serial") if comm.rank == 0 else None, root=0)
    _same_on_one_rank(sim, raw, other, lambda s: s["erosion"]["eroded_cells"])


@pytest.mark.parametrize("cell", ["quadrilateral", "triangle"])
def test_mass_scaling_holds_the_step_of_shells(cell, shared_dir, tmp_path_factory):
    raw = crush_scene(cell, dt_min=DT_MIN, dt_min_action="mass_scaling", max_added_mass=0.5)
    sim = build_simulation(parse_scene(copy.deepcopy(raw), source="test"), comm, shared_dir)
    at_rest = sim.internal.inertia.copy()  # kg, kg m^2
    sim.run()
    summary = sim.history.summary
    steps, energy = summary["time_step"], summary["energy"]
    body, s = sim.internal, sim.state
    print(f"{cell}: mass scaling: {steps['scaled_cells']} cells, "
          f"{steps['added_mass_percent']:.3g} % added, work {steps['mass_scaling_work']:.3e} J, "
          f"balance {energy['max_balance_error']:.2e}")
    assert summary["status"] == "done"
    assert steps["smallest"] == DT_MIN and 0 < steps["scaled_cells"] < 40
    assert 0.0 < steps["added_mass_percent"] < 50.0
    assert steps["mass_scaling_work"] < 0.0
    assert energy["max_balance_error"] <= 1e-12
    assert np.allclose(body.inertia[:, 0], s.mass, rtol=1e-14, atol=0)  # the masses, scaled
    grown = s.mass > at_rest[:, 0] * (1 + 1e-9)
    assert comm.allreduce(int(grown.sum())) > 0
    ratio = body.inertia[:, 1] / body.inertia[:, 0]
    assert np.allclose(ratio, at_rest[:, 1] / at_rest[:, 0], rtol=1e-12)  # I / m as at rest
    other = comm.bcast(tmp_path_factory.mktemp("serial") if comm.rank == 0 else None, root=0)
    _same_on_one_rank(sim, raw, other, lambda s: s["time_step"]["scaled_cells"])
