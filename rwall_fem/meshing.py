"""Bodies from gmsh: the built-in shapes (``meshes/*.geo``) or a user's .msh/.geo file.

The mesh is generated (or read) on rank 0 and distributed by DOLFINx. Named
gmsh physical groups travel with it: surfaces as facet tags, so that scenes can refer to
boundary node sets by name, and volumes as cell tags, so that a scene's parts can name
the regions they are made of (the built-in shapes have "body", and "front", or
"bottom_layer" and "top_layer", when asked for).
"""

from __future__ import annotations

import contextlib
import importlib.resources
import signal
import threading
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from mpi4py import MPI

from rwall_fem import _compat, interrupts
from rwall_fem.cell_shapes import bad_cells

__all__ = [
    "SURFACE_CELLS",
    "BodyMesh",
    "MeshTooLarge",
    "Refinement",
    "bar_mesh",
    "body_mesh",
    "boundary_nodes",
    "coordinate_noise",
    "group_nodes",
    "perturb",
    "plate_mesh",
    "plate_surface_mesh",
    "plate_with_hole_mesh",
    "read_mesh",
    "rotation_to",
    "round_bar_mesh",
    "tube_mesh",
]


# The cells of a surface mesh (topological dimension 2 in 3-D): a body of shells.
SURFACE_CELLS = ("quadrilateral", "triangle")


@dataclass
class BodyMesh:
    """A distributed mesh with its named facet groups (name -> facet tag value) and its
    named regions (name -> cell tag value; a body of your own without them is one
    region)."""

    msh: object
    facet_tags: object = None
    groups: dict[str, int] = field(default_factory=dict)
    cell_tags: object = None
    volumes: dict[str, int] = field(default_factory=dict)

    @property
    def num_cells(self) -> int:
        """Global number of cells."""
        imap = self.msh.topology.index_map(self.msh.topology.dim)
        return imap.size_global


@dataclass(frozen=True)
class Refinement:
    """Smaller cells near ``point`` (m, scene coordinates): the element size is ``size`` (m) at
    the point and grows linearly back to the body's element size over ``radius`` (m).

    A gmsh Threshold field in the body's section, and layers graded by the same law along
    the sweep of the bars (``meshes/refine.geo``).
    """

    point: tuple[float, float, float]
    size: float
    radius: float


class MeshTooLarge(ValueError):
    """gmsh made (or read) more cells than allowed; ``cells`` is how many."""

    def __init__(self, cells: int):
        super().__init__(f"{cells} cells")
        self.cells = cells


def body_mesh(comm: MPI.Comm, spec, max_cells: float | None = None) -> BodyMesh:
    """The body a scene's ``[mesh]`` table (a :class:`~rwall_fem.scene.MeshSpec`) describes;
    :class:`MeshTooLarge` when it has more than ``max_cells`` cells."""
    if spec.file is not None:
        return read_mesh(comm, spec.file, max_cells=max_cells)
    common = {"element_size": spec.element_size, "cell": spec.cell, "axis": spec.axis}
    common["max_cells"] = max_cells
    if spec.refine_point is not None:
        common["refine"] = Refinement(spec.refine_point, spec.refine_size, spec.refine_radius)
    if spec.shape in ("bar", "round_bar"):
        common["front"] = spec.front_length
    else:
        common["layers_at"] = (spec.bottom_layer, spec.top_layer)
    if spec.shape == "bar":
        return bar_mesh(comm, spec.origin, spec.size, **common)
    if spec.shape == "round_bar":
        return round_bar_mesh(comm, spec.origin, spec.radius, spec.length, **common)
    if spec.shape == "tube":
        trigger = (spec.trigger_amplitude, spec.trigger_wavelength)
        return tube_mesh(comm, spec.origin, spec.width, spec.length, spec.element_size,
                         spec.cell, spec.section, spec.axis, trigger, max_cells)  # fmt: skip
    if spec.shape == "plate" and spec.cell in SURFACE_CELLS:
        return plate_surface_mesh(comm, spec.origin, spec.size, spec.element_size, spec.cell,
                                  spec.axis, max_cells)  # fmt: skip
    if spec.shape == "plate":
        return plate_mesh(comm, spec.origin, spec.size, layers=spec.layers, **common)
    if spec.shape == "plate_with_hole":
        return plate_with_hole_mesh(
            comm,
            spec.origin,
            spec.size,
            spec.hole_radius,
            hole_offset=spec.hole_offset,
            layers=spec.layers,
            **common,
        )
    raise ValueError(f"unknown mesh shape {spec.shape!r}")


