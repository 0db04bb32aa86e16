"""The stable central-difference step, from the element kernels (no stored stiffness).

Central differences are stable for dt <= 2/omega_max, omega_max^2 the largest
eigenvalue of M^-1 K. :func:`critical_time_step` finds it with SLEPc on a shell
operator whose product is the kernels' internal force (linear elasticity with the
body's element technology: the tangent at rest of every material). The element
estimate (shortest edge / c_p) is reported beside it.
"""

from __future__ import annotations

import math

import numpy as np
from mpi4py import MPI
from petsc4py import PETSc

__all__ = ["critical_time_step", "start_vector"]


def start_vector(X: np.ndarray) -> np.ndarray:
    """A start vector (n, 3) for eigenvalue iterations that depends only on the node
    coordinates ``X`` (m), so that every partitioning finds the same eigenvalue."""
    return np.sin(X @ np.array([12.9898, 78.233, 37.719]) * 1e3)[:, None] * [1.0, -1.0, 1.0] + 1.5


class _ScaledStiffness:
    """The product y = M^-1/2 K M^-1/2 x, K applied by an element force (a PETSc shell)."""

    def __init__(self, force, mass: np.ndarray):
        self.force = force
        self.scale = np.repeat(1.0 / np.sqrt(mass), 3)

    def mult(self, mat, x, y):
        u = (x.getArray(readonly=True) * self.scale).reshape(-1, 3)
        y.setArray(self.force.forces(u).ravel() * self.scale)


def critical_time_step(force, mass: np.ndarray, X: np.ndarray, comm: MPI.Comm) -> float:
    """Stable step 2/omega_max (s) of the linear elastic ``force`` (an
    :class:`~rwall_fem.elements.ElementForce`) with lumped masses ``mass`` (kg, owned
    nodes), the owned nodes at ``X`` (m)."""
    from slepc4py import SLEPc

    size = (3 * len(mass), PETSc.DECIDE)
    A = PETSc.Mat().createPython((size, size), _ScaledStiffness(force, mass), comm=comm)
    A.setUp()
    start = A.createVecRight()
    start.setArray(start_vector(X).ravel())
    eps = SLEPc.EPS().create(comm)
    eps.setOperators(A)
    eps.setProblemType(SLEPc.EPS.ProblemType.HEP)
    eps.setWhichEigenpairs(SLEPc.EPS.Which.LARGEST_REAL)
    eps.setDimensions(1)
    eps.setTolerances(1e-8, 2000)
    eps.setInitialSpace([start])
    eps.solve()
    converged = eps.getConverged()
    lambda_max = eps.getEigenvalue(0).real if converged else math.nan
    for obj in (eps, A, start):
        obj.destroy()
    if not converged or not lambda_max > 0.0:
        raise RuntimeError("the largest eigenvalue of M^-1 K did not converge")
    return 2.0 / math.sqrt(lambda_max)
