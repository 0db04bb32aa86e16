"""Bodies of shells before their elements: surface meshes, lumped inertia, the rotations'
update.

References are closed forms: a rectangle's area and edges, a plate's mass rho t A and the
sum of Radioss's rotational inertias over the cells, sum rho t A_c (A_c / 6 + t^2 / 12);
central differences on w' = -M / I with a constant moment are exact (w linear in t), and
book the moment's work as the rotations' kinetic energy gained, to round-off. Every
figure is a global sum: the same on any number of ranks.
"""

import math
from pathlib import Path

import numpy as np
import pytest
import ufl
from dolfinx import fem  # conftest imported rwall_fem first (MPI order of the PyPI wheel)
from mpi4py import MPI

from rwall_fem import _compat
from rwall_fem.meshing import group_nodes, plate_surface_mesh, read_mesh
from rwall_fem.shells.inertia import cell_areas, lumped_inertia
from rwall_fem.solver import State

comm = MPI.COMM_WORLD
FILES = Path(__file__).resolve().parents[1] / "bad_scenes" / "files"


def total(value) -> float:
    return comm.allreduce(float(value))


def area(msh) -> float:
    return total(fem.assemble_scalar(_compat.form(fem.Constant(msh, 1.0) * ufl.dx(domain=msh))))


@pytest.mark.parametrize("cell", ["quadrilateral", "triangle"])
def test_plate_mid_surface(cell):
    """The plate 0.1 x 0.05 m, 4 mm thick, turned onto x: its mid-surface at x = 2 mm, the
    right cells, area and edges."""
    lx, ly, t, h = 0.1, 0.05, 0.004, 0.01
    body = plate_surface_mesh(comm, (0, 0, 0), (lx, ly, t), h, cell, axis=(1.0, 0.0, 0.0))
    msh = body.msh
    assert (msh.topology.dim, msh.geometry.dim) == (2, 3)
    assert msh.topology.cell_type.name == cell
    assert body.num_cells == 50 * (2 if cell == "triangle" else 1)
    assert area(msh) == pytest.approx(lx * ly, rel=1e-12)
    x = msh.geometry.x
    assert np.allclose(x[:, 0], t / 2, atol=1e-15)
    assert body.volumes == {"body": 1}
    V = _compat.vector_space(msh)
    owned = V.dofmap.index_map.size_local
    counts = {g: total(np.sum(group_nodes(V, body, g) < owned)) for g in body.groups}
    assert counts == {"side_x0": 6, "side_x1": 6, "side_y0": 11, "side_y1": 11}


def test_a_gmsh_file_of_surfaces_is_a_body_of_shells_with_its_parts():
    """two_panels.geo: two physical surfaces (parts) at a right angle, one physical curve."""
    body = read_mesh(comm, FILES / "two_panels.geo")
    msh = body.msh
    assert (msh.topology.dim, msh.geometry.dim) == (2, 3)
    assert msh.topology.cell_type.name == "quadrilateral"
    assert set(body.volumes) == {"floor", "wall"}
    assert set(body.groups) == {"free_edge"}
    assert area(msh) == pytest.approx(2e-4, rel=1e-12)
    owned = msh.topology.index_map(2).size_local
    tags = body.cell_tags
    kept = tags.indices < owned
    for name in ("floor", "wall"):
        assert total(np.sum(tags.values[kept] == body.volumes[name])) == 4


@pytest.mark.parametrize("cell", ["quadrilateral", "triangle"])
def test_lumped_mass_and_rotational_inertia(cell):
    """Mass rho t A of the plate; rotational inertia the sum of rho t A_c (A_c/6 + t^2/12);
    every node's inertia positive."""
    lx, ly, t, h, rho = 0.06, 0.04, 0.003, 0.01, 7800.0
    body = plate_surface_mesh(comm, (0, 0, 0), (lx, ly, t), h, cell, axis=(0.3, -0.2, 1.0))
    V = _compat.vector_space(body.msh)
    owned = body.msh.topology.index_map(2).size_local
    cells = np.asarray(_compat.cell_nodes(V))[:owned]
    inertia = lumped_inertia(V, cells, rho, t)
    assert total(inertia[:, 0].sum()) == pytest.approx(rho * t * lx * ly, rel=1e-12)
    a = h * h / (2 if cell == "triangle" else 1)  # every cell of the structured mesh
    cell_count = 24 * (2 if cell == "triangle" else 1)
    expected = cell_count * rho * t * a * (a / 6 + t * t / 12)
    assert total(inertia[:, 1].sum()) == pytest.approx(expected, rel=1e-12)
    assert comm.allreduce(float(inertia.min(initial=np.inf)), op=MPI.MIN) > 0.0
    areas = cell_areas(V.tabulate_dof_coordinates(), cells)
    assert np.allclose(areas, a, rtol=1e-12)