def bar_mesh(
    comm: MPI.Comm,
    origin,
    size,
    element_size: float,
    cell: str,
    axis=(0.0, 0.0, 1.0),
    refine: Refinement | None = None,
    max_cells: float | None = None,
    front: float = 0.0,
) -> BodyMesh:
    """Rectangular bar ``meshes/bar.geo``: the box ``origin`` + [0, size] (m), turned about
    ``origin`` so that its own z axis points along ``axis``.

    ``cell`` is "hexahedron" or "tetrahedron"; layers are at most ``element_size`` (m) thick.
    Structured unless ``refine`` is given (then an unstructured section swept in graded layers).
    Regions: "body", and with ``front`` > 0 the first ``front`` metres along its own z,
    "front".
    """
    params = _bar(size, front)
    return _swept_body(comm, "bar.geo", params, origin, axis, element_size, cell, refine, max_cells)


def round_bar_mesh(
    comm: MPI.Comm,
    origin,
    radius: float,
    length: float,
    element_size: float,
    cell: str,
    axis=(0.0, 0.0, 1.0),
    refine: Refinement | None = None,
    max_cells: float | None = None,
    front: float = 0.0,
) -> BodyMesh:
    """Cylinder ``meshes/round_bar.geo`` of ``radius`` and ``length`` (m): its own z axis from
    ``origin`` (the centre of its bottom face) turned onto ``axis``.

    The disc is meshed at ``element_size`` (quadrangles or triangles) and swept along the
    axis in layers at most ``element_size`` thick: hexahedra, or prisms split into tetrahedra.
    Regions: "body", and with ``front`` > 0 the first ``front`` metres of its length,
    "front".
    """
    params = _round_bar(radius, length, front)
    return _swept_body(
        comm, "round_bar.geo", params, origin, axis, element_size, cell, refine, max_cells
    )


def plate_mesh(
    comm: MPI.Comm,
    origin,
    size,
    element_size: float,
    cell: str,
    axis=(0.0, 0.0, 1.0),
    layers: int = 0,
    refine: Refinement | None = None,
    max_cells: float | None = None,
    layers_at: tuple[float, float] = (0.0, 0.0),
) -> BodyMesh:
    """Plate ``meshes/plate.geo``: the box ``origin`` + [0, size] (m) with the thickness
    ``size[2]`` along its own z, turned about ``origin`` so that its own z points along ``axis``.

    ``layers`` elements through the thickness (0: the fewest at most ``element_size`` thick).
    Regions: "body", and the layers of thicknesses ``layers_at`` (m; 0: none) at its bottom
    and top faces, "bottom_layer" and "top_layer".
    """
    params = _plate(size, layers, layers_at)
    return _swept_body(
        comm, "plate.geo", params, origin, axis, element_size, cell, refine, max_cells
    )


def plate_surface_mesh(
    comm: MPI.Comm,
    origin,
    size,
    element_size: float,
    cell: str,
    axis=(0.0, 0.0, 1.0),
    max_cells: float | None = None,
) -> BodyMesh:
    """The mid-surface of the plate of :func:`plate_mesh`, for shells
    (``meshes/plate_surface.geo``): the rectangle ``size[0]`` x ``size[1]`` (m) at half the
    thickness ``size[2]`` above ``origin``, turned about ``origin`` so that its own z points
    along ``axis``; ``cell`` "quadrilateral" (squares of side at most ``element_size``) or
    "triangle" (each square halved). Region "body"; edges "side_x0", "side_x1", "side_y0",
    "side_y1"."""
    params = dict(zip(("lx", "ly", "thickness"), size, strict=True))
    params |= {"quadrangles": int(cell == "quadrilateral")}
    origin = np.asarray(origin, dtype=float)
    params |= dict(zip(("x0", "y0", "z0"), origin, strict=True)) | {"h": element_size}
    with importlib.resources.as_file(
        importlib.resources.files("rwall_fem.meshes") / "plate_surface.geo"
    ) as path:
        body = read_mesh(comm, path, params, max_cells)
    x = body.msh.geometry.x
    x[:] = (x - origin) @ rotation_to(axis).T + origin
    return body


