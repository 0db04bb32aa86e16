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

# gmsh's (Radioss's) order of the corners of a hexahedron -> the tensor order, where node
# I = b0 + 2 b1 + 4 b2 sits at xi_k = 2 b_k - 1.
_TENSOR = [0, 1, 3, 2, 4, 5, 7, 6]


def corner_volumes(x: np.ndarray) -> np.ndarray:
    """The Jacobian determinants (m^3, times 8) at the corners of cells whose corner
    coordinates (m) are ``x``, shape (cells, 8 or 4, 3): for hexahedra (cells, 8), the
    triple products E_0 . (E_1 x E_2) of the edges through each corner taken along +xi_k
    (corners in tensor order); for tetrahedra (cells, 1), six times the volume."""
    if x.shape[1] == 4:
        a = x[:, 1:] - x[:, :1]
        return _triple(a[:, 0], a[:, 1], a[:, 2])[:, None]
    t = x[:, _TENSOR].reshape(len(x), 2, 2, 2, 3)  # axes b2, b1, b0
    e0 = (t[:, :, :, 1] - t[:, :, :, 0])[:, :, :, None]  # by (b2, b1)
    e1 = (t[:, :, 1] - t[:, :, 0])[:, :, None]  # by (b2, b0)
    e2 = (t[:, 1] - t[:, 0])[:, None]  # by (b1, b0)
    return _triple(e0, e1, e2).reshape(len(x), 8)


def _triple(a, b, c):
    """a . (b x c) over the last axis (of length 3), broadcast over the others."""
    return (a[..., 0] * (b[..., 1] * c[..., 2] - b[..., 2] * c[..., 1])
            + a[..., 1] * (b[..., 2] * c[..., 0] - b[..., 0] * c[..., 2])
            + a[..., 2] * (b[..., 0] * c[..., 1] - b[..., 1] * c[..., 0]))  # fmt: skip


def bad_cells(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The cells (indices) among those of corners ``x`` (cells, 8 or 4, 3; m; gmsh's
    order) that are flat or inside out, and for each the corner (an index into its
    nodes) where it is worst. A cell whose corners are all negative is mirrored, not
    inside out."""
    if not len(x):
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    x = np.asarray(x, dtype=np.float64)
    det = corner_volumes(x)
    size = np.linalg.norm(x.max(axis=1) - x.min(axis=1), axis=1)  # its box's diagonal, m
    relative = det / (np.maximum(size, np.finfo(float).tiny) ** 3)[:, None]
    oriented = np.where(relative.sum(axis=1) < 0.0, -1.0, 1.0)[:, None] * relative
    bad = np.flatnonzero(~(oriented.min(axis=1) > FLAT))
    worst = oriented[bad].argmin(axis=1)
    return bad, np.asarray(_TENSOR)[worst] if x.shape[1] == 8 else worst
