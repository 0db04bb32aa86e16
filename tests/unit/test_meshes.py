"""The gmsh bodies of meshes/: volumes, named faces, turning, refinement, layers, bad input.

References are analytic: the volume and face areas of a box, a cylinder and a plate with a
hole. The curved faces are meshed as inscribed polygons: a circle of radius r cut into
chords of length c (central angle theta = c / r to first order) loses the area fraction
1 - sin(theta)/theta ~ theta^2/6 = (c/r)^2/6 and the perimeter fraction
1 - sin(theta/2)/(theta/2) ~ (c/r)^2/24. gmsh makes the chords about the element size h;
the bounds below allow chords up to 1.25 h. Every figure is a global sum (allreduce), so
all ranks take the same decisions.
"""

import math
import subprocess
import sys

import numpy as np
import pytest
import ufl
from dolfinx import fem  # conftest imported rwall_fem first (MPI order of the PyPI wheel)
from mpi4py import MPI

from rwall_fem import SceneError, _compat, parse_scene
from rwall_fem.meshing import (
    Refinement,
    body_mesh,
    group_nodes,
    plate_mesh,
    plate_with_hole_mesh,
    read_mesh,
    rotation_to,
    round_bar_mesh,
)

comm = MPI.COMM_WORLD
CELLS = ("hexahedron", "tetrahedron")
CHORD = 1.25  # longest chord gmsh leaves on a circle, in element sizes


def integral(body, measure) -> float:
    """Global integral of 1 over ``measure`` (dx, or ds(tag)) on ``body``'s mesh."""
    one = fem.Constant(body.msh, 1.0)
    return comm.allreduce(fem.assemble_scalar(fem.form(one * measure)), op=MPI.SUM)


def volume(body) -> float:
    return integral(body, ufl.dx(domain=body.msh))


def area(body, name) -> float:
    ds = ufl.ds(domain=body.msh, subdomain_data=body.facet_tags)
    return integral(body, ds(body.groups[name]))


def group_points(body, name) -> np.ndarray:
    """Coordinates (m) of the local nodes of the named face group."""
    V = _compat.vector_space(body.msh)
    return V.tabulate_dof_coordinates()[group_nodes(V, body, name)]


def cell_diameters(body) -> tuple[np.ndarray, np.ndarray]:
    """(centroids, largest vertex distance) of the owned cells, in m."""
    V = _compat.vector_space(body.msh)
    cells = _compat.cell_nodes(V)[: body.msh.topology.index_map(3).size_local]
    x = V.tabulate_dof_coordinates()[cells]  # (cells, vertices, 3)
    gaps = np.linalg.norm(x[:, :, None, :] - x[:, None, :, :], axis=-1)
    return x.mean(axis=1), gaps.max(axis=(1, 2))


def global_mean(values) -> float:
    total, count = comm.allreduce(np.array([values.sum(), values.size], dtype=float))
    return total / count


# --- volumes and faces ---------------------------------------------------------


@pytest.mark.parametrize("cell", CELLS)
def test_plate_volume_faces_and_layers(cell):
    size, h = (0.03, 0.02, 0.003), 0.005
    body = plate_mesh(comm, (0.0, 0.0, 0.0), size, h, cell, layers=3)
    assert body.msh.topology.cell_type.name == cell
    lx, ly, t = size
    assert volume(body) == pytest.approx(lx * ly * t, rel=1e-12)
    assert area(body, "bottom") == pytest.approx(lx * ly, rel=1e-12)
    assert area(body, "top") == pytest.approx(lx * ly, rel=1e-12)
    assert area(body, "sides") == pytest.approx(2 * (lx + ly) * t, rel=1e-12)
    # three layers through the thickness: four planes of nodes
    z = np.unique(np.round(body.msh.geometry.x[:, 2] / t * 3, 9))
    planes = np.unique(np.concatenate(comm.allgather(z)))
    assert planes.tolist() == [0.0, 1.0, 2.0, 3.0]
    # without `layers`: the fewest layers at most h thick (one here)
    cells_of = {k: plate_mesh(comm, (0, 0, 0), size, h, cell, layers=k).num_cells for k in (0, 1)}
    assert cells_of[0] == cells_of[1] == body.num_cells // 3


