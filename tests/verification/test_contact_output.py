"""Contact loads in the outputs: the nodal contact force and contact pressure in
``fields.xdmf``, and frames coloured by the contact pressure (rwall_fem/output/contact_loads.py).

A 4 mm steel cube drops at 2 m/s, sliding at 1 m/s, onto a clamped plate, with friction
(the block on a plate of test_contact.py). References independent of the code that makes
the fields:

- the balance of each side of the contact: the pressure written in ``fields.xdmf``,
  integrated over the block's lower face and over the plate's upper face at the
  snapshot's positions (X + u, read from the file; the test's own quadrature of the
  nodal values, a quarter of each face's area at each corner), equals the interface's
  normal force in ``contacts.csv`` at that step (the kernel's sum over the secondary
  nodes of both passes): each side gets all of the normal force, its own nodes' share
  directly and the other side's as the reaction on its segments. To 3e-5: the faces
  tilt by the strains (1e-4 rad or less), and the friction force (mu = 0.3 of the normal
  force) has a component mu x tilt along a node's normal (1e-6 seen);
- the contact force is 0 (exactly) at every node off those two faces, and so is the
  pressure; the block's forces sum to the normal force along z (Newton: what the
  block gets, the plate gives: the two sides' forces are equal and opposite to 1e-9);
- the same on 1 and 2 ranks (every rank computes the surface alike).
"""

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import run
from mpi4py import MPI
from test_contact import BLOCK, G, H, block_on_plate

from rwall_fem import build_simulation, parse_scene
from rwall_fem.scene import SceneError

READER = r"""
import sys
import meshio, numpy as np

path, out = sys.argv[1], sys.argv[2]
seen = {}
with meshio.xdmf.TimeSeriesReader(path) as reader:
    points, cells = reader.read_points_cells()
    seen["points"], seen["cells"] = points, cells[0].data
    for k in range(reader.num_steps):
        t, point_data, _ = reader.read_data(k)
        seen[f"{k}/t"] = t
        for name, values in point_data.items():
            seen[f"{k}/{name}"] = values
np.savez(out, **seen)
"""

# The faces of a hexahedron in the XDMF's (VTK's) vertex order, as DOLFINx writes it.
HEX_FACES = ((0, 1, 2, 3), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7))


def _read_back(path: Path) -> dict:
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMI", "PMIX"))}
    out = path.parent / "seen.npz"
    result = subprocess.run([sys.executable, "-c", READER, str(path), str(out)], env=env,
                            capture_output=True, text=True)  # fmt: skip
    assert result.returncode == 0, result.stderr[-2000:]
    return dict(np.load(out))


def _plane_faces(points, cells, z, above) -> np.ndarray:
    """The faces (rows of 4 point indices) of the hexahedra on the side ``above`` (bool) of
    the plane at height ``z`` (m) that lie in it."""
    centre = points[cells].mean(axis=1)[:, 2]
    cells = cells[(centre > z) == above]
    faces = np.concatenate([cells[:, list(f)] for f in HEX_FACES])
    return faces[np.all(np.abs(points[faces, 2] - z) <= 1e-9, axis=1)]


def _integral(x, pressure, faces) -> float:
    """The pressure integrated over the faces at x: a quarter of each face's area at each
    corner (N)."""
    p = x[faces]
    area = 0.5 * np.linalg.norm(np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 1]), axis=1)
    return float((pressure[faces].sum(axis=1) * area / 4).sum())


def _scene(directory):
    raw = block_on_plate(directory, (0, 0, -G), (1.0, 0, 0), 1.2e-5)
    raw["output"] |= {"fields": 7, "history_interval": 1}
    return raw


def test_the_contact_pressure_integrates_to_the_normal_force(shared_dir):
    sim = run(_scene(shared_dir), shared_dir)
    if MPI.COMM_WORLD.rank != 0:
        return
    seen = _read_back(Path(shared_dir) / "fields.xdmf")
    rows = np.loadtxt(Path(shared_dir) / "contacts.csv", delimiter=",", skiprows=1, ndmin=2)
    columns = (Path(shared_dir) / "contacts.csv").read_text().splitlines()[0].split(",")
    normal, time = rows[:, columns.index("normal_force")], rows[:, columns.index("time")]
    X, cells = seen["points"], seen["cells"]
    gap = 0.1 * H
    lower = _plane_faces(X, cells, gap * (1 + 1e-6), above=True)  # the block's lower face
    upper = _plane_faces(X, cells, 0.0, above=False)  # the plate's upper face
    assert len(lower) == (BLOCK / H) ** 2 and len(upper) == 12 * 8
    on_faces = np.zeros(len(X), bool)
    on_faces[np.unique(np.concatenate([lower, upper]))] = True
    snapshots = sorted(k for k in range(100) if f"{k}/t" in seen)
    assert len(snapshots) == 7
    touching = 0
    for k in snapshots:
        t, u = float(seen[f"{k}/t"]), seen[f"{k}/displacement"]
        force, pressure = seen[f"{k}/contact_force"], seen[f"{k}/contact_pressure"].ravel()
        row = np.flatnonzero(np.abs(time - t) <= 1e-9 * max(t, 1e-12))
        assert len(row) == 1, (t, time[:3])
        expected = float(normal[row[0]])
        # 0 off the faces (DOLFINx writes the nodal values through an interpolation:
        # round-off of 1e-15 of the largest)
        assert np.abs(force[~on_faces]).max() <= 1e-12 * np.abs(force).max(initial=0.0)
        assert np.abs(pressure[~on_faces]).max() <= 1e-12 * pressure.max(initial=0.0)
        assert pressure.min() >= -1e-12 * pressure.max(initial=0.0)
        x = X + u
        for faces in (lower, upper):
            assert _integral(x, pressure, faces) == pytest.approx(expected, rel=3e-5, abs=1e-9)
        block = np.unique(lower)
        plate = np.unique(upper)
        assert force[block].sum(axis=0) == pytest.approx(-force[plate].sum(axis=0), rel=1e-9,
                                                         abs=1e-9 * expected)  # fmt: skip
        touching += expected > 0.0
    assert touching >= 5  # the block is on the plate from the second snapshot on


def test_frames_are_coloured_by_the_contact_pressure(shared_dir):
    raw = _scene(shared_dir)
    raw["output"] |= {"fields": 0, "frames": 3, "color": "contact_pressure"}
    run(raw, shared_dir)
    if MPI.COMM_WORLD.rank != 0:
        return
    frames = Path(shared_dir) / "frames"
    assert len(list(frames.glob("frame_*.png"))) == 3
    last = np.load(frames / "data" / "frame_0002.npz")
    pressure = last["contact_pressure"]
    # About the block's weight under 10^4 g and its impact, over its face: MPa.
    assert pressure.max() > 1e5 and np.count_nonzero(pressure) < len(pressure) / 2


def test_contact_pressure_without_contact_is_one_line(shared_dir):
    raw = _scene(shared_dir)
    del raw["contact"]
    raw["output"] |= {"frames": 2, "color": "contact_pressure"}
    with pytest.raises(SceneError, match=r"output.color: 'contact_pressure' needs contact"):
        build_simulation(parse_scene(raw, source="test"), MPI.COMM_WORLD, shared_dir)
