"""A body of several built-in shapes placed as separate pieces (``[mesh] shape = "pieces"``
with ``[[mesh.piece]]`` tables): a rod above a plate without a .geo.

Rank 0 meshes each piece with its own ``meshes/<shape>.geo`` and parameters in a gmsh
session of its own (as :func:`~rwall_fem.meshing.body_mesh` meshes one shape), turns it
into place, and puts every piece into one gmsh model of discrete entities; DOLFINx then
distributes it as it does any gmsh model. The pieces share no node: each is a region of
the body named after it (and ``<piece>_front``, ``<piece>_bottom_layer``,
``<piece>_top_layer`` when the piece has them), each face group ``<piece>_<group>``
(``rod_bottom``, ``plate_top``, ...). A ``[[part]]`` named after a piece takes it (its
``volumes`` default to its name), with its own material and initial velocity; pieces
touch each other only through a ``[[contact]]``.
"""

from __future__ import annotations

import importlib.resources
from pathlib import Path

import numpy as np

from rwall_fem import interrupts
from rwall_fem.meshing import (
    BodyMesh,
    Refinement,
    _gmsh_model,
    _GmshError,
    _sigint_kept,
    gmsh_module,
    model_to_body,
    shape_geometry,
    swept_parameters,
    turned,
)

__all__ = ["pieces_mesh"]


def _piece(gmsh, piece) -> dict:
    """Mesh ``piece`` (a :class:`~rwall_fem.scene.PieceSpec`) in a session of its own: its
    nodes (tags, coordinates in place) and, per named physical
    group, its dimension and cells by gmsh type."""
    geo, params = shape_geometry(piece)
    refine = None
    if piece.refine_point is not None:
        refine = Refinement(piece.refine_point, piece.refine_size, piece.refine_radius)
    params = swept_parameters(params, piece.origin, piece.axis, piece.element_size, piece.cell,
                              refine)  # fmt: skip
    argv = [""]
    for name, value in params.items():
        argv += ["-setnumber", name, repr(float(value))]
    gmsh.initialize(argv, readConfigFiles=False)
    try:
        shipped = importlib.resources.files("rwall_fem.meshes") / geo
        with importlib.resources.as_file(shipped) as path:
            _gmsh_model(Path(path))
        tags, x, _ = gmsh.model.mesh.getNodes()
        x = turned(np.asarray(x).reshape(-1, 3), piece.origin, piece.axis)
        groups = {}
        for dim, tag in sorted(gmsh.model.getPhysicalGroups(), reverse=True):  # regions first
            if dim < 2:
                continue
            cells: dict[int, list] = {}
            for entity in gmsh.model.getEntitiesForPhysicalGroup(dim, tag):
                for kind, _, nodes in zip(*gmsh.model.mesh.getElements(dim, entity), strict=True):
                    cells.setdefault(int(kind), []).append(np.asarray(nodes, dtype=np.int64))
            groups[gmsh.model.getPhysicalName(dim, tag)] = (dim, cells)
        # The nodes of the cells, numbered 1, 2, ... (DOLFINx 0.5 takes no node of no cell
        # between others: the centre of a circle)
        used = np.unique(np.concatenate([n for dim, kinds in groups.values() if dim == 3
                                         for nodes in kinds.values() for n in nodes]))  # fmt: skip
        tags = np.asarray(tags, dtype=np.int64)
        order = np.argsort(tags)
        x = x[order[np.searchsorted(tags, used, sorter=order)]]
        for _, kinds in groups.values():
            for kind, nodes in kinds.items():
                kinds[kind] = [np.searchsorted(used, n) + 1 for n in nodes]
        return {"tags": np.arange(1, len(used) + 1, dtype=np.int64), "x": x, "groups": groups}
    finally:
        gmsh.finalize()


def _region(piece: str, name: str) -> str:
    """The name in the body of the piece's region or face group ``name``."""
    return piece if name == "body" else f"{piece}_{name}"


def _model(gmsh, meshed: list[tuple[str, dict]]) -> tuple[dict[str, int], dict[str, int], int]:
    """Put the ``meshed`` pieces (name, :func:`_piece`) into the current session's model as
    discrete entities: (face groups, regions, cells)."""
    gmsh.model.add("pieces")
    groups, volumes, cells, node_offset, cell_tag = {}, {}, 0, 0, 1
    for name, piece in meshed:
        first = None
        for group, (dim, kinds) in piece["groups"].items():
            entity = gmsh.model.addDiscreteEntity(dim)
            if first is None:  # the piece's nodes live on its first entity
                first = (dim, entity)
                gmsh.model.mesh.addNodes(dim, entity, piece["tags"] + node_offset,
                                         piece["x"].ravel())  # fmt: skip
            for kind, nodes in kinds.items():
                nodes = np.concatenate(nodes) + node_offset
                per = gmsh.model.mesh.getElementProperties(kind)[3]
                count = len(nodes) // per
                tags = np.arange(cell_tag, cell_tag + count)
                gmsh.model.mesh.addElementsByType(entity, kind, tags, nodes)
                cell_tag += count
                cells += count if dim == 3 else 0
            tag = gmsh.model.addPhysicalGroup(dim, [entity])
            region = _region(name, group)
            gmsh.model.setPhysicalName(dim, tag, region)
            (volumes if dim == 3 else groups)[region] = tag
        node_offset += int(piece["tags"].max(initial=0))
    return groups, volumes, cells


def pieces_mesh(comm, pieces, max_cells: float | None = None) -> BodyMesh:
    """The body of ``pieces`` (the scene's :class:`~rwall_fem.scene.PieceSpec`, collective);
    :class:`~rwall_fem.meshing.MeshTooLarge` above ``max_cells`` cells, and a ValueError of
    one line, on every rank, for what gmsh refuses."""
    with interrupts.at_once(), _sigint_kept() as keep:
        gmsh = gmsh_module()
        groups, volumes, error, cells = None, None, None, 0
        running = False  # the session of the body's model
        if comm.rank == 0:
            meshed = []
            try:
                for piece in pieces:
                    meshed.append((piece.name, _piece(gmsh, piece)))
                    keep()
                gmsh.initialize([""], readConfigFiles=False)
                running = True
                keep()
                gmsh.option.setNumber("General.Terminal", 0)
                groups, volumes, cells = _model(gmsh, meshed)
            except _GmshError as err:
                error = f"mesh.piece[{len(meshed)}]: {err}"
            except Exception as err:  # gmsh raises plain Exceptions
                error = f"mesh.piece[{len(meshed)}]: gmsh: {' '.join(str(err).split())}"
        return model_to_body(gmsh, comm, (groups, volumes, error, cells), max_cells, running)
