"""The main surface of a contact interface: the boundary faces of solid parts, or the
shells of shell parts, as segments.

A face of a part's cells is on the part's boundary when no other cell of the part holds
it (faces between two parts bonded by shared nodes belong to both parts' surfaces). Each
segment is oriented outward (its normal ``(p2 - p0) x (p3 - p1)``, or ``(p1 - p0) x (p2 -
p0)`` for a triangle, points away from its cell) and carries, from that cell at the start:

- the penalty stiffness of Radioss's TYPE7 for a solid main segment (Istf = 0 with the
  default Stfac): ``k0 = stiffness_scale x B A^2 / V`` (N/m), B = lambda + 2 mu / 3 the
  bulk modulus of the cell's material, A the face's area, V the cell's volume;
- the depth ``V / (2 A)`` (m, half the cell's height under the face): how far behind the
  face a node is still pushed out (deeper, it is taken for a node of the other side);
- its shortest edge (m): the default gap is 0.1 x the shortest of them (Radioss Gapmin).

A shell is a segment with both sides active (:func:`shell_surface`): its depth is
``-t / 2`` (negative: the kernel takes the distance to it unsigned; its magnitude is the
segment's share of a variable gap), its stiffness Radioss's for a shell main segment,
``k0 = stiffness_scale x E t`` (N/m: E Young's modulus of the shell's material, t its
thickness), its shortest edge the shortest side.

A face on a symmetry plane is not a segment (:func:`held_plane_faces`): a solid's boundary
face lying in a plane x_c = const (c = x, y or z) all of whose nodes a boundary condition
holds at zero velocity in c: the body goes on beyond it (its mirror image, or whatever
holds it), so nothing can come at it from outside, and a node of another body cut by the
same plane, sliding in that plane, would be taken as a whole gap inside it.

A shell is cut by a symmetry plane along its sides, not its faces, and stays a segment:
:func:`held_plane_sides` finds the sides on such planes (a side of one shell only, which
leaves the plane, lying in a plane x_c = const whose nodes a boundary condition holds at zero
velocity in c with their rotations about the two other axes held), whose nodes act with
their share of the whole node (:mod:`rwall_fem.contact`).

Every rank gets every segment of the interface, in global node numbers, sorted by their
nodes (the same on every rank); the interface keeps each rank's share of them
(:mod:`rwall_fem.contact.interface`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["Surface", "boundary_faces", "cell_faces", "held_plane_faces", "held_plane_sides",
           "part_surface", "once", "shell_segments", "shell_surface"]

# The faces of DOLFINx's reference cells as cycles of their vertices.
_FACES = {
    8: ((0, 1, 3, 2), (4, 5, 7, 6), (0, 1, 5, 4), (2, 3, 7, 6), (0, 2, 6, 4), (1, 3, 7, 5)),
    4: ((1, 2, 3, -1), (0, 2, 3, -1), (0, 1, 3, -1), (0, 1, 2, -1)),
}


@dataclass
class Surface:
    """Segments (rows of 4 global node numbers, -1 as the 4th of a triangle), their
    stiffness k0 (N/m, before the interface's scale), depth (m) and shortest edge (m)."""

    segments: np.ndarray
    stiffness: np.ndarray
    depth: np.ndarray
    edge: np.ndarray

    @property
    def nodes(self) -> np.ndarray:
        """The global numbers of the segments' nodes, sorted."""
        ids = self.segments.ravel()
        return np.unique(ids[ids >= 0])

    def __add__(self, other: Surface) -> Surface:
        return Surface(*(np.concatenate([a, b]) for a, b in zip(
            (self.segments, self.stiffness, self.depth, self.edge),
            (other.segments, other.stiffness, other.depth, other.edge), strict=True)))  # fmt: skip

    def select(self, keep: np.ndarray) -> Surface:
        """The segments where ``keep`` (a mask) is true."""
        return Surface(self.segments[keep], self.stiffness[keep], self.depth[keep], self.edge[keep])


def _area_vector(p: np.ndarray, triangle: np.ndarray) -> np.ndarray:
    """(faces, 3): the normal times the area of each face of corners p (faces, 4, 3)."""
    quad = np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 1])
    tri = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    return 0.5 * np.where(triangle[:, None], tri, quad)


def part_surface(body, k: int, comm) -> Surface:
    """The boundary faces of part ``k`` of ``body`` (a :class:`~rwall_fem.body.Body`), the
    same on every rank of ``comm`` (collective)."""
    return boundary_faces(*cell_faces(body, k), comm)


