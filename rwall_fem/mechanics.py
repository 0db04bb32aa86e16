"""The discretised solid: lumped mass, stable step, and the UFL forms of Hooke's law.

All arrays returned here hold the rank's *owned* nodes only, shape (n, 3) for
vectors, in the order of the function space's index map. The internal force is
computed by the element kernels (:mod:`rwall_fem.elements`); the UFL stress and
stiffness forms here are the references the tests and the field output use.
"""

from __future__ import annotations

import math

import numpy as np
import ufl
from dolfinx import fem
from mpi4py import MPI
from petsc4py import PETSc

from rwall_fem import _compat
from rwall_fem.scene import Material

__all__ = [
    "coordinate_pattern",
    "critical_time_step",
    "lumped_mass",
    "shortest_edge",
    "stiffness_form",
    "strain",
    "stress",
]

# Vertices joined by an edge, in DOLFINx's reference-cell numbering.
_EDGES = {
    "tetrahedron": [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)],
    "hexahedron": [
        (0, 1),
        (2, 3),
        (4, 5),
        (6, 7),  # x
        (0, 2),
        (1, 3),
        (4, 6),
        (5, 7),  # y
        (0, 4),
        (1, 5),
        (2, 6),
        (3, 7),  # z
    ],
}


def strain(u):
    """Small-strain tensor sym(grad u)."""
    return ufl.sym(ufl.grad(u))


def stress(u, material: Material):
    """Linear elastic (Hooke) Cauchy stress in Pa."""
    lmbda, mu = material.lame
    eps = strain(u)
    return 2.0 * mu * eps + lmbda * ufl.tr(eps) * ufl.Identity(len(u))


def lumped_mass(V, density, *, positive: bool = True) -> np.ndarray:
    """Row-sum lumped nodal masses (kg) of the owned nodes of ``V``, shape (n,), of the
    ``density`` (kg/m^3: a number, or a function of the cells, e.g. piecewise constant).

    Row sum equals vertex quadrature (HRZ) for P1 tetrahedra and Q1 hexahedra,
    so every mass is positive; anything else is refused (unless not ``positive``: the
    masses of a part of the body, zero away from it).
    """
    w = ufl.TestFunction(V)
    ones = ufl.as_vector([1.0] * V.mesh.geometry.dim)
    b = fem.petsc.assemble_vector(_compat.form(density * ufl.inner(ones, w) * ufl.dx))
    b.ghostUpdate(addv=PETSc.InsertMode.ADD, mode=PETSc.ScatterMode.REVERSE)
    mass = b.array.reshape(-1, V.dofmap.index_map_bs)[:, 0].copy()
    b.destroy()
    if not positive:
        return mass
    lowest = V.mesh.comm.allreduce(mass.min(initial=np.inf), op=MPI.MIN)
    if not lowest > 0.0:
        raise ValueError(
            f"lumped mass is not positive (min {lowest:g} kg): the element "
            f"{V.mesh.topology.cell_type.name} P1 is the only supported choice"
        )
    return mass


def stiffness_form(V, material: Material) -> fem.Form:
    """The compiled small-strain stiffness form a(u, w) = int sigma(u) : eps(w) dx on ``V``."""
    u, w = ufl.TrialFunction(V), ufl.TestFunction(V)
    return _compat.form(ufl.inner(stress(u, material), strain(w)) * ufl.dx)


class _ScaledStiffness:
    """The product y = M^-1/2 K M^-1/2 x of a PETSc shell matrix, K applied by the element
    kernels of a linear elastic force."""

    def __init__(self, force, mass: np.ndarray):
        self.force = force
        self.scale = np.repeat(1.0 / np.sqrt(mass), 3)

    def mult(self, mat, x, y):
        u = (x.getArray(readonly=True) * self.scale).reshape(-1, 3)
        y.setArray(self.force.forces(u).ravel() * self.scale)


def critical_time_step(force, mass: np.ndarray, coords: np.ndarray, comm: MPI.Comm) -> float:
    """Stable central-difference step 2/omega_max (s), omega_max^2 = lambda_max(M^-1 K).

    K is the small-strain stiffness that the linear elastic ``force`` (an
    :class:`~rwall_fem.elements.ElementForce`) applies cell by cell: no matrix is stored.
    The eigenvalue of the symmetric M^-1/2 K M^-1/2 comes from SLEPc on a shell
    operator, started from :func:`coordinate_pattern` of the owned nodes' coordinates
    ``coords`` (m) so that every partitioning finds the same value. ``mass``: lumped
    masses (kg) of the owned nodes.
    """
    from slepc4py import SLEPc

    size = (3 * len(mass), PETSc.DECIDE)
    A = PETSc.Mat().createPython((size, size), _ScaledStiffness(force, mass), comm=comm)
    A.setUp()
    start = A.createVecRight()
    start.array[:] = coordinate_pattern(coords).repeat(3) + 1.5
    eps = SLEPc.EPS().create(comm)
    eps.setOperators(A)
    eps.setProblemType(SLEPc.EPS.ProblemType.HEP)
    eps.setWhichEigenpairs(SLEPc.EPS.Which.LARGEST_REAL)
    eps.setDimensions(1)
    eps.setTolerances(1e-8, 2000)
    eps.setInitialSpace([start])
    eps.solve()
    converged = eps.getConverged() >= 1
    lambda_max = eps.getEigenvalue(0).real if converged else math.nan
    for obj in (eps, A, start):
        obj.destroy()
    if not lambda_max > 0.0:
        raise RuntimeError("the largest eigenvalue of M^-1 K did not converge")
    return 2.0 / math.sqrt(lambda_max)


def coordinate_pattern(X: np.ndarray) -> np.ndarray:
    """A value in [-1, 1] per point of ``X`` (n, 3) (m) that depends on its coordinates
    only: eigenvalue iterations started from it find the same value on any partitioning."""
    return np.sin(X @ np.array([12.9898, 78.233, 37.719]) * 1e3)


def shortest_edge(V, x: np.ndarray | None = None, chunk: int = 65536) -> float:
    """The shortest edge (m) of the owned cells of ``V`` on any rank, with the nodes at ``x``
    (rows of owned and ghost nodes; by default where the mesh puts them). The cells are
    taken ``chunk`` at a time, so that a million cells need no more than tens of MB."""
    if x is None:
        x = V.tabulate_dof_coordinates()
    cells = _compat.cell_nodes(V)[: V.mesh.topology.index_map(V.mesh.topology.dim).size_local]
    first, second = np.array(_EDGES[V.mesh.topology.cell_type.name]).T
    shortest = np.inf
    for start in range(0, len(cells), chunk):
        block = cells[start : start + chunk]
        d = x[block[:, first]] - x[block[:, second]]
        shortest = min(shortest, np.einsum("cei,cei->ce", d, d).min(initial=np.inf))
    return V.mesh.comm.allreduce(float(np.sqrt(shortest)), op=MPI.MIN)