@pytest.mark.parametrize("cell", CELLS)
def test_round_bar_volume_within_the_chord_error(cell):
    r, L, h = 0.005, 0.012, 0.002
    body = round_bar_mesh(comm, (0.0, 0.0, 0.0), r, L, h, cell)
    assert body.msh.topology.cell_type.name == cell
    loss = 1 - volume(body) / (math.pi * r**2 * L)
    assert 0 < loss <= (CHORD * h / r) ** 2 / 6
    # the end faces are the same polygon; the side is its perimeter times L
    assert 1 - area(body, "bottom") / (math.pi * r**2) == pytest.approx(loss, rel=1e-9)
    assert 1 - area(body, "top") / (math.pi * r**2) == pytest.approx(loss, rel=1e-9)
    side_loss = 1 - area(body, "sides") / (2 * math.pi * r * L)
    assert 0 < side_loss <= (CHORD * h / r) ** 2 / 24
    if comm.rank == 0:
        print(
            f"round bar {cell}: volume -{loss:.2%}, side -{side_loss:.2%}, {body.num_cells} cells"
        )


@pytest.mark.parametrize("cell", CELLS)
def test_plate_with_hole_volume_and_hole_area(cell):
    size, r, t, h = (0.04, 0.03, 0.002), 0.008, 0.002, 0.003
    offset = (0.004, -0.002)
    body = plate_with_hole_mesh(comm, (0.0, 0.0, 0.0), size, r, h, cell, hole_offset=offset)
    assert body.msh.topology.cell_type.name == cell
    lx, ly, _ = size
    hole = math.pi * r**2 * t
    excess = volume(body) - (lx * ly * t - hole)  # the polygonal hole is smaller
    assert 0 < excess <= hole * (CHORD * h / r) ** 2 / 6
    hole_loss = 1 - area(body, "hole") / (2 * math.pi * r * t)
    assert 0 < hole_loss <= (CHORD * h / r) ** 2 / 24
    assert area(body, "sides") == pytest.approx(2 * (lx + ly) * t, rel=1e-12)
    # the hole sits where asked: its nodes are at distance r from its centre
    centre = np.array([lx / 2 + offset[0], ly / 2 + offset[1]])
    x = group_points(body, "hole")
    worst = comm.allreduce(np.abs(np.hypot(*(x[:, :2] - centre).T) - r).max(initial=0), MPI.MAX)
    assert worst < 1e-12
    if comm.rank == 0:
        print(
            f"plate with hole {cell}: volume +{excess / hole:.2%} of the hole's, hole area"
            f" -{hole_loss:.2%}, {body.num_cells} cells"
        )


# --- turning -------------------------------------------------------------------


@pytest.mark.parametrize("cell", CELLS)
def test_axis_turns_the_body_and_keeps_its_volume(cell):
    r, L, h = 0.004, 0.01, 0.002
    origin = np.array([0.01, -0.02, 0.003])
    axis = np.array([1.0, -2.0, 2.0]) / 3.0
    straight = round_bar_mesh(comm, origin, r, L, h, cell)
    turned = round_bar_mesh(comm, origin, r, L, h, cell, axis=axis)
    assert volume(turned) == pytest.approx(volume(straight), rel=1e-12)
    top = (group_points(turned, "top") - origin) @ axis
    bottom = (group_points(turned, "bottom") - origin) @ axis
    sides = group_points(turned, "sides") - origin
    radial = np.linalg.norm(sides - np.outer(sides @ axis, axis), axis=1)
    errors = [np.abs(top - L), np.abs(bottom), np.abs(radial - r)]
    worst = comm.allreduce(max(e.max(initial=0.0) for e in errors), MPI.MAX)
    assert worst < 1e-12


def test_plate_turned_puts_its_top_face_along_the_axis():
    size = (0.02, 0.01, 0.002)
    axis = np.array([0.0, -1.0, 0.0])  # the plate stands up, its top facing -y
    body = plate_mesh(comm, (0.0, 0.0, 0.0), size, 0.005, "hexahedron", axis=axis, layers=2)
    assert volume(body) == pytest.approx(np.prod(size), rel=1e-12)
    top = group_points(body, "top")
    error = comm.allreduce(np.abs(top[:, 1] + size[2]).max(initial=0), MPI.MAX)
    assert error < 1e-12


# --- refinement ----------------------------------------------------------------


