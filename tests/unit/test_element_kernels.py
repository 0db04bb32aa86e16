"""The compiled element kernels against UFL, the patch test and rigid motions.

References independent of the kernels: DOLFINx's assembly of the same forms
(UFL with the quadrature degree set to the kernel's rule: degree 2 is 2 x 2 x 2
Gauss points on hexahedra), the exact equality of full and one-point-plus-
physical-hourglass integration on parallelepipeds for linear elasticity, and
the zero force of a linear (patch test) or rigid displacement field. Every
comparison holds to round-off: 1e-12 relative to the largest force.
Runs serially and on 2 ranks (ghost nodes, reverse scatter).
"""

import os
import subprocess
import sys

import numpy as np
import pytest
import ufl
from dolfinx import fem, mesh
from mpi4py import MPI
from petsc4py import PETSc

from rwall_fem import _compat
from rwall_fem.elements import ElementForce, GhostedField, Technology
from rwall_fem.hyperelasticity import strain_energy_density
from rwall_fem.kernels import HOURGLASS
from rwall_fem.scene import Material

COMM = MPI.COMM_WORLD
MODELS = ("linear_elastic", "saint_venant_kirchhoff", "neo_hookean")
CELLS = ("tetrahedron", "hexahedron")
TOL = 1e-12


def unit_cube(cell, n=4, *, affine=None, distort=0.0):
    """Function space on a unit cube of n^3 cells (hexahedra, or 6 tetrahedra each), mapped
    by the matrix ``affine`` (a parallelepiped) or distorted inside (boundary nodes stay on
    the cube's faces) by ``distort`` times the cell size."""
    kind = mesh.CellType.hexahedron if cell == "hexahedron" else mesh.CellType.tetrahedron
    msh = mesh.create_unit_cube(COMM, n, n, n, kind)
    x = msh.geometry.x[:, :3]
    X0 = x.copy()
    if affine is not None:
        x[:] = X0 @ np.asarray(affine).T + 0.3
    if distort:
        bubble = 64.0 * np.prod(X0 * (1.0 - X0), axis=1)[:, None]
        waves = np.sin(5.0 * X0 @ np.array([[3.1, 1.7, 2.3], [1.3, 2.9, 0.7], [2.2, 0.4, 3.3]]))
        x += distort / n * bubble * waves
    return _compat.vector_space(msh)


def owned_coordinates(V):
    return V.tabulate_dof_coordinates()[: V.dofmap.index_map.size_local]


def material(model):
    return Material(model, density=7850.0, young=210e9, poisson=0.3)


def element_force(V, model, technology):
    return ElementForce(V, material(model), technology, GhostedField(V), GhostedField(V))


def ufl_force(V, model, u_owned):
    """Internal forces (N) on the owned nodes, assembled by DOLFINx from UFL, 2x2x2 points."""
    m = material(model)
    u = fem.Function(V)
    u.x.array[: u_owned.size] = u_owned.ravel()
    u.x.scatter_forward()
    w = ufl.TestFunction(V)
    dx = ufl.dx(metadata={"quadrature_degree": 2})
    if model == "linear_elastic":
        lmbda, mu = m.lame
        eps = ufl.sym(ufl.grad(u))
        sigma = 2 * mu * eps + lmbda * ufl.tr(eps) * ufl.Identity(3)
        residual = ufl.inner(sigma, ufl.sym(ufl.grad(w))) * dx
        energy = 0.5 * ufl.inner(sigma, eps) * dx
    else:
        F = ufl.variable(ufl.Identity(3) + ufl.grad(u))
        psi = strain_energy_density(F, m)
        residual = ufl.inner(ufl.diff(psi, F), ufl.grad(w)) * dx
        energy = psi * dx
    b = fem.petsc.assemble_vector(fem.form(residual))
    b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    f = b.array.reshape(-1, 3)[: len(u_owned)].copy()
    b.destroy()
    return f, COMM.allreduce(fem.assemble_scalar(fem.form(energy)))


def relative_error(a, b):
    scale = COMM.allreduce(np.abs(b).max(initial=0.0), op=MPI.MAX)
    return COMM.allreduce(np.abs(a - b).max(initial=0.0), op=MPI.MAX) / scale


@pytest.mark.parametrize("model", MODELS)
@pytest.mark.parametrize("cell", CELLS)
def test_full_integration_equals_ufl(cell, model):
    """Full integration (P1 tetrahedra, 2x2x2 Q1) equals DOLFINx's assembly of the UFL
    residual on a distorted mesh, at small strain (linear) or ~20 % strain (hyperelastic);
    the stored energy equals the assembled energy."""
    V = unit_cube(cell, distort=0.15)
    X = owned_coordinates(V)
    if model == "linear_elastic":
        u = 1e-3 * np.sin(7.0 * X @ np.array([[1.0, 2.0, 0.5], [0.3, 1.1, 2.0], [1.7, 0.2, 0.9]]))
    else:
        u = 0.15 * np.sin(3.0 * X) + 0.05 * np.cos(5.0 * X[:, ::-1])
    force = element_force(V, model, Technology.choose(cell, "full"))
    expected, energy = ufl_force(V, model, u)
    assert relative_error(force.forces(u), expected) < TOL
    stored, hourglass = force.stored_energy_at(u)
    assert abs(stored - energy) < TOL * abs(energy) and hourglass == 0.0


