"""Results do not depend on the number of ranks beyond round-off."""

import numpy as np
import pytest
from conftest import COLUMN, bar_scene, run
from mpi4py import MPI


@pytest.mark.skipif(MPI.COMM_WORLD.size == 1, reason="compares a partitioned run with a serial one")
@pytest.mark.parametrize("cell", ["hexahedron", "tetrahedron"])
def test_partitioned_run_equals_serial_run(cell, shared_dir, tmp_path):
    raw = bar_scene(elements=24, h=2e-3, axis=(1.0, -2.0, 2.0), cell=cell)
    raw["mesh"]["size"] = [6e-3, 4e-3, 48e-3]  # several cells across: a real partition
    parallel = run(raw, shared_dir)
    serial = run(raw, tmp_path, comm=MPI.COMM_SELF)
    assert parallel.state.dt == serial.state.dt
    e_par, e_ser = parallel.history.energy, serial.history.energy
    assert e_par.shape == e_ser.shape
    scale = serial.history.summary["energy"]["initial"]
    assert np.abs(e_par[:, 1:5] - e_ser[:, 1:5]).max() <= 1e-10 * scale
    w_par, w_ser = parallel.history.wall(0), serial.history.wall(0)
    contacts = COLUMN["contacts"]
    assert np.array_equal(w_par[:, contacts], w_ser[:, contacts])  # same nodes, same steps
    impulse = slice(COLUMN["impulse_x"], COLUMN["impulse_z"] + 1)
    scale = np.abs(w_ser[:, impulse]).max()
    assert np.abs(w_par[:, impulse] - w_ser[:, impulse]).max() <= 1e-10 * scale