def tube_mesh(
    comm: MPI.Comm,
    origin,
    width: float,
    length: float,
    element_size: float,
    cell: str,
    section: str = "square",
    axis=(0.0, 0.0, 1.0),
    trigger: tuple[float, float] = (0.0, 0.0),
    max_cells: float | None = None,
) -> BodyMesh:
    """Thin-walled tube as a mid-surface, for shells (``meshes/tube.geo``): a ``section``
    "square" of side ``width`` or "circle" of diameter ``width`` (m), along its own z over
    ``length`` (m) from ``origin`` (the centre of its bottom end), turned about ``origin``
    onto ``axis``; ``cell`` "quadrilateral" or "triangle". Region "body"; ends "bottom" and
    "top".

    ``trigger`` = (amplitude, wavelength) (m; 0: none) dents the last wavelength before the
    top end, where a crush should start to fold: the wall moves along its normal by
    amplitude x sin(2 pi zeta) (zeta from 0 to 1 over that wavelength: one lobe in, one
    out), on a square's faces also x sin(pi xi) across the face (0 at the corners, which
    stay) with the sign alternating from face to face (the progressive folding mode of
    square tubes); a circle's whole ring moves (the concertina mode)."""
    params = {"width": width, "length": length, "section": int(section == "circle")}
    params |= {"quadrangles": int(cell == "quadrilateral"), "h": element_size}
    origin = np.asarray(origin, dtype=float)
    params |= dict(zip(("x0", "y0", "z0"), origin, strict=True))
    with importlib.resources.as_file(
        importlib.resources.files("rwall_fem.meshes") / "tube.geo"
    ) as path:
        body = read_mesh(comm, path, params, max_cells)
    x = body.msh.geometry.x
    amplitude, wavelength = trigger
    if amplitude > 0.0:
        x[:] = origin + _dented(x - origin, width, length, section, amplitude, wavelength)
    x[:] = (x - origin) @ rotation_to(axis).T + origin
    return body


def _dented(x: np.ndarray, width, length, section, amplitude, wavelength) -> np.ndarray:
    """The points ``x`` (m, the tube's own frame about its origin) with the trigger dents
    of :func:`tube_mesh`."""
    zeta = (x[:, 2] - (length - wavelength)) / wavelength
    wave = np.where((zeta > 0.0) & (zeta < 1.0), np.sin(2.0 * np.pi * zeta), 0.0)
    moved = x.copy()
    if section == "circle":
        radial = x[:, :2] / np.linalg.norm(x[:, :2], axis=1, keepdims=True)
        moved[:, :2] += (amplitude * wave)[:, None] * radial
        return moved
    a = 0.5 * width
    on_x = np.abs(np.abs(x[:, 0]) - a) <= np.abs(np.abs(x[:, 1]) - a)  # a face x = +-a
    across = np.where(on_x, x[:, 1], x[:, 0])  # from -a to a along the face
    # Faces x = +-a go out, faces y = +-a in (a lobe of one face beside the other's).
    sign = np.where(on_x, 1.0, -1.0)
    offset = sign * amplitude * wave * np.sin(np.pi * (across + a) / width)
    normal = np.where(on_x, 0, 1)
    rows = np.arange(len(x))
    moved[rows, normal] += offset * np.sign(x[rows, normal])
    return moved


def plate_with_hole_mesh(
    comm: MPI.Comm,
    origin,
    size,
    hole_radius: float,
    element_size: float,
    cell: str,
    axis=(0.0, 0.0, 1.0),
    hole_offset=(0.0, 0.0),
    layers: int = 0,
    refine: Refinement | None = None,
    max_cells: float | None = None,
    layers_at: tuple[float, float] = (0.0, 0.0),
) -> BodyMesh:
    """:func:`plate_mesh` with a circular through-hole (``meshes/plate_with_hole.geo``) of
    ``hole_radius`` (m), its centre ``hole_offset`` (m, own x and y) from the plate's centre.

    The faces of the hole are the group ``hole``.
    """
    params = _plate_with_hole(size, hole_radius, hole_offset, layers, layers_at)
    return _swept_body(
        comm, "plate_with_hole.geo", params, origin, axis, element_size, cell, refine, max_cells
    )


