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
- the same on 1 and 2 ranks (every rank computes the surface alike);
- on triangles (the block on the plate in tetrahedra; a punch of triangle shells on a
  plate of them): the pressure at each node in contact is its normal force over a third
  of the area of its triangles, computed here by hand from the file, to 1e-9; the
  tributary area is a third of h^2 / 2 per triangle at the node (1, 2, 3 or 6 of them on
  these structured meshes) to 1e-3.
"""

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import run
from mpi4py import MPI
from test_contact import BLOCK, G, H, block_on_plate, write_geo

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


# --- triangles: the faces of tetrahedra, and triangle shells ----------------------------

PUNCH_GEO = """h = 0.001;
Point(1) = {0, 0, 0, h};
ex[] = Extrude {0.012, 0, 0} { Point{1}; Layers{12}; };
ey[] = Extrude {0, 0.012, 0} { Line{ex[1]}; Layers{12}; };
Physical Surface("plate") = {ey[1]};
Physical Curve("edge") = {ex[1], ey[0], ey[2], ey[3]};
Point(101) = {0.00325, 0.00325, 0.001, h};
px[] = Extrude {0.005, 0, 0} { Point{101}; Layers{5}; };
py[] = Extrude {0, 0.005, 0} { Line{px[1]}; Layers{5}; };
Physical Surface("punch") = {py[1]};
"""


def _tetrahedra_scene(directory) -> dict:
    """The block on the plate of :func:`_scene` in tetrahedra: each hexahedron of the
    structured mesh split into 6 (gmsh's extrusion of the triangulated faces)."""
    raw = _scene(directory)
    path = Path(raw["mesh"]["file"])
    tets = path.with_name("block_on_plate_tets.geo")
    if MPI.COMM_WORLD.rank == 0:
        text = path.read_text().replace("Recombine Surface {f};\n", "")
        tets.write_text(text.replace(" Recombine; };", " };"))
    MPI.COMM_WORLD.Barrier()
    raw["mesh"]["file"] = str(tets)
    return raw


def _shell_scene(directory) -> dict:
    """A 5 x 5 mm steel punch of 1 mm triangle shells (1 mm thick) at 20 m/s onto a 12 x
    12 mm steel plate of 1 mm triangle shells (1 mm thick, its edges held), the punch's
    nodes a quarter cell off the plate's, 0.2 mm outside the gap (0.8 mm) at the start."""
    path = write_geo(directory, "punch.geo", PUNCH_GEO)
    return {
        "run": {"end_time": 2.5e-5},
        "mesh": {"file": str(path)},
        "material": {"model": "linear_elastic", "density": 7850.0, "young": 200e9,
                     "poisson": 0.3},
        "element": {"thickness": 1e-3},
        "part": [{"name": "plate"},
                 {"name": "punch", "initial": {"velocity": [0.0, 0.0, -20.0]}}],
        "boundary": [{"group": "edge", "velocity": [0.0, 0.0, 0.0]}],
        "contact": [{"main": ["plate"], "secondary": ["punch"], "friction": 0.3}],
        "output": {"plot": False, "fields": 6},
    }  # fmt: skip


TET_FACES = ((1, 2, 3), (0, 2, 3), (0, 1, 3), (0, 1, 2))


def _tet_faces(points, cells) -> np.ndarray:
    """The faces of the tetrahedra (rows of 3 point indices) in the planes z = 0 (the
    plate's top, from the cells below) and z = gap (the block's bottom, from above)."""
    faces = []
    centre = points[cells].mean(axis=1)[:, 2]
    for z, above in ((0.0, False), (0.1 * H * (1 + 1e-6), True)):
        mine = cells[(centre > z) == above]
        every = np.concatenate([mine[:, list(f)] for f in TET_FACES])
        faces.append(every[np.all(np.abs(points[every, 2] - z) <= 1e-9, axis=1)])
    return np.concatenate(faces)


@pytest.mark.parametrize("kind", ["tetrahedra", "triangle shells"])
def test_the_contact_pressure_on_triangles_is_the_force_over_a_third_of_the_areas(shared_dir, kind):
    """Triangle faces: at each node in contact, the pressure in ``fields.xdmf`` is the
    normal contact force over the node's tributary area, both computed here by hand from
    the file (the snapshot's positions X + u, its contact force, its triangles): the
    triangles of the flat contact around the node (the faces of the plate's top and of
    the block's bottom; every shell at a shell node), its normal their area-weighted
    normal, its area a third of each one's. To 1e-9 (the file's round-off is 1e-15; the
    code's sums go in another order). And the tributary area is a third of the node's
    triangles at rest, h^2 / 6 each (the structured meshes: 1 to 6 around a node), to
    1e-3 (the strains under the contact are below 1e-4)."""
    scene = _tetrahedra_scene if kind == "tetrahedra" else _shell_scene
    run(scene(shared_dir), shared_dir)
    if MPI.COMM_WORLD.rank != 0:
        return
    seen = _read_back(Path(shared_dir) / "fields.xdmf")
    X, cells = seen["points"], seen["cells"]
    faces = cells if cells.shape[1] == 3 else _tet_faces(X, cells)
    count = np.bincount(faces.ravel(), minlength=len(X))  # triangles at each node
    checked, kinds = 0, set()
    for k in sorted(k for k in range(100) if f"{k}/t" in seen):
        x = X + seen[f"{k}/displacement"]
        force, pressure = seen[f"{k}/contact_force"], seen[f"{k}/contact_pressure"].ravel()
        p = x[faces]
        area_vector = 0.5 * np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
        # Off the contact the file holds round-off (DOLFINx writes the nodal values
        # through an interpolation: 1e-15 of the largest)
        size = np.linalg.norm(force, axis=1)
        loaded = np.flatnonzero(size > 1e-12 * size.max(initial=0.0))
        largest = pressure.max(initial=0.0)
        assert set(loaded) <= set(np.flatnonzero(count))  # only nodes of those triangles
        for node in loaded:
            mine = area_vector[np.any(faces == node, axis=1)]
            mine *= np.sign(mine @ force[node])[:, None]  # turned to the force's side
            normal = mine.sum(axis=0) / np.linalg.norm(mine.sum(axis=0))
            tributary = np.linalg.norm(mine, axis=1).sum() / 3.0
            expected = abs(force[node] @ normal) / tributary
            close = pytest.approx(expected, rel=1e-9, abs=1e-12 * largest)
            assert pressure[node] == close, (k, node)
            assert tributary == pytest.approx(count[node] * H**2 / 6.0, rel=1e-3)
            checked += 1
            kinds.add(int(count[node]))
        off = np.setdiff1d(np.arange(len(X)), loaded)
        assert np.abs(pressure[off]).max(initial=0.0) <= 1e-12 * largest
    print(f"{kind}: {checked} nodal pressures checked, at nodes of {sorted(kinds)} triangles")
    assert checked >= 50 and len(kinds) >= 3
