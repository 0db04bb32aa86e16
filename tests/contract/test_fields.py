"""fields.xdmf: one time series with every field, read back by meshio and by pyvista.

The readers run in a separate process (as the renderer does: VTK and h5py bring their
own libraries, which must not meet DOLFINx's in one process) on rank 0; the file is
written by every rank. The body flies free, so the displacement at t is v0 t at every
node and the velocity v0; a cell field that the test gives the internal force (a linear
function of the cell's centre, growing with t) checks that cell values land on their cells.
Checkpoints close the file between snapshots, so it goes through its rewrites for
DOLFINx's appends and back.
"""

import copy
import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
from conftest import bar_scene
from mpi4py import MPI

from rwall_fem import build_simulation, parse_scene

V0 = np.array([1.0, 2.0, -5.0])  # m/s
WEIGHTS = np.array([1.0, 2.0, 3.0])  # the test's cell field: (WEIGHTS . centre) t, m s

# Reads fields.xdmf (argv[1]) with meshio's time-series reader and with pyvista's XDMF
# reader; saves what each reader sees in argv[2] (npz).
READER = r"""
import json, sys
import meshio, numpy as np, pyvista

path, out = sys.argv[1], sys.argv[2]
seen = {}
with meshio.xdmf.TimeSeriesReader(path) as reader:
    points, cells = reader.read_points_cells()
    seen["meshio/points"], seen["meshio/cells"] = points, cells[0].data
    steps = [reader.read_data(k) for k in range(reader.num_steps)]
seen["meshio/t"] = [t for t, _, _ in steps]
for k, (t, point_data, cell_data) in enumerate(steps):
    for name, values in [*point_data.items(), *((n, v[0]) for n, v in cell_data.items())]:
        seen[f"meshio/{k}/{name}"] = values
reader = pyvista.get_reader(path)
seen["pyvista/t"] = reader.time_values
for k, t in enumerate(reader.time_values):
    reader.set_active_time_value(t)
    grid = reader.read()
    seen["pyvista/points"] = grid.points
    seen["pyvista/cells"] = grid.cells.reshape(grid.n_cells, -1)[:, 1:]
    for name in [*grid.point_data, *grid.cell_data]:
        seen[f"pyvista/{k}/{name}"] = grid[name]
np.savez(out, **seen)
print(json.dumps(sorted(seen)))
"""


def _run_with_a_cell_field(directory, count):
    raw = bar_scene(elements=6, h=2e-3, cell="hexahedron", wall=False, end_time=2e-6)
    raw["initial"]["velocity"] = V0.tolist()
    raw["output"]["fields"] = count
    raw["output"]["checkpoint_steps"] = 2  # each checkpoint closes the file; DOLFINx appends
    sim = build_simulation(parse_scene(copy.deepcopy(raw), source="test"), out=directory)
    internal = sim.internal
    centres = internal.X[internal.cells].mean(axis=1)  # owned cells, m
    internal.cell_fields = lambda state: {"plastic_strain": centres @ WEIGHTS * state.t}
    sim.run()
    return sim


def _read_back(path: Path) -> dict:
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMI", "PMIX"))}
    out = path.parent / "seen.npz"
    result = subprocess.run(
        [sys.executable, "-c", READER, str(path), str(out)],
        env=env,
        capture_output=True,
        text=True,
    )
    assert result.returncode == 0, result.stderr[-2000:]
    assert json.loads(result.stdout)  # the reader saw something
    return dict(np.load(out))


def test_one_time_series_with_every_field(shared_dir):
    count = 3
    sim = _run_with_a_cell_field(shared_dir, count)
    if MPI.COMM_WORLD.rank != 0:
        return
    path = Path(shared_dir) / "fields.xdmf"
    xml = path.read_text()
    assert 'xmlns:xi="http://www.w3.org/2001/XInclude"' in xml
    assert xml.count('CollectionType="Temporal"') == 1
    seen = _read_back(path)
    dt = sim.state.dt  # an elastic body: the step does not vary
    # At the first step at or after each requested time k end_time / (count - 1).
    times = [math.ceil(k * sim.end_time / (count - 1) / dt - 1e-9) * dt for k in range(count)]
    cells = sim.info["cells"]
    for reader in ("meshio", "pyvista"):
        assert np.allclose(seen[f"{reader}/t"], times, rtol=1e-12), reader
        X = seen[f"{reader}/points"]
        centres = X[seen[f"{reader}/cells"]].mean(axis=1)
        assert len(X) == sim.info["nodes"] and len(centres) == cells
        for k, t in enumerate(times):
            u = seen[f"{reader}/{k}/displacement"]
            assert np.allclose(u, V0 * t, rtol=1e-9, atol=1e-15), (reader, k)
            assert np.allclose(seen[f"{reader}/{k}/velocity"], V0, rtol=1e-9), (reader, k)
            mises = seen[f"{reader}/{k}/von_mises_stress"].ravel()
            assert len(mises) == cells and np.abs(mises).max() < 1e-3  # Pa: rigid motion
            strain = seen[f"{reader}/{k}/plastic_strain"].ravel()
            assert np.allclose(strain, centres @ WEIGHTS * t, rtol=1e-12, atol=1e-18)