def _swept_body(comm, geo, params, origin, axis, element_size, cell, refine, max_cells) -> BodyMesh:
    """Mesh ``meshes/<geo>`` in the body's own frame and turn it about ``origin`` onto ``axis``."""
    params = swept_parameters(params, origin, axis, element_size, cell, refine)
    # Shipped as the package rwall_fem.meshes (the repository's meshes/ folder); gmsh reads
    # the file from disk and finds its Include "refine.geo" beside it.
    with importlib.resources.as_file(importlib.resources.files("rwall_fem.meshes") / geo) as path:
        body = read_mesh(comm, path, params, max_cells)
    x = body.msh.geometry.x
    x[:] = turned(x, origin, axis)
    return body


def turned(x: np.ndarray, origin, axis) -> np.ndarray:
    """Points ``x`` (n, 3) of a body's own frame turned about ``origin`` onto ``axis`` (m)."""
    origin = np.asarray(origin, dtype=float)
    return (x - origin) @ rotation_to(axis).T + origin


def swept_parameters(params, origin, axis, element_size, cell, refine) -> dict[str, float]:
    """The gmsh parameters of a swept shape's .geo: its own ``params``, and where it is, its
    element size, cell and refinement in its own frame."""
    origin = np.asarray(origin, dtype=float)
    R = rotation_to(axis)
    params = dict(params) | dict(zip(("x0", "y0", "z0"), origin, strict=True))
    params |= {"h": element_size, "hexahedra": int(cell == "hexahedron"), "refine_size": 0}
    if refine is not None:
        # The .geo works in the body's own frame: take the point back there.
        own = (np.asarray(refine.point, dtype=float) - origin) @ R + origin
        params |= dict(zip(("refine_x", "refine_y", "refine_z"), own, strict=True))
        params |= {"refine_size": refine.size, "refine_radius": refine.radius}
    return params


def shape_geometry(spec) -> tuple[str, dict[str, float]]:
    """The .geo of ``meshes/`` and its own parameters for the swept built-in shape of
    ``spec`` (a [mesh] table or a piece: bar, round_bar, plate, plate_with_hole)."""
    layers_at = (spec.bottom_layer, spec.top_layer)
    if spec.shape == "bar":
        return "bar.geo", _bar(spec.size, spec.front_length)
    if spec.shape == "round_bar":
        return "round_bar.geo", _round_bar(spec.radius, spec.length, spec.front_length)
    if spec.shape == "plate":
        return "plate.geo", _plate(spec.size, spec.layers, layers_at)
    if spec.shape == "plate_with_hole":
        return "plate_with_hole.geo", _plate_with_hole(
            spec.size, spec.hole_radius, spec.hole_offset, spec.layers, layers_at
        )
    raise ValueError(f"not a swept solid shape: {spec.shape!r}")


def _bar(size, front) -> dict[str, float]:
    return dict(zip(("lx", "ly", "lz"), size, strict=True)) | {"front": front}


def _round_bar(radius, length, front) -> dict[str, float]:
    return {"radius": radius, "length": length, "front": front}


def _plate(size, layers, layers_at) -> dict[str, float]:
    params = dict(zip(("lx", "ly", "thickness"), size, strict=True)) | {"layers": layers}
    return params | dict(zip(("bottom_layer", "top_layer"), layers_at, strict=True))


def _plate_with_hole(size, hole_radius, hole_offset, layers, layers_at) -> dict[str, float]:
    params = _plate(size, layers, layers_at) | {"hole_radius": hole_radius}
    return params | dict(zip(("hole_dx", "hole_dy"), hole_offset, strict=True))


def rotation_to(axis) -> np.ndarray:
    """Rotation matrix (3, 3) that turns the z axis onto the direction ``axis``."""
    b = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    c = b[2]  # cos of the angle between z and b
    if c < -1 + 1e-12:
        return np.diag([1.0, -1.0, -1.0])  # half turn about x
    k = np.array([-b[1], b[0], 0.0])  # z x b, of length sin(angle)
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + K + K @ K / (1 + c)


