"""``histories.png``'s balance line: what ``energy.csv`` books, drawn whole."""

import numpy as np
from conftest import run
from mpi4py import MPI

from rwall_fem.output.plots import balance_curve


def test_the_balance_line_holds_every_stored_energy(shared_dir):
    """A cube of one-point hexahedra with viscous hourglass control on a sphere wall books
    hourglass energy beside K and U: the picture's line (every stored energy less every
    work) stays at the initial energy to 1e-12 of it, as the balance does; K + U less the
    works, the line drawn before, falls by the hourglass energy."""
    raw = {
        "run": {"end_time": 2e-4},
        "mesh": {"shape": "bar", "origin": [-0.006, -0.006, 1e-5], "size": [0.012] * 3,
                 "element_size": 0.002},  # fmt: skip
        "material": {"model": "linear_elastic", "density": 7850.0, "young": 210e9, "poisson": 0.3},
        "element": {"integration": "reduced", "hourglass": "viscous"},
        "initial": {"velocity": [0.0, 0.0, -5.0]},
        "wall": [{"kind": "sphere", "point": [0.0, 0.0, -0.002], "diameter": 0.004}],
        "output": {"plot": True, "history_interval": 10},
    }
    sim = run(raw, shared_dir)
    if MPI.COMM_WORLD.rank != 0:
        return
    energy = np.genfromtxt(shared_dir / "energy.csv", delimiter=",", names=True)
    initial = sim.history.summary["energy"]["initial"]
    assert energy["hourglass"][-1] > 1e-6 * initial
    assert np.abs(balance_curve(energy) - initial).max() < 1e-12 * initial
    before = energy["kinetic"] + energy["internal"] - energy["external_work"] - energy["wall_work"]
    assert initial - before[-1] > 0.5 * energy["hourglass"][-1]
    assert (shared_dir / "histories.png").stat().st_size > 0
