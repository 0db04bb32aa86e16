"""A scene's body of shells: its surface mesh, parts, sections, inertia and stable step.

:func:`shell_solid` is what :func:`rwall_fem.build.build_simulation` builds for a mesh of
surface cells (topological dimension 2 in 3-D) in place of a solid body; the rest of the
pipeline (walls, boundary conditions, gravity, outputs, checkpoints) is the solids'. What
shells cannot do yet is refused here in one line naming the key.
"""

from __future__ import annotations

import math

import numpy as np
from mpi4py import MPI

from rwall_fem import _compat
from rwall_fem.body import PartError, parts_of
from rwall_fem.elements import GhostedField
from rwall_fem.scene import SceneError
from rwall_fem.scene.schema import SHELL_KEYS, element_fits_the_surface
from rwall_fem.shells.body import ShellBody, ShellSection
from rwall_fem.shells.inertia import lumped_inertia

__all__ = ["shell_solid", "solid_keys_on_shells"]

# The defaults of the shells' [element] keys: Radioss's N, hm, hf, hr and Ashear.
POINTS, HOURGLASS, SHEAR_FACTOR = 5, (0.01, 0.01, 0.01), 5.0 / 6.0
# The scene's [element] keys that only solids have, as the Element dataclass holds them
# (None: not given).
_SOLID_VALUES = ("integration", "hourglass", "hourglass_coefficient")


def solid_keys_on_shells(scene, cell: str) -> None:
    """Refuse, in one line naming the key, the [element] keys of a mesh file's cells that
    are not theirs: a solid's keys on shells, or a shell's thickness or formulation on a
    volume mesh (a scene mixes no shells and solids in one mesh)."""
    for where, element in _element_tables(scene):
        given = {name: getattr(element, name) for name in
                 (*_SOLID_VALUES, *SHELL_KEYS)}  # fmt: skip
        given = {name: value for name, value in given.items() if value is not None}
        wrong = element_fits_the_surface(where, given, cell)
        if wrong:
            if cell not in ("quadrilateral", "triangle"):
                wrong += " (a scene mixes no shells and solids in one mesh)"
            raise SceneError(f"{scene.source}: {wrong}")


def _element_tables(scene):
    tables = [("element", scene.element)]
    tables += [(f"part[{i}].element", p.element) for i, p in enumerate(scene.parts) if p.element]
    return tables


def _section(scene, i: int, spec, cell: str) -> ShellSection:
    """Part ``i``'s section from its [element] (the scene's when it gives none)."""
    element = spec.element
    where = f"part[{i}].element" if scene.parts else "element"
    thickness = element.thickness
    if thickness is None and scene.mesh is not None and scene.mesh.shape == "plate":
        thickness = scene.mesh.size[2]
    if thickness is None:
        raise SceneError(
            f"{scene.source}: {where}.thickness: missing: a mesh file of surfaces (shells) "
            "needs the shells' thickness (m)"
        )
    from rwall_fem.shells.elements import ShellTechnology

    formulation = element.formulation or ("bsc" if cell == "triangle" else "bwc")
    points = element.points or POINTS
    try:
        technology = ShellTechnology.choose(
            cell,
            formulation,
            points=points,
            hourglass=element.hourglass_coefficients or HOURGLASS,
            shear_factor=element.shear_factor or SHEAR_FACTOR,
            hourglass_stiffness=element.hourglass_stiffness or 0.0,
            drilling_stiffness=element.drilling_stiffness or 0.0,
            step_length=element.step_length or "bt",
            hourglass_yield=bool(element.hourglass_yield),
        )
    except ValueError as err:  # "element.<key>: ..." of the kernels, or a sentence
        said = str(err)
        said = where + said[len("element") :] if said.startswith("element.") else f"{where}: {said}"
        raise SceneError(f"{scene.source}: {said}") from None
    failed_share = 1.0 if element.failed_share is None else element.failed_share
    return ShellSection(technology, formulation, thickness, points, failed_share,
                        bool(element.thickness_change))  # fmt: skip


# The sides of DOLFINx's triangle and quadrilateral, by local node index.
_SIDES = {3: [(0, 1), (1, 2), (2, 0)], 4: [(0, 1), (1, 3), (3, 2), (2, 0)]}