def read_mesh(
    comm: MPI.Comm,
    path: Path,
    parameters: dict[str, float] | None = None,
    max_cells: float | None = None,
) -> BodyMesh:
    """Mesh a gmsh ``.geo`` (with ``DefineConstant`` ``parameters``) or read a ``.msh``.

    Rank 0 runs gmsh alone; whatever goes wrong there (a syntax error, a file that is not
    a mesh, no cells, mixed cell types, more than ``max_cells`` cells: a
    :class:`MeshTooLarge`) reaches every rank as the same ``ValueError`` of one line,
    before any collective call that the others would wait in for ever.

    Nothing here needs undoing: a stop signal ends the process at once
    (:func:`rwall_fem.interrupts.at_once`), even while gmsh's C code runs.
    """
    with interrupts.at_once(), _sigint_kept() as keep:
        return _read_mesh(comm, path, parameters, max_cells, keep)


def gmsh_module():
    """The gmsh module, imported without losing the SIGINT handler in place."""
    with _sigint_kept() as keep:
        import gmsh

        keep()
    return gmsh


@contextlib.contextmanager
def _sigint_kept():
    """Keep the SIGINT handler of the main thread, which gmsh sets to end the process at
    once and silently when it is imported (4.8: before it loads its library, which takes
    seconds on a loaded machine) or initialised (4.15), putting back on finalize what it
    found then. In this block gmsh's calls to set it change nothing (they are answered with
    the handler in place), so that no Ctrl-C finds it unset; yields a function that puts
    the handler back now, whatever else changed it."""
    main = threading.current_thread() is threading.main_thread()
    handler = signal.getsignal(signal.SIGINT) if main else None
    real = signal.signal

    def unchanged(number, action):
        if number == signal.SIGINT:
            return signal.getsignal(signal.SIGINT)
        return real(number, action)

    def keep():
        if handler is not None:
            real(signal.SIGINT, handler)

    if main:
        signal.signal = unchanged
    try:
        yield keep
    finally:
        signal.signal = real
        keep()


def _read_mesh(comm, path, parameters, max_cells, keep) -> BodyMesh:
    gmsh = gmsh_module()
    groups, volumes, error, cells = None, None, None, 0
    if comm.rank == 0:
        argv = [""]
        for name, value in (parameters or {}).items():
            argv += ["-setnumber", name, repr(float(value))]
        gmsh.initialize(argv, readConfigFiles=False)
        keep()
        try:
            groups, volumes, dim = _gmsh_model(Path(path))
            cells = sum(len(tags) for tags in gmsh.model.mesh.getElements(dim)[1])
        except _GmshError as err:
            error = f"{Path(path).name}: {err}"
        except UnicodeDecodeError:  # gmsh's own message quotes the file's bytes
            error = f"{Path(path).name}: gmsh cannot read it: not a mesh or a geometry file"
        except Exception as err:  # gmsh raises plain Exceptions, naming the file
            error = " ".join(str(err).replace(f"'{path}', ", "").split())
            error = f"{Path(path).name}: gmsh cannot read it: {error}"
    return model_to_body(gmsh, comm, (groups, volumes, error, cells), max_cells,
                         running=comm.rank == 0)


def model_to_body(gmsh, comm, found: tuple, max_cells: float | None, running: bool) -> BodyMesh:
    """The model gmsh holds on rank 0 as a DOLFINx body (collective). ``found`` is rank 0's
    (groups, volumes, error, cells); an error, or more cells than ``max_cells``, is raised
    on every rank (ValueError, :class:`MeshTooLarge`). gmsh is finalised on rank 0 in every
    case (where ``running``: its session was started)."""
    groups, volumes, error, cells = comm.bcast(found, root=0)
    if error or (max_cells is not None and cells > max_cells):
        if running:
            gmsh.finalize()
        raise ValueError(error) if error else MeshTooLarge(cells)
    try:
        msh, cell_tags, facet_tags = _compat.model_to_mesh(gmsh.model, comm, 0, gdim=3)
    finally:
        if comm.rank == 0:
            gmsh.finalize()
    return BodyMesh(msh, facet_tags, groups, cell_tags, volumes)