@pytest.mark.parametrize("cell", CELLS)
def test_refinement_makes_cells_near_the_point_smaller(cell):
    h, small = 0.005, 0.001
    point = np.array([0.01, 0.02, 0.001])
    refine = Refinement(tuple(point), small, 0.01)
    body = plate_mesh(comm, (0.0, 0.0, 0.0), (0.04, 0.04, 0.001), h, cell, layers=2, refine=refine)
    centres, diameters = cell_diameters(body)
    distance = np.hypot(*(centres[:, :2] - point[:2]).T)
    near = global_mean(diameters[distance < small])
    far = global_mean(diameters[distance > 0.01 + h])
    ratio = near / far
    if comm.rank == 0:
        print(f"plate {cell}: cells near / far {ratio:.3f} (refine_size / element_size 0.2)")
    assert 0.5 * small / h < ratio < 2 * small / h


@pytest.mark.parametrize("cell", CELLS)
def test_refinement_of_a_round_bar_in_three_directions(cell):
    # A point on the side, as where a bar lying across a curved wall touches it.
    r, L, h, small, radius = 0.006, 0.03, 0.003, 0.001, 0.006
    origin = np.zeros(3)
    axis = np.array([0.0, 1.0, 1.0]) / math.sqrt(2)
    point = origin + rotation_to(axis) @ np.array([r, 0.0, 0.012])
    refine = Refinement(tuple(point), small, radius)
    body = round_bar_mesh(comm, origin, r, L, h, cell, axis=axis, refine=refine)
    centres, diameters = cell_diameters(body)
    distance = np.linalg.norm(centres - point, axis=1)
    ratio = global_mean(diameters[distance < 1.5 * small]) / global_mean(
        diameters[distance > radius + h]
    )
    if comm.rank == 0:
        print(f"round bar {cell}: cells near / far {ratio:.3f} (refine_size / element_size 0.33)")
    assert 0.5 * small / h < ratio < 2 * small / h


def test_a_refined_hexahedral_bar_is_all_hexahedra_and_keeps_its_volume():
    raw = {
        "shape": "bar",
        "size": [0.006, 0.006, 0.02],
        "element_size": 0.002,
        "refine_point": [0.0, 0.0, 0.01],
        "refine_size": 0.001,
    }
    body = body_mesh(comm, _spec(raw))
    assert body.msh.topology.cell_type.name == "hexahedron"
    assert volume(body) == pytest.approx(0.006 * 0.006 * 0.02, rel=1e-12)
    assert set(body.groups) == {"bottom", "top", "sides"}


def test_a_mesh_of_mixed_cells_is_refused(tmp_path):
    # A cube of hexahedra next to a wedge of prisms: DOLFINx takes one cell type only.
    (tmp_path / "mixed.geo").write_text(
        "Point(1) = {0, 0, 0, 1}; Point(2) = {1, 0, 0, 1}; Point(3) = {1, 1, 0, 1};\n"
        "Point(4) = {0, 1, 0, 1}; Point(5) = {2, 0, 0, 1};\n"
        "Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4}; Line(4) = {4, 1};\n"
        "Line(5) = {2, 5}; Line(6) = {5, 3};\n"
        "Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};\n"
        "Curve Loop(2) = {5, 6, -2}; Plane Surface(2) = {2};\n"
        "Transfinite Curve{1, 2, 3, 4, 5, 6} = 2; Transfinite Surface{1}; Recombine Surface{1};\n"
        "Extrude {0, 0, 1} { Surface{1, 2}; Layers{1}; Recombine; }\n"
    )
    with pytest.raises(ValueError, match=r"mixed\.geo: mixed cells \(Hexahedron 8, Prism 6\)"):
        read_mesh(comm, tmp_path / "mixed.geo")


# --- scenes --------------------------------------------------------------------

MATERIAL = {"model": "linear_elastic", "density": 7850.0, "young": 210e9, "poisson": 0.3}


def _scene(mesh: dict) -> dict:
    return {"run": {"end_time": 1e-6}, "mesh": mesh, "material": dict(MATERIAL)}


def _spec(mesh: dict):
    return parse_scene(_scene(mesh), source="test").mesh


