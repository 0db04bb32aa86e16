"""The lumped inertia of a shell body: each node's mass and rotational inertia.

A cell of area A, thickness t and density rho gives each of its n nodes (4 for a
quadrilateral, 3 for a triangle) the mass m = rho t A / n, and the rotational inertia
m (A / 6 + t^2 / 12): the t^2 / 12 of a thin lamina about its mid-surface, and A / 6 that
scales the rotations' inertia up so that they never set the stable step. Radioss's rule is
m (A / 9 + t^2 / 12); on a strip one cell wide its fastest mode (the nodes' rotations
against the transverse shear) is 12 % above the membrane's, unstable at dt_scale 0.9
(``docs/theory.md``, "Shell bodies"). One inertia about every axis: the nodes' rotations
are integrated in the global frame, where an inertia tensor would need turning with the
shell every step.

Everything here is vectorised over the cells, once, when the body is built.
"""

from __future__ import annotations

import numpy as np
from dolfinx import la

from rwall_fem import _compat

__all__ = ["cell_areas", "lumped_inertia", "rotational_inertia"]


def cell_areas(x: np.ndarray, cells: np.ndarray) -> np.ndarray:
    """The area (m^2) of each cell, its nodes (rows of ``cells``: 3 or 4 indices into
    ``x``, m, DOLFINx numbering) at ``x``: half the norm of the cross product of the
    triangle's edges, or of a quadrilateral's diagonals (its projected area when warped)."""
    p = x[cells]
    if cells.shape[1] == 3:
        normal = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    else:  # DOLFINx's quadrilateral: 0-1 along one side, 2-3 the opposite side
        normal = np.cross(p[:, 3] - p[:, 0], p[:, 2] - p[:, 1])
    return 0.5 * np.linalg.norm(normal, axis=1)


def rotational_inertia(mass, area, thickness):
    """The rotational inertia (kg m^2) of a node's ``mass`` (kg) from a cell of ``area``
    (m^2) and ``thickness`` (m): m (A / 6 + t^2 / 12)."""
    return mass * (area / 6.0 + thickness**2 / 12.0)


def lumped_inertia(V, cells: np.ndarray, density: float, thickness) -> np.ndarray:
    """(owned nodes, 2): the masses (kg) and rotational inertias (kg m^2) that the owned
    ``cells`` (rows of local node indices of ``V``) of one material of ``density``
    (kg/m^3) and ``thickness`` (m; one value, or one per cell) give the owned nodes, the
    shares of ghost nodes added on their owners (collective)."""
    x = V.tabulate_dof_coordinates()
    area = cell_areas(x, cells)
    t = np.broadcast_to(np.asarray(thickness, dtype=float), area.shape)
    share = density * t * area / cells.shape[1]
    inertia = rotational_inertia(share, area, t)
    rows = la.vector(V.dofmap.index_map, 2)
    sums = rows.array.reshape(-1, 2)
    size = len(sums)
    for column, per_node in enumerate((share, inertia)):
        weights = np.repeat(per_node, cells.shape[1])
        sums[:, column] = np.bincount(cells.ravel(), weights=weights, minlength=size)
    _compat.scatter_reverse_add(rows)
    return sums[: V.dofmap.index_map.size_local].copy()