class _GmshError(Exception):
    """What is wrong with the model gmsh read, in one line."""


def _gmsh_model(path: Path) -> tuple[dict[str, int], dict[str, int], int]:
    """Open ``path`` in the current gmsh session, mesh it in 3-D if it holds no volume
    cells, and return its named facet groups and regions (name -> tag; one region "body"
    when it names none) and the dimension of its cells; raises on anything DOLFINx cannot
    take.

    A body of volumes has physical surfaces as facet groups and physical volumes as
    regions; a body of surfaces (shells: a file without volumes, with surface cells or
    surfaces to mesh), physical curves and physical surfaces."""
    import gmsh

    _looks_like_gmsh(path)
    gmsh.option.setNumber("General.Terminal", 0)
    # Never ask "Do you really want to continue?" on stdin (tiny sizes): the size limits
    # of rwall_fem.estimate refuse such scenes before they get here, unless lifted.
    gmsh.option.setNumber("General.ExpertMode", 1)
    # ONELAB keeps DefineConstant values across sessions in a process: start afresh, so
    # that a parameter not given takes its default in the .geo, not the last file's value.
    gmsh.onelab.clear()
    gmsh.open(str(path))
    if len(gmsh.model.mesh.getElements(3)[0]) == 0:
        if gmsh.model.getEntities(3) or not len(gmsh.model.mesh.getElements(2)[0]):
            gmsh.model.mesh.generate(3)  # of surfaces alone, their surface mesh
    if not any(len(gmsh.model.mesh.getElements(dim)[0]) for dim in (2, 3)):
        raise _GmshError("no cells: the file holds no mesh, and no geometry to mesh")
    # Without volume cells the body is its surfaces (shells).
    dim = 3 if len(gmsh.model.mesh.getElements(3)[0]) else 2
    groups = {
        gmsh.model.getPhysicalName(d, tag) or f"{d}:{tag}": tag
        for d, tag in gmsh.model.getPhysicalGroups()
        if d == dim - 1
    }
    if not any(d == dim for d, _ in gmsh.model.getPhysicalGroups()):
        # DOLFINx reads only cells that belong to a physical group.
        tag = gmsh.model.addPhysicalGroup(dim, [t for _, t in gmsh.model.getEntities(dim)])
        gmsh.model.setPhysicalName(dim, tag, "body")
    volumes = {
        gmsh.model.getPhysicalName(d, tag) or f"{d}:{tag}": tag
        for d, tag in gmsh.model.getPhysicalGroups()
        if d == dim
    }
    _regions_are_disjoint(volumes, dim)
    if dim == 3:
        _surfaces_lie_on_the_volumes(groups)
    types = gmsh.model.mesh.getElementTypes(dim)
    kinds = [gmsh.model.mesh.getElementProperties(k)[0] for k in types]
    if len(kinds) > 1:
        hint = "cell = 'tetrahedron'" if dim == 3 else "one of quadrangles or triangles"
        raise _GmshError(
            f"mixed cells ({', '.join(kinds)}); DOLFINx needs one cell type"
            f" (a shape of meshes/: try another element_size or {hint})"
        )
    if dim == 3:
        _cells_are_cells(volumes)
    return groups, volumes, dim


