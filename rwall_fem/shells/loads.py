"""Loads and damping on a body of shells (a scene's ``[[load]]`` and ``[damping]``).

The solids' forces (:mod:`rwall_fem.loads`) act on the nodes' translations, as here:

- a nodal force (``kind = "force"``) on a named node set (an edge group of the surface
  mesh) is :class:`~rwall_fem.loads.NodalForce` as it is; no moments (Radioss's /CLOAD
  on rotations is not read);
- a pressure (``kind = "pressure"``) acts on the cells of the named surfaces (a mesh
  file's physical surfaces, a built-in shape's region ``"body"``), not on outer faces: on
  the mid-surface of each cell, following its current area and normal, a positive
  pressure pushing it against its normal (the right-hand normal of its nodes' order:
  +z for a built-in plate), in equal shares to its nodes (Radioss's /PLOAD on shells);
  :class:`~rwall_fem.loads.Pressure` on the cells' node cycles;
- ``[damping]``'s mass-proportional part damps the translations, -alpha m v, and the
  rotations, -alpha I w, of the nodes (:class:`ShellDamping`); its stiffness-proportional
  part (beta) is refused: the shells' kernels integrate a rate form and keep no stiffness
  at rest to multiply the velocities with.
"""

from __future__ import annotations

import numpy as np

from rwall_fem.loads import Factor, NodalForce, Pressure, RayleighDamping
from rwall_fem.scene import SceneError

__all__ = ["ShellDamping", "shell_loads", "surface_cells"]

# DOLFINx's quadrilateral vertices (0,0), (1,0), (0,1), (1,1): their cyclic order.
_CYCLE = {3: [0, 1, 2], 4: [0, 1, 3, 2]}


def surface_cells(scene, where: str, names, body, owned: int) -> np.ndarray:
    """The owned cells (local indices) of the named surfaces ``names`` (regions of the
    surface mesh), or one line refusing an unknown name."""
    regions = body.volumes or {"body": 0}
    for name in names:
        if name not in regions:
            raise SceneError(
                f"{scene.source}: {where}.group: {name!r} is not a surface of the mesh; a "
                f"pressure on shells acts on the cells of: {', '.join(regions)}"
            )
    tags = np.zeros(owned, dtype=np.int64)
    if body.cell_tags is not None:
        kept = body.cell_tags.indices < owned
        tags[body.cell_tags.indices[kept]] = body.cell_tags.values[kept]
    return np.flatnonzero(np.isin(tags, [regions[name] for name in names])).astype(np.int32)


class ShellDamping(RayleighDamping):
    """Mass-proportional damping of the owned ``nodes`` of the shell body ``shells`` (a
    :class:`~rwall_fem.shells.body.ShellBody`): the forces -alpha m v^{n-1/2} and the
    moments -alpha I w^{n-1/2} (N, N m; alpha in 1/s). Their work at mid-step velocities,
    the moments' with the angular velocities, is booked as ``damping_work``."""

    def __init__(self, nodes: np.ndarray, alpha: float, shells):
        super().__init__(nodes, alpha, 0.0)
        self.shells = shells
        self._moment = np.zeros((len(self.nodes), 3))  # M^n on the nodes, N m

    def accelerate(self, state) -> None:
        super().accelerate(state)
        body, nodes = self.shells, self.nodes
        w = body.w.owned[nodes]
        moment = -self.alpha * body.inertia[nodes, 1:2] * w
        body.alpha[nodes] += moment * body.inv_inertia[nodes, None]
        self._moment[:] = moment
        self.done += self._half * float(np.sum(moment * w))

    def settle(self, state) -> None:
        """Book the v^{n+1/2} and w^{n+1/2} halves of the latest step."""
        if self._half:
            w = self.shells.w.owned[self.nodes]
            self.done += self._half * float(np.sum(self._moment * w))
        super().settle(state)

    def checkpoint_state(self) -> dict[str, np.ndarray]:
        return super().checkpoint_state() | {"moment": self._moment}

    def restore_state(self, arrays: dict[str, np.ndarray]) -> None:
        super().restore_state(arrays)
        self._moment[:] = arrays["moment"]


def shell_loads(scene, solid) -> list:
    """The ``[[load]]`` forces and pressures, then the ``[damping]``, of a body of shells
    (``solid``: :class:`~rwall_fem.build._Solid` with ``shells``), in that order."""
    from rwall_fem.build import _named_nodes

    V, body, owned, comm = solid.V, solid.body, solid.owned, solid.comm
    forces = []
    for i, spec in enumerate(scene.loads):
        where, factor = f"load[{i}]", Factor(spec.history)
        if spec.kind == "force":
            nodes = _named_nodes(scene, where, spec.group, V, body, owned)
            force = np.asarray(spec.force)
            if spec.per == "set":
                force = force / max(comm.allreduce(len(nodes)), 1)
            forces.append(NodalForce(where, nodes, force, factor))
            continue
        cells = surface_cells(scene, where, spec.group, body, body.msh.topology.index_map(
            body.msh.topology.dim).size_local)  # fmt: skip
        nodes = solid.elastic._nodes[cells]
        faces = np.ascontiguousarray(nodes[:, _CYCLE[nodes.shape[1]]], dtype=np.int32)
        forces.append(Pressure(where, V, faces, spec.pressure, factor, solid.u))
    damping = scene.damping
    if damping is not None:
        if damping.beta:
            raise SceneError(
                f"{scene.source}: damping.beta: stiffness-proportional damping is for "
                "solids: shells keep no stiffness at rest (their kernels integrate a rate "
                "form); use alpha"
            )
        nodes = np.arange(owned, dtype=np.int32)
        if damping.group is not None:
            nodes = _named_nodes(scene, "damping", damping.group, V, body, owned)
        forces.append(ShellDamping(nodes, damping.alpha, solid.elastic))
    return forces
