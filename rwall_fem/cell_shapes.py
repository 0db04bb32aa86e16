"""Cells that are not cells: flat, or turned inside out, before a mesh is made of them.

A hexahedron is valid when the Jacobian of its trilinear map is positive at its eight
corners (or negative at all eight: a mirrored cell, which the element forces turn), a
tetrahedron when its volume is not zero. A cell whose top face lies on its bottom face
has a Jacobian of zero at every corner; one whose nodes are out of order has corners of
both signs. Either would run into nonsense (a stable step of zero: "run.max_steps ...
3.84e+16 steps"), so the readers refuse it first, naming the cell: the deck reader by
element ID and line, the mesh reader by gmsh's element tag and region
(:mod:`rwall_fem.meshing`). The one-point hexahedra test the same corners as the body
deforms (``kernels/step.h``).

Corners are in gmsh's (and Radioss's) order: nodes 0-3 around the bottom face, 4-7 above
them. NumPy over all the cells at once, once per mesh.
"""

from __future__ import annotations

import numpy as np

__all__ = ["FLAT", "bad_cells"]

# Relative corner volume below which a corner is flat: det J_I / (the cell's box diagonal)^3.
FLAT = 1e-10

# The three neighbours of each corner of a hexahedron along its edges, in gmsh's order,
# as a right-handed triple at the corners of a cell of positive volume.
_HEX_EDGES = np.array([[1, 3, 4], [2, 0, 5], [3, 1, 6], [0, 2, 7],
                       [7, 5, 0], [4, 6, 1], [5, 7, 2], [6, 4, 3]])  # fmt: skip


def corner_volumes(x: np.ndarray) -> np.ndarray:
    """The Jacobian determinants (m^3, up to a factor 1/8) at the corners of cells whose
    corner coordinates (m) are ``x``, shape (cells, 8 or 4, 3): (cells, 8) for
    hexahedra, (cells, 1), six times the volume, for tetrahedra."""
    if x.shape[1] == 4:
        a = x[:, 1:] - x[:, :1]
        return np.einsum("ci,ci->c", a[:, 0], np.cross(a[:, 1], a[:, 2]))[:, None]
    a = x[:, _HEX_EDGES] - x[:, :, None, :]  # (cells, corner, edge, xyz)
    return np.einsum("cki,cki->ck", a[:, :, 0], np.cross(a[:, :, 1], a[:, :, 2]))


def bad_cells(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The cells (indices) among those of corners ``x`` (cells, 8 or 4, 3; m) that are
    flat or inside out, and for each the corner (0-7) where it is worst."""
    if not len(x):
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    det = corner_volumes(np.asarray(x, dtype=np.float64))
    size = np.linalg.norm(np.ptp(x, axis=1), axis=1)  # the diagonal of its box, m
    relative = det / (np.maximum(size, np.finfo(float).tiny) ** 3)[:, None]
    sign = np.where(np.median(relative, axis=1) < 0.0, -1.0, 1.0)[:, None]
    oriented = sign * relative
    bad = np.flatnonzero(~(oriented.min(axis=1) > FLAT))
    return bad, oriented[bad].argmin(axis=1)
