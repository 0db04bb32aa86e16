"""Bodies from gmsh: the geometry files in ``meshes/`` or a user's .msh/.geo file.

The mesh is generated (or read) on rank 0 and distributed by DOLFINx. Named
gmsh physical groups travel with it as facet tags so that scenes can refer to
boundary node sets by name.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from mpi4py import MPI

from rwall_fem import _compat

__all__ = [
    "BodyMesh",
    "bar_mesh",
    "boundary_nodes",
    "coordinate_noise",
    "group_nodes",
    "perturb",
    "read_mesh",
    "rotation_to",
]

GEOMETRY_DIR = Path(__file__).resolve().parent.parent / "meshes"


@dataclass
class BodyMesh:
    """A distributed mesh with its named facet groups (name -> facet tag value)."""

    msh: object
    facet_tags: object = None
    groups: dict[str, int] = field(default_factory=dict)

    @property
    def num_cells(self) -> int:
        """Global number of cells."""
        imap = self.msh.topology.index_map(self.msh.topology.dim)
        return imap.size_global


def bar_mesh(
    comm: MPI.Comm, origin, size, element_size: float, cell: str, axis=(0.0, 0.0, 1.0)
) -> BodyMesh:
    """Rectangular bar ``meshes/bar.geo``: the box ``origin`` + [0, size] (m), turned about
    ``origin`` so that its own z axis points along ``axis``.

    ``cell`` is "hexahedron" or "tetrahedron"; layers are at most ``element_size`` (m) thick.
    """
    params = dict(zip(("x0", "y0", "z0"), origin, strict=True))
    params |= dict(zip(("lx", "ly", "lz"), size, strict=True))
    params |= {"h": element_size, "hexahedra": int(cell == "hexahedron")}
    body = read_mesh(comm, GEOMETRY_DIR / "bar.geo", params)
    x = body.msh.geometry.x
    x[:] = (x - origin) @ rotation_to(axis).T + origin
    return body


def rotation_to(axis) -> np.ndarray:
    """Rotation matrix (3, 3) that turns the z axis onto the direction ``axis``."""
    b = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    c = b[2]  # cos of the angle between z and b
    if c < -1 + 1e-12:
        return np.diag([1.0, -1.0, -1.0])  # half turn about x
    k = np.array([-b[1], b[0], 0.0])  # z x b, of length sin(angle)
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + K + K @ K / (1 + c)


def read_mesh(comm: MPI.Comm, path: Path, parameters: dict[str, float] | None = None) -> BodyMesh:
    """Mesh a gmsh ``.geo`` (with ``DefineConstant`` ``parameters``) or read a ``.msh``."""
    import gmsh

    groups = None
    if comm.rank == 0:
        argv = [""]
        for name, value in (parameters or {}).items():
            argv += ["-setnumber", name, repr(float(value))]
        gmsh.initialize(argv)
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.open(str(path))
        if len(gmsh.model.mesh.getElements(3)[0]) == 0:
            gmsh.model.mesh.generate(3)
        groups = {
            gmsh.model.getPhysicalName(dim, tag) or f"{dim}:{tag}": tag
            for dim, tag in gmsh.model.getPhysicalGroups()
            if dim == 2
        }
        if not any(dim == 3 for dim, _ in gmsh.model.getPhysicalGroups()):
            # DOLFINx reads only cells that belong to a physical group.
            gmsh.model.addPhysicalGroup(3, [t for _, t in gmsh.model.getEntities(3)])
    groups = comm.bcast(groups, root=0)
    try:
        msh, _, facet_tags = _compat.model_to_mesh(gmsh.model, comm, 0, gdim=3)
    finally:
        if comm.rank == 0:
            gmsh.finalize()
    return BodyMesh(msh, facet_tags, groups)


def boundary_nodes(V) -> np.ndarray:
    """Local node (block) indices of ``V`` on the exterior boundary of its mesh."""
    from dolfinx import fem, mesh

    msh = V.mesh
    tdim = msh.topology.dim
    msh.topology.create_connectivity(tdim - 1, tdim)
    facets = mesh.exterior_facet_indices(msh.topology)
    return fem.locate_dofs_topological(V, tdim - 1, facets)


def group_nodes(V, body: BodyMesh, name: str) -> np.ndarray:
    """Local node indices of ``V`` on the facets of the named physical group ``name``."""
    from dolfinx import fem

    fdim = body.msh.topology.dim - 1
    facets = body.facet_tags.find(body.groups[name])
    return fem.locate_dofs_topological(V, fdim, facets)


def coordinate_noise(ids: np.ndarray, amplitude: float, seed: int) -> np.ndarray:
    """Deterministic noise in [-amplitude, amplitude]^3 (m) for points with integer ``ids``.

    It depends only on (seed, id), so a node moves the same way on every
    partitioning: a counter-based hash (splitmix64) of seed, id and component.
    """
    ids = np.asarray(ids, dtype=np.uint64)
    with np.errstate(over="ignore"):
        salt = np.uint64(seed) * np.uint64(0x9E3779B97F4A7C15)
        keys = (ids[:, None] * np.uint64(3) + np.arange(3, dtype=np.uint64)) ^ salt
        z = keys + np.uint64(0x9E3779B97F4A7C15)
        z = (z ^ (z >> np.uint64(30))) * np.uint64(0xBF58476D1CE4E5B9)
        z = (z ^ (z >> np.uint64(27))) * np.uint64(0x94D049BB133111EB)
        z = z ^ (z >> np.uint64(31))
    unit = (z >> np.uint64(11)).astype(np.float64) / float(1 << 53)  # in [0, 1)
    return amplitude * (2.0 * unit - 1.0)


def perturb(body: BodyMesh, amplitude: float, seed: int) -> None:
    """Move every node of the mesh by :func:`coordinate_noise` of its input (gmsh) index."""
    x = body.msh.geometry.x
    ids = np.asarray(body.msh.geometry.input_global_indices, dtype=np.int64)
    x += coordinate_noise(ids, amplitude, seed)