def _shortest_side(V, nodes: np.ndarray, comm: MPI.Comm) -> float:
    """The shortest side (m) of the surface's cells (collective)."""
    x = V.tabulate_dof_coordinates()
    sides = np.array(_SIDES[nodes.shape[1]])
    length = np.linalg.norm(x[nodes[:, sides[:, 1]]] - x[nodes[:, sides[:, 0]]], axis=2)
    return comm.allreduce(float(length.min(initial=np.inf)), op=MPI.MIN)


def shell_solid(scene, comm: MPI.Comm, body):
    """The :class:`~rwall_fem.build._Solid` of the scene's body of shells on the surface
    mesh ``body`` (a :class:`~rwall_fem.meshing.BodyMesh`): parts (physical surfaces) with
    their sections, the nodes' masses and rotational inertias, and the stable step at rest
    (s): the smallest L_c / c of a cell (Radioss's, without an eigenvalue)."""
    from rwall_fem.build import _Solid

    cell = body.msh.topology.cell_type.name
    solid_keys_on_shells(scene, cell)
    specs = scene.body_parts
    sections = [_section(scene, i, spec, cell) for i, spec in enumerate(specs)]
    try:
        parts = parts_of(specs, body, sections, comm)
    except PartError as err:
        raise SceneError(f"{scene.source}: {err}") from None
    V = _compat.vector_space(body.msh)
    nodes = np.asarray(_compat.cell_nodes(V))
    if scene.mesh is not None and scene.mesh.noise is not None:
        from rwall_fem.build import _noise_is_small
        from rwall_fem.meshing import perturb

        if scene.mesh.file is not None:  # a built-in shape's noise was checked with the scene
            _noise_is_small(scene, _shortest_side(V, nodes, comm))
        perturb(body, *scene.mesh.noise)
    X = V.tabulate_dof_coordinates()[: V.dofmap.index_map.size_local].copy()
    inertias = [
        lumped_inertia(V, nodes[part.cells], part.material.density, part.technology.thickness)
        for part in parts
    ]
    masses = np.column_stack([inertia[:, 0] for inertia in inertias])
    inertia = sum(inertias)
    if scene.added_masses:  # point masses: no rotational inertia; shared as solids share them
        from rwall_fem.build import _named_nodes
        from rwall_fem.loads import added_masses

        owned = len(X)
        added = added_masses(scene.added_masses, lambda i, name: _named_nodes(
            scene, f"added_mass[{i}]", name, V, body, owned), owned, comm)  # fmt: skip
        total = masses.sum(axis=1)
        masses = masses + added[:, None] * masses / np.where(total > 0, total, 1.0)[:, None]
        inertia[:, 0] += added
    lowest = comm.allreduce(float(inertia[:, 0].min(initial=np.inf)), op=MPI.MIN)
    if not lowest > 0.0:
        raise SceneError(
            f"{scene.source}: mesh: a node has no mass ({lowest:g} kg): every node of a body "
            "of shells is a corner of a cell of positive area"
        )
    u, v = GhostedField(V), GhostedField(V)
    try:
        shells = ShellBody(V, parts, u, v, inertia, explicit=bool(scene.parts))
    except ValueError as err:  # a material the shell kernels do not have
        raise SceneError(f"{scene.source}: {err}") from None
    dt_stable = comm.allreduce(float(shells.steps_at_rest().min(initial=np.inf)), op=MPI.MIN)
    if not (math.isfinite(dt_stable) and dt_stable > 0.0):
        from rwall_fem.estimate import unphysical_material

        raise unphysical_material(scene, f"the cells' L_c / c came out as {dt_stable:g} s")
    low, high = np.empty(3), np.empty(3)
    comm.Allreduce(X.min(axis=0, initial=np.inf), low, op=MPI.MIN)
    comm.Allreduce(X.max(axis=0, initial=-np.inf), high, op=MPI.MAX)
    size = float(np.linalg.norm(high - low))
    return _Solid(comm, body, V, X, inertia[:, 0].copy(), masses, u, v, parts, shells,
                  dt_stable, size, shells=True)  # fmt: skip