def cell_faces(body, k: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Every face of this rank's cells of part ``k``, cell after cell (row ``c x faces per
    cell + f``): its 4 global node numbers oriented outward of the cell, the same sorted
    (the face's key), and its k0 (N/m), depth (m) and shortest edge (m)."""
    force = body.elements[k]
    cells, X = force.cells, body.X
    faces = np.array(_FACES[cells.shape[1]])
    triangle_cells = cells.shape[1] == 4
    lmbda, mu = body.parts[k].material.lame
    bulk = lmbda + 2.0 * mu / 3.0
    imap = body.V.dofmap.index_map
    to_global = imap.local_to_global
    n, per = len(cells), len(faces)
    local = np.full((n, per, 4), -1, dtype=np.int64)
    for f, face in enumerate(faces):
        for c, vertex in enumerate(face):
            if vertex >= 0:
                local[:, f, c] = cells[:, vertex]
    local = local.reshape(-1, 4)
    triangle = np.full(len(local), triangle_cells)
    corners = X[np.where(local >= 0, local, local[:, :1])]  # (faces, 4, 3)
    centre = np.repeat(X[cells].mean(axis=1), per, axis=0)
    face_centre = np.where(triangle[:, None], corners[:, :3].mean(axis=1), corners.mean(axis=1))
    area_vector = _area_vector(corners, triangle)
    outward = np.einsum("ij,ij->i", area_vector, face_centre - centre) >= 0.0
    flipped = local.copy()
    flipped[:, 1:] = np.where(triangle[:, None], local[:, [2, 1, 3]], local[:, [3, 2, 1]])
    local = np.where(outward[:, None], local, flipped)
    # The cell's volume: the cones of its faces (triangles about their centres) to its centre.
    volume = np.zeros(n * per)
    for c in range(4):
        a, b = corners[:, c], corners[:, (c + 1) % 4]
        cone = np.abs(np.einsum("ij,ij->i", np.cross(a - face_centre, b - face_centre),
                                face_centre - centre)) / 6.0  # fmt: skip
        volume += np.where(triangle & (c == 3), 0.0, cone)
    volume = volume.reshape(n, per).sum(axis=1)
    if triangle_cells:  # the triangle's fan about its centre covers 3 of the 4 terms
        volume = np.abs(np.einsum("ij,ij->i", np.cross(X[cells[:, 1]] - X[cells[:, 0]],
                        X[cells[:, 2]] - X[cells[:, 0]]), X[cells[:, 3]] - X[cells[:, 0]])) / 6.0
    volume = np.repeat(volume, per)
    area = np.linalg.norm(area_vector, axis=1)
    edges = [np.linalg.norm(corners[:, (c + 1) % 4] - corners[:, c], axis=1) for c in range(4)]
    edge = np.minimum.reduce(edges[:2] + [np.where(triangle, np.linalg.norm(
        corners[:, 0] - corners[:, 2], axis=1), np.minimum(edges[2], edges[3]))])  # fmt: skip
    ids = np.where(local >= 0, to_global(np.where(local >= 0, local, 0).ravel().astype(np.int32)).reshape(-1, 4), -1)
    values = np.column_stack([bulk * area**2 / volume, 0.5 * volume / area, edge])
    return ids, np.sort(ids, axis=1), values


def boundary_faces(ids: np.ndarray, key: np.ndarray, values: np.ndarray, comm) -> Surface:
    """The faces (rows of :func:`cell_faces`) that one cell holds over all ranks of
    ``comm``, the same on every rank, sorted by their keys (collective)."""
    # The faces held once on this rank, then once over all ranks.
    _, first, counts = np.unique(key, axis=0, return_index=True, return_counts=True)
    once = np.sort(first[counts == 1])
    gathered = comm.allgather((ids[once], key[once], values[once]))
    ids = np.concatenate([g[0] for g in gathered]).reshape(-1, 4)
    key = np.concatenate([g[1] for g in gathered]).reshape(-1, 4)
    values = np.concatenate([g[2] for g in gathered]).reshape(-1, 3)
    _, first, counts = np.unique(key, axis=0, return_index=True, return_counts=True)
    keep = first[counts == 1]  # np.unique sorts by key: the same order on every rank
    return Surface(ids[keep], *values[keep].T.copy())


def held_plane_faces(surface: Surface, nodes: np.ndarray, x: np.ndarray,
                     held: np.ndarray) -> np.ndarray:
    """The axis c (0, 1, 2; -1 for none) of the symmetry plane each segment of ``surface``
    lies on: a plane x_c = const (its corners' x_c within 1e-9 of its shortest edge of each
    other) whose every node is held in c, and not every node in all three (a clamped face
    stays). ``nodes`` are sorted global numbers, ``x`` their positions (m, rows of 3),
    ``held`` their components held at zero velocity (rows of 3 booleans); a node not in
    ``nodes`` is free."""
    ids = surface.segments
    if not len(nodes):
        return np.full(len(ids), -1)
    ids = np.where(ids >= 0, ids, ids[:, :1])  # a triangle's 4th corner is its 1st
    rows = np.minimum(np.searchsorted(nodes, ids), len(nodes) - 1)
    found = (nodes[rows] == ids)[:, :, None]
    corners, fixed = x[rows], held[rows] & found  # (segments, 4, 3)
    spread = corners.max(axis=1) - corners.min(axis=1)
    flat = spread <= 1e-9 * surface.edge[:, None]
    on = flat & fixed.all(axis=1) & ~fixed.all(axis=(1, 2))[:, None]
    return np.where(on.any(axis=1), np.argmax(on, axis=1), -1)


def held_plane_sides(body, k: int, comm, held) -> tuple[Surface, np.ndarray]:
    """The sides of the shells of part ``k`` of ``body`` (a
    :class:`~rwall_fem.shells.body.ShellBody`) on symmetry planes, the same on every rank
    of ``comm`` (collective): each as a segment of 2 nodes (its 3rd and 4th -1, its
    stiffness and depth 0, its shell's shortest side), and the axis c of its plane. A side
    is on a plane x_c = const as a solid's face is (:func:`held_plane_faces`, ``held``: the
    nodes held in c, for shells those whose rotations about the two other axes are held
    too), its shell leaves the plane (a corner off it by more than 1e-9 of its shortest
    side: a sheet lying in the plane, held so, is clamped there, not cut) and no other
    shell of the part holds it (a line of a whole model held so is not a cut)."""
    ids, values = shell_segments(body, k)
    X = body.elements[k].X
    local = body.elements[k].cells
    corners = local.shape[1]
    edge = values[:, 2]
    x = X[local]  # (cells, corners, 3)
    spread = x.max(axis=1) - x.min(axis=1)  # (cells, 3)
    sides = np.full((len(ids) * corners, 4), -1, dtype=np.int64)
    sides[:, 0] = ids[:, :corners].ravel()
    sides[:, 1] = np.roll(ids[:, :corners], -1, axis=1).ravel()
    edges = np.repeat(edge, corners)
    zero = np.zeros_like(edges)
    axis = held_plane_faces(Surface(sides, zero, zero, edges), *held)
    leaves = np.repeat(spread, corners, axis=0)[np.arange(len(sides)), np.maximum(axis, 0)]
    on = (axis >= 0) & (leaves > 1e-9 * edges)
    shell = np.repeat(np.sort(ids, axis=1), corners, axis=0)  # each side's shell, its nodes
    gathered = comm.allgather((sides[on], axis[on], edges[on], shell[on]))
    sides = np.concatenate([g[0] for g in gathered]).reshape(-1, 4)
    axis = np.concatenate([g[1] for g in gathered]).astype(np.int64)
    edges = np.concatenate([g[2] for g in gathered])
    shell = np.concatenate([g[3] for g in gathered]).reshape(-1, 4)
    pair = np.sort(sides[:, :2], axis=1)
    # Each side of each shell once (a shell may be on several ranks), then the sides of one
    # shell only: a side between two shells is inside the model, not on its cut
    _, first = np.unique(np.column_stack([pair, shell]), axis=0, return_index=True)
    _, inverse, counts = np.unique(pair[first], axis=0, return_inverse=True, return_counts=True)
    first = first[counts[inverse.ravel()] == 1]
    zero = np.zeros(len(first))
    return Surface(sides[first], zero, zero, edges[first]), axis[first]


def once(ids: np.ndarray, values: np.ndarray, comm) -> Surface:
    """The segments ``ids`` (global numbers) with their stiffness, depth and edge
    (``values``, rows of 3) of every rank, in the order of their sorted nodes."""
    gathered = comm.allgather((ids, values))
    ids = np.concatenate([g[0] for g in gathered]).reshape(-1, 4)
    values = np.concatenate([g[1] for g in gathered]).reshape(-1, 3)
    key = np.sort(ids, axis=1)
    _, first = np.unique(key, axis=0, return_index=True)
    return Surface(ids[first], *values[first].T.copy())


def shell_surface(body, k: int, comm) -> Surface:
    """The shells of part ``k`` of ``body`` (a :class:`~rwall_fem.shells.body.ShellBody`)
    as two-sided segments, the same on every rank of ``comm`` (collective)."""
    return once(*shell_segments(body, k), comm)


def shell_segments(body, k: int) -> tuple[np.ndarray, np.ndarray]:
    """This rank's shells of part ``k`` of ``body`` as segments, cell after cell: their 4
    global node numbers (-1 as a triangle's 4th) and their k0 (N/m), depth (m) and
    shortest side (m)."""
    force = body.elements[k]
    cells, X = force.cells, force.X
    thickness = force.kernel.thickness
    material = body.parts[k].material
    local = np.full((len(cells), 4), -1, dtype=np.int64)
    local[:, : cells.shape[1]] = cells  # quadrilaterals counter-clockwise (the kernels')
    corners = X[np.where(local >= 0, local, local[:, :1])]
    triangle = local[:, 3] < 0
    sides = [np.linalg.norm(corners[:, (c + 1) % 4] - corners[:, c], axis=1) for c in range(4)]
    closing = np.linalg.norm(corners[:, 0] - corners[:, 2], axis=1)  # a triangle's third side
    edge = np.minimum.reduce([sides[0], sides[1], np.where(triangle, closing, sides[2]),
                              np.where(triangle, np.inf, sides[3])])  # fmt: skip
    to_global = body.V.dofmap.index_map.local_to_global
    ids = np.where(local >= 0, to_global(np.where(local >= 0, local, 0).ravel().astype(np.int32))
                   .reshape(-1, 4), -1)  # fmt: skip
    values = np.column_stack([float(material.young) * thickness, -0.5 * thickness, edge])
    return ids, values