def test_scene_keys_reach_the_mesh():
    spec = _spec(
        {
            "shape": "plate_with_hole",
            "size": [0.04, 0.03, 0.002],
            "hole_radius": 0.005,
            "hole_offset": [0.001, 0.0],
            "layers": 2,
            "element_size": 0.004,
            "cell": "tetrahedron",
            "refine_point": [0.02, 0.015, 0.0],
            "refine_size": 0.002,
        }
    )
    assert spec.refine_radius == pytest.approx(4 * 0.004)  # the default
    body = body_mesh(comm, spec)
    assert body.msh.topology.cell_type.name == "tetrahedron"
    assert set(body.groups) == {"bottom", "top", "sides", "hole"}
    round_bar = _spec(
        {"shape": "round_bar", "radius": 0.003, "length": 0.01, "element_size": 0.002}
    )
    assert (round_bar.radius, round_bar.length, round_bar.cell) == (0.003, 0.01, "hexahedron")


BAR = {"shape": "bar", "size": [0.01, 0.01, 0.1], "element_size": 0.002}
ROUND = {"shape": "round_bar", "radius": 0.005, "length": 0.1, "element_size": 0.002}
PLATE = {"shape": "plate", "size": [0.1, 0.1, 0.002], "element_size": 0.005}
HOLED = {
    "shape": "plate_with_hole",
    "size": [0.1, 0.05, 0.002],
    "hole_radius": 0.01,
    "element_size": 0.005,
}


@pytest.mark.parametrize(
    "mesh, change, message",
    [
        (
            BAR,
            {"radius": 0.01},
            r"mesh\.radius: is not a key of a bar \(it belongs to a round_bar\)",
        ),
        (ROUND, {"size": [1, 1, 1]}, r"mesh\.size: is not a key of a round_bar"),
        (PLATE, {"hole_radius": 0.01}, r"mesh\.hole_radius: is not a key of a plate \(it belongs"),
        (BAR, {"layers": 2}, r"mesh\.layers: is not a key of a bar \(it belongs to a plate or"),
        (ROUND, {"length": None}, r"mesh\.length: missing"),
        (ROUND, {"radius": 0.0}, r"mesh\.radius: must be a finite number in \(0, inf\)"),
        (PLATE, {"layers": 0}, r"mesh\.layers: must be an integer >= 1, got 0"),
        (HOLED, {"hole_radius": 0.03}, r"mesh\.hole_radius: the hole .* does not fit in the"),
        (HOLED, {"hole_offset": [0.045, 0.0]}, r"it needs \|dx\| \+ r < lx/2"),
        (HOLED, {"hole_offset": [0.01]}, r"mesh\.hole_offset: must be 2 finite numbers"),
        (PLATE, {"refine_size": 0.001}, r"mesh\.refine_point: missing"),
        (
            PLATE,
            {"refine_point": [0, 0, 0], "refine_size": 0.005},
            r"mesh\.refine_size: must be a finite number in \(0, 0\.005\)",
        ),
        (
            PLATE,
            {"refine_point": [0, 0, 0], "refine_size": 1e-3, "refine_radius": -1.0},
            r"mesh\.refine_radius: must be a finite number in \(0, inf\)",
        ),
        (ROUND, {"refine_sise": 1e-3}, r"unknown key \(did you mean 'refine_size'\?\)"),
        (BAR, {"shape": "cylinder"}, r"mesh\.shape: must be one of 'bar', 'round_bar', 'plate'"),
        ({"file": "x.msh"}, {"radius": 0.01}, r"mesh\.radius: is not a key of a mesh file"),
    ],
)
def test_bad_mesh_keys_name_the_key(mesh, change, message):
    mesh = {k: v for k, v in (mesh | change).items() if v is not None}
    with pytest.raises(SceneError, match=message):
        parse_scene(_scene(mesh), source="bad.toml")


@pytest.mark.serial
def test_command_line_refuses_a_key_of_another_shape_in_one_line(tmp_path):
    (tmp_path / "scene.toml").write_text(
        '[run]\nend_time = 1e-6\n[mesh]\nshape = "plate"\nsize = [0.1, 0.1, 0.002]\n'
        'element_size = 0.005\n[material]\nmodel = "linear_elastic"\ndensity = 7850.0\n'
        "young = 210e9\npoisson = 0.3\n"
    )
    result = subprocess.run(
        [sys.executable, "-m", "rwall_fem", "check", "scene.toml", "--set", "mesh.radius=0.01"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert result.returncode == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and "mesh.radius: is not a key of a plate" in lines[0], result.stderr
    assert "Traceback" not in result.stderr