@pytest.mark.parametrize("model", MODELS)
def test_physical_hourglass_equals_full_integration_on_parallelepipeds(model):
    """On a mesh of parallelepipeds, one point + physical hourglass control equals 2x2x2
    integration exactly for linear elasticity; for the hyperelastic laws at small strain
    it agrees to the strain's order (the hourglass part is linear)."""
    V = unit_cube("hexahedron", affine=[[1.0, 0.3, 0.1], [0.2, 0.8, -0.2], [0.1, 0.15, 1.2]])
    X = owned_coordinates(V)
    u = 1e-7 * np.sin(7.0 * X @ np.array([[1.0, 2.0, 0.5], [0.3, 1.1, 2.0], [1.7, 0.2, 0.9]]))
    full = element_force(V, model, Technology.choose("hexahedron", "full")).forces(u)
    reduced = element_force(V, model, Technology.choose("hexahedron", "reduced", "physical"))
    error = relative_error(reduced.forces(u), full)
    assert error < (TOL if model == "linear_elastic" else 1e-5)


def all_technologies():
    yield "tetrahedron", Technology.choose("tetrahedron")
    yield "hexahedron", Technology.choose("hexahedron", "full")
    for hourglass in HOURGLASS:
        yield "hexahedron", Technology.choose("hexahedron", "reduced", hourglass)


@pytest.mark.parametrize(("cell", "technology"), list(all_technologies()))
def test_patch_linear_field_gives_no_interior_force(cell, technology):
    """A linear displacement field on a distorted mesh: zero force on every interior node,
    for every technology (the uniform gradient of the one-point hexahedron is exact)."""
    V = unit_cube(cell, distort=0.15)
    X = owned_coordinates(V)
    u = X @ np.array([[1.0, 2.0, -1.0], [0.5, -1.0, 3.0], [2.0, 1.0, 1.0]]).T * 1e-3
    f = element_force(V, "linear_elastic", technology).forces(u)
    interior = np.all((X > 1e-9) & (X < 1.0 - 1e-9), axis=1)
    assert COMM.allreduce(int(interior.sum())) == 27
    scale = COMM.allreduce(np.abs(f).max(initial=0.0), op=MPI.MAX)
    assert COMM.allreduce(np.abs(f[interior]).max(initial=0.0), op=MPI.MAX) < TOL * scale


@pytest.mark.parametrize(("cell", "technology"), list(all_technologies()))
def test_rigid_motions_give_no_force(cell, technology):
    """Small strain: a rigid translation plus an infinitesimal rotation gives zero force.
    Total Lagrangian: a finite rotation (60 degrees) gives zero force."""
    V = unit_cube(cell, distort=0.15)
    X = owned_coordinates(V)
    # The force of a unit strain sets the scale of round-off.
    stretch = element_force(V, "linear_elastic", technology).forces(X * [1.0, 0.0, 0.0])
    scale = COMM.allreduce(np.abs(stretch).max(initial=0.0), op=MPI.MAX)
    W = np.array([[0.0, -3.0, 2.0], [3.0, 0.0, -1.0], [-2.0, 1.0, 0.0]]) * 1e-4
    small = element_force(V, "linear_elastic", technology).forces(X @ W.T + [1e-3, 2e-3, 3e-3])
    assert COMM.allreduce(np.abs(small).max(initial=0.0), op=MPI.MAX) < TOL * scale
    c, s = np.cos(np.pi / 3), np.sin(np.pi / 3)
    R = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]) @ np.array(
        [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]]
    )
    for model in MODELS[1:]:
        rotated = element_force(V, model, technology).forces(X @ (R - np.eye(3)).T)
        assert COMM.allreduce(np.abs(rotated).max(initial=0.0), op=MPI.MAX) < TOL * scale


@pytest.mark.skipif(COMM.size > 1, reason="starts a Python process of its own")
def test_a_compiler_failure_is_one_line(tmp_path):
    """Without a working C compiler a run stops with one line naming what to install, and
    exit code 2."""
    from conftest import SCENE

    (tmp_path / "scene.toml").write_text(SCENE)
    env = os.environ | {"CC": str(tmp_path / "no-such-cc"), "RWALL_FEM_CACHE": str(tmp_path)}
    result = subprocess.run(
        [sys.executable, "-m", "rwall_fem", "check", "scene.toml"],
        env=env, cwd=tmp_path, capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert result.returncode == 2
    (line,) = result.stderr.strip().splitlines()
    assert line.startswith("rwall-fem: error: could not compile the element kernels")
    assert "install gcc" in line
