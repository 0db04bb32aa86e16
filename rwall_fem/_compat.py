"""The one place where DOLFINx 0.5 and DOLFINx 0.10+ differ.

Everything else in rwall_fem is written in the current DOLFINx idiom and
calls these helpers where a name or a signature changed. Importing this
module also puts ``dolfinx_solver`` (the PyPI wheel that bundles PETSc and
MPICH) before ``dolfinx`` and ``petsc4py`` when it is installed, as that
wheel requires.
"""

from __future__ import annotations

import importlib.util
import inspect

if importlib.util.find_spec("dolfinx_solver") is not None:
    import dolfinx_solver  # noqa: F401  (must precede dolfinx and petsc4py)

import dolfinx
import dolfinx.fem.petsc  # noqa: F401  (registers fem.petsc)
import numpy as np
from dolfinx import fem, plot

__all__ = [
    "DOLFINX_VERSION",
    "assemble_matrix",
    "cell_nodes",
    "create_vector",
    "expression",
    "scalar_space",
    "scatter_reverse_add",
    "model_to_mesh",
    "vector_space",
    "vtk_mesh",
]

DOLFINX_VERSION = dolfinx.__version__
_MODERN = hasattr(fem, "functionspace")


def vector_space(msh) -> fem.FunctionSpace:
    """Continuous piecewise-linear (P1/Q1) vector space of dimension gdim on ``msh``."""
    gdim = msh.geometry.dim
    if _MODERN:
        return fem.functionspace(msh, ("Lagrange", 1, (gdim,)))
    return fem.VectorFunctionSpace(msh, ("Lagrange", 1))


def vtk_mesh(V):
    """``(topology, cell_types, points)`` of the local cells of ``V``, for pyvista."""
    if _MODERN:
        return plot.vtk_mesh(V)
    return plot.create_vtk_mesh(V)


def cell_nodes(V) -> np.ndarray:
    """Node (block) indices of each local cell of ``V``: shape (num_cells, nodes_per_cell)."""
    dofs = V.dofmap.list
    if isinstance(dofs, np.ndarray):
        return dofs
    return dofs.array.reshape(-1, V.dofmap.dof_layout.num_dofs)


def model_to_mesh(model, comm, rank: int, gdim: int = 3):
    """Distribute a gmsh model built on ``rank``: ``(msh, cell_tags, facet_tags)``."""
    if _MODERN:
        from dolfinx.io import gmsh as gmshio

        data = gmshio.model_to_mesh(model, comm, rank, gdim=gdim)
        return data.mesh, data.cell_tags, data.facet_tags
    from dolfinx.io import gmshio

    return gmshio.model_to_mesh(model, comm, rank, gdim=gdim)


def assemble_matrix(form, mat_type: str):
    """Assemble the bilinear ``form`` into a new, assembled PETSc matrix of type ``mat_type``.

    ``mat_type`` is a PETSc type such as ``"baij"``; DOLFINx preallocates it from the
    form's sparsity pattern (converting an assembled AIJ matrix instead takes minutes
    at a million cells).
    """
    if "kind" in inspect.signature(fem.petsc.assemble_matrix).parameters:
        A = fem.petsc.assemble_matrix(form, kind=mat_type)
    else:
        A = fem.petsc.create_matrix(form, mat_type)
        fem.petsc.assemble_matrix(A, form)
    A.assemble()
    return A


def create_vector(V, form):
    """A ghosted PETSc vector for assembling the linear ``form`` whose test space is ``V``."""
    first = next(iter(inspect.signature(fem.petsc.create_vector).parameters))
    return fem.petsc.create_vector(V if first == "V" else form)


def scalar_space(msh, family: str = "DG", degree: int = 0) -> fem.FunctionSpace:
    """Scalar space, e.g. piecewise constants for cell data."""
    if _MODERN:
        return fem.functionspace(msh, (family, degree))
    return fem.FunctionSpace(msh, (family, degree))


def expression(expr, V) -> fem.Expression:
    """``expr`` compiled for interpolation into ``V``."""
    points = V.element.interpolation_points
    return fem.Expression(expr, points() if callable(points) else points)


def scatter_reverse_add(x) -> None:
    """Add the ghost entries of the DOLFINx vector ``x`` to their owners' entries."""
    from dolfinx import la

    x.scatter_reverse(la.InsertMode.add if hasattr(la, "InsertMode") else la.ScatterMode.add)
