"""The mesh of a deck as a gmsh file: its elements, in regions (the parts: gmsh physical
volumes, or physical surfaces of shells), and its node groups as face groups (of shells:
groups of their sides).

rwall_fem refers to node sets by the name of a gmsh physical surface group (a facet
tag of the DOLFINx mesh): a set is the nodes of its faces. A /GRNOD becomes the faces
of the elements (on the boundary or inside) whose nodes all belong to it; a group whose
nodes are not all on such faces cannot be written so and is refused, naming the nodes.
DOLFINx keeps one tag per facet, so groups that share faces are written as their
disjoint pieces ("atoms": the faces of the same groups), and a group is the list of its
atoms' names (``grnod_3``, ``grnod_3_7`` for the faces in both 3 and 7).

The file is MSH 2.2 text, with coordinates in metres written with 17 significant digits
(exactly the numbers the deck gives, in SI). Its node tags number the nodes of the
elements 1, 2, ... in the order of their IDs: DOLFINx 0.5 reads only tags without gaps,
and decks often number each part's nodes from its own start.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np

__all__ = ["WRITER", "FaceGroups", "face_groups", "write_msh"]

# What the files of write_msh are: part of the name of a deck's mesh in the cache, so that
# a change of the writer writes the meshes anew.
WRITER = "MSH 2.2; a physical volume (shells: surface) per region; node tags 1..N"

# The faces of gmsh's (and Radioss's) hexahedron and tetrahedron, by local node index.
_FACES = {
    "hexahedron": np.array(
        [[0, 3, 2, 1], [0, 1, 5, 4], [0, 4, 7, 3], [1, 2, 6, 5], [2, 3, 7, 6], [4, 5, 6, 7]]
    ),
    "tetrahedron": np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]),
    # Shells: the facets are the sides (a node set of a shell body is a union of sides).
    "quadrilateral": np.array([[0, 1], [1, 2], [2, 3], [3, 0]]),
    "triangle": np.array([[0, 1], [1, 2], [2, 0]]),
}
# gmsh's element types: cells; facets by their node count (quadrangles, triangles, lines)
_GMSH_TYPE = {"hexahedron": 5, "tetrahedron": 4, "quadrilateral": 3, "triangle": 2,
              4: 3, 3: 2, 2: 1}  # fmt: skip
_DIMENSION = {"hexahedron": 3, "tetrahedron": 3, "quadrilateral": 2, "triangle": 2}


@dataclass
class FaceGroups:
    """Disjoint face groups: ``atoms`` name -> faces (k, 4 or 3) of node IDs; ``of`` group
    ID -> the names of its atoms."""

    atoms: dict[str, np.ndarray]
    of: dict[int, list[str]]


def face_groups(cell: str, cells: np.ndarray, groups: dict[int, np.ndarray]) -> tuple[
    FaceGroups, dict[int, np.ndarray]
]:  # fmt: skip
    """The atoms of the node groups ``groups`` (ID -> node IDs) over the elements
    ``cells`` (node IDs), and per group the node IDs its faces do not reach (to refuse)."""
    if not groups:
        return FaceGroups({}, {}), {}
    local = _FACES[cell]
    faces = cells[:, local].reshape(-1, local.shape[1])
    key = np.sort(faces, axis=1)
    _, first = np.unique(key, axis=0, return_index=True)
    faces = faces[np.sort(first)]
    ids = list(groups)
    member = np.zeros((len(faces), len(ids)), dtype=bool)
    unreached = {}
    for j, gid in enumerate(ids):
        member[:, j] = np.isin(faces, groups[gid]).all(axis=1)
        reached = np.unique(faces[member[:, j]])
        unreached[gid] = np.setdiff1d(groups[gid], reached)
    signature = np.packbits(member, axis=1)
    used = member.any(axis=1)
    atoms: dict[str, np.ndarray] = {}
    of: dict[int, list[str]] = {gid: [] for gid in ids}
    if used.any():
        kinds, which = np.unique(signature[used], axis=0, return_inverse=True)
        which = which.ravel()
        for k, packed in enumerate(kinds):
            bits = np.unpackbits(packed)[: len(ids)].astype(bool)
            members = [ids[j] for j in np.flatnonzero(bits)]
            name = "grnod_" + "_".join(str(g) for g in members)
            atoms[name] = faces[used][which == k]
            for gid in members:
                of[gid].append(name)
    return FaceGroups(atoms, of), unreached


def write_msh(path: Path, node_ids: np.ndarray, coordinates: np.ndarray, cell: str,
              regions: dict[str, np.ndarray], groups: FaceGroups) -> None:  # fmt: skip
    """Write the nodes of the cells (m), the cells of each region (name -> cells: a
    physical volume of that name) and the face groups (physical surfaces named as the
    atoms) as MSH 2.2 text to ``path``, atomically."""
    used = np.unique(np.concatenate(list(regions.values())))
    order = np.argsort(node_ids)
    rows = order[np.searchsorted(node_ids[order], used)]
    names = list(groups.atoms)
    path = Path(path)
    partial = path.with_name(path.name + f".partial{os.getpid()}")
    with open(partial, "w", encoding="ascii") as out:
        out.write("$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$PhysicalNames\n")
        out.write(f"{len(names) + len(regions)}\n")
        dim = _DIMENSION[cell]
        for tag, name in enumerate(regions, start=1):
            out.write(f'{dim} {tag} "{name}"\n')
        for tag, name in enumerate(names, start=1):
            out.write(f'{dim - 1} {tag} "{name}"\n')
        out.write(f"$EndPhysicalNames\n$Nodes\n{len(used)}\n")
        table = np.column_stack([np.arange(1.0, len(used) + 1), coordinates[rows]])
        np.savetxt(out, table, fmt=["%d", "%.17g", "%.17g", "%.17g"])
        count = sum(len(c) for c in regions.values()) + sum(len(f) for f in groups.atoms.values())
        out.write(f"$EndNodes\n$Elements\n{count}\n")
        number = 1
        for tag, name in enumerate(names, start=1):
            faces = groups.atoms[name]
            _elements(out, number, _GMSH_TYPE[faces.shape[1]], tag, _tags(used, faces))
            number += len(faces)
        for tag, cells in enumerate(regions.values(), start=1):
            _elements(out, number, _GMSH_TYPE[cell], tag, _tags(used, cells))
            number += len(cells)
        out.write("$EndElements\n")
    os.replace(partial, path)


def _tags(used: np.ndarray, ids: np.ndarray) -> np.ndarray:
    """The gmsh node tags of the node IDs ``ids``: their places in ``used`` (sorted), from 1."""
    return np.searchsorted(used, ids) + 1


def _elements(out, first: int, kind: int, tag: int, nodes: np.ndarray) -> None:
    """Element lines: number, type, 2 tags (physical, elementary), node tags."""
    n = len(nodes)
    head = np.column_stack([np.arange(first, first + n), np.full((n, 4), [kind, 2, tag, tag])])
    np.savetxt(out, np.column_stack([head, nodes]), fmt="%d")