class _Moments:
    """The internal force of a test: no force, a constant moment on every node (N m)."""

    books_work = True
    labels = None

    def __init__(self, n, moment, inertia):
        self.nodal_force = np.zeros((n, 3))
        self.moments = np.tile(moment, (n, 1))
        self.inertia = np.column_stack([np.ones(n), inertia])
        self.alpha = -self.moments / inertia[:, None]
        self.w = type("Field", (), {"owned": np.zeros((n, 3))})()
        self.rotational_kinetic, self.rotational_sums = 0.0, (0.0, 0.0)
        self.work = 0.0

    def book(self, state, first, second):
        self.work += 0.5 * state.dt_velocity * (first + second + sum(self.rotational_sums))


def test_rotations_advance_by_central_differences():
    """w' = -M / I from w0: w^{n+1/2} = w0 - (n + 1/2) dt M / I once the first half step is
    taken as dt (v^{-1/2} = v0), and minus the moments' work is the rotational kinetic
    energy gained."""
    from rwall_fem.shells.update import ShellUpdate

    n, dt, steps = 5, 1e-6, 200
    inertia = np.linspace(1e-6, 2e-6, n)
    body = _Moments(n, np.array([0.0, 2e-3, -1e-3]), inertia)
    w0 = np.array([3.0, -1.0, 0.5])
    body.w.owned[:] = w0
    state = State(X=np.zeros((n, 3)), mass=np.ones(n), dt=dt)
    update = ShellUpdate(state, body)
    for step in range(steps):
        update(state)
        state.dt_previous, state.step, state.t = state.dt, step + 1, state.t + state.dt
    assert np.allclose(body.w.owned, w0 + steps * dt * body.alpha, rtol=0, atol=1e-12)
    kinetic0 = 0.5 * np.sum(inertia[:, None] * w0**2)
    w_old = body.w.owned - dt * body.alpha
    shadow = 0.5 * np.einsum("i,ij,ij->", inertia, w_old, body.w.owned)
    assert body.rotational_kinetic == pytest.approx(shadow, rel=1e-14)
    # The work of the internal moments at mid-step velocities, up to the first half of the
    # latest step, is what the rotations' shadow kinetic energy lost.
    work = body.work - 0.5 * dt * np.sum(body.moments * body.w.owned)
    assert abs(body.rotational_kinetic - kinetic0 + work) <= 1e-13 * kinetic0


@pytest.mark.parametrize("section", ["square", "circle"])
@pytest.mark.parametrize("cell", ["quadrilateral", "triangle"])
def test_tube_mid_surface_and_its_trigger(section, cell):
    """A tube of width 40 mm and length 0.1 m along (1, 1, 0): its area (4 w L, or the
    inscribed polygon of 4 ns chords of the circle), its ends, and the trigger dents: the
    last 20 mm moved by at most the amplitude, the rest and (square) the corners not."""
    from rwall_fem.meshing import rotation_to, tube_mesh

    w, length, h, amplitude, wavelength = 0.04, 0.1, 0.005, 5e-4, 0.02
    axis = (1.0, 1.0, 0.0)
    plain = tube_mesh(comm, (0, 0, 0), w, length, h, cell, section, axis)
    dented = tube_mesh(comm, (0, 0, 0), w, length, h, cell, section, axis,
                       trigger=(amplitude, wavelength))  # fmt: skip
    msh = plain.msh
    assert (msh.topology.dim, msh.geometry.dim) == (2, 3)
    assert msh.topology.cell_type.name == cell
    if section == "square":
        expected = 4 * w * length
    else:
        segments = 4 * math.ceil(math.pi * w / 4 / h - 1e-9)
        expected = segments * w * math.sin(math.pi / segments) * length
    assert area(msh) == pytest.approx(expected, rel=1e-12)
    assert set(plain.groups) == {"bottom", "top"}
    own = dented.msh.geometry.x @ rotation_to(axis)  # back in the tube's own frame
    rest = plain.msh.geometry.x @ rotation_to(axis)
    assert np.allclose(own[:, 2], rest[:, 2], atol=1e-15)  # dents move across the axis only
    moved = np.linalg.norm(own - rest, axis=1)
    largest = comm.allreduce(float(moved.max(initial=0.0)), op=MPI.MAX)
    assert 0.5 * amplitude < largest <= amplitude * (1 + 1e-12)
    assert np.all(moved[rest[:, 2] < length - wavelength - 1e-12] <= 1e-15)
    if section == "square":
        corners = np.isclose(np.abs(rest[:, 0]), w / 2) & np.isclose(np.abs(rest[:, 1]), w / 2)
        assert np.all(moved[corners] <= 1e-15)