def _cells_are_cells(volumes: dict[str, int]) -> None:
    """No two cells of the physical volumes have the same nodes (a cell written twice, in
    one region or two: DOLFINx would stop on a "Duplicate mesh entity"), and none is flat
    or inside out (:mod:`rwall_fem.cell_shapes`); the first offender is named by its gmsh
    element tag, region and place."""
    import gmsh

    tags, nodes, regions = [], [], []
    for name, tag in volumes.items():
        for entity in gmsh.model.getEntitiesForPhysicalGroup(3, tag):
            for kind, cell_tags, cell_nodes in zip(*gmsh.model.mesh.getElements(3, int(entity)),
                                                   strict=True):  # fmt: skip
                corners = gmsh.model.mesh.getElementProperties(kind)[5]
                rows = np.asarray(cell_nodes, dtype=np.int64).reshape(len(cell_tags), -1)
                tags.append(np.asarray(cell_tags, dtype=np.int64))
                nodes.append(rows[:, :corners])
                regions += [name] * len(cell_tags)
    if not tags:
        return
    tags, nodes = np.concatenate(tags), np.concatenate(nodes)
    _, first, count = np.unique(np.sort(nodes, axis=1), axis=0, return_index=True,
                                return_counts=True)  # fmt: skip
    if (count > 1).any():
        again = np.flatnonzero(count > 1)
        k = first[again[0]]
        same = np.flatnonzero((np.sort(nodes, axis=1) == np.sort(nodes[k])).all(axis=1))
        said = " and ".join(f"{tags[j]} (region '{regions[j]}')" for j in same[:2])
        raise _GmshError(
            f"cells {said} have the same nodes ({int((count[again] - 1).sum())} cell(s) "
            "written twice in all): a cell can be in one region only, once"
        )
    node_tags, coordinates, _ = gmsh.model.mesh.getNodes()
    order = np.argsort(node_tags)
    rows = order[np.searchsorted(np.asarray(node_tags)[order], nodes)]
    x = np.asarray(coordinates).reshape(-1, 3)[rows]
    bad, corner = bad_cells(x)
    if len(bad):
        k = bad[0]
        where = ", ".join(f"{c:.4g}" for c in x[k].mean(axis=0))
        raise _GmshError(
            f"cell {tags[k]} (region '{regions[k]}', at ({where})) is flat or inside out: "
            f"the volume at its corner node {nodes[k, corner[0]]} is not positive "
            f"({len(bad)} such cell(s)); every cell needs a positive volume at its corners"
        )


def _surfaces_lie_on_the_volumes(groups: dict[str, int]) -> None:
    """Every physical surface of a body of volumes lies on its volume cells (a face group):
    a surface apart from them would be shells, and a body is shells or solids."""
    import gmsh

    _, cell_nodes = gmsh.model.mesh.getElements(3)[1:]
    solid = np.unique(np.concatenate([np.asarray(n) for n in cell_nodes]))
    for name, tag in groups.items():
        nodes = np.asarray(gmsh.model.mesh.getNodesForPhysicalGroup(2, tag)[0])
        apart = np.setdiff1d(nodes, solid)
        if len(apart):
            raise _GmshError(
                f"the physical surface '{name}' has {len(apart)} nodes on no volume cell: "
                "it is shells beside the solids, and a scene mixes no shells and solids in "
                "one mesh"
            )


def _regions_are_disjoint(volumes: dict[str, int], dim: int = 3) -> None:
    """Every volume (``dim`` 3) or surface (2) entity is in at most one physical group of
    its dimension: DOLFINx reads each group's cells, so a cell in two would be two cells."""
    import gmsh

    kind = {3: "volume", 2: "surface"}[dim]
    owner: dict[int, str] = {}
    for name, tag in volumes.items():
        for entity in gmsh.model.getEntitiesForPhysicalGroup(dim, tag):
            if int(entity) in owner:
                raise _GmshError(
                    f"the physical {kind}s '{owner[int(entity)]}' and '{name}' share {kind} "
                    f"{int(entity)}: a cell can be in one region only"
                )
            owner[int(entity)] = name


def _looks_like_gmsh(path: Path) -> None:
    """Refuse a .msh that does not start as one, or a .geo that is not text, before gmsh
    reads it: on bytes it cannot parse, gmsh queues errors that it raises again in later
    calls of the process (seen with gmsh 4.8 and 4.15), failing the next good file."""
    with open(path, "rb") as file:
        head = file.read(4096)
    if path.suffix == ".msh" and not head.lstrip().startswith(b"$MeshFormat"):
        raise _GmshError("not a gmsh mesh file (it does not start with $MeshFormat)")
    if path.suffix == ".geo":
        try:
            if b"\0" in head:
                raise UnicodeDecodeError("utf-8", head, head.index(b"\0"), len(head), "NUL")
            head.decode("utf-8")
        except UnicodeDecodeError as err:
            if err.end < len(head) or err.reason == "NUL":  # not a cut multi-byte character
                raise _GmshError(f"not a text file (binary data at byte {err.start})") from None


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
