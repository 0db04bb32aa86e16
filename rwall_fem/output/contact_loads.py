"""The contact loads at the nodes, for ``fields.xdmf`` and the frames: the contact force
(N) and the contact pressure (Pa) of the latest step (``docs/usage.md``, "Outputs").

The contact force at a node is what the contact interfaces added to its acceleration at
the step (:meth:`~rwall_fem.contact.interface.ContactInterface.nodal_forces`), summed over
the interfaces; 0 off every contact surface and where nothing touches.

The contact pressure at a node is, for each interface, its nodal normal contact force
divided by its tributary area, summed over the interfaces:

- the node's faces are the interface's segments around it (faces of solids, shells) at
  the positions x^n; the faces that carry its force are those that face it, whose normal
  is within 60 degrees of the force's line (all of its faces if none does: a node on a
  sharp corner);
- the node's normal is the area-weighted mean of those faces' normals (each turned to
  the side the force comes from), its normal force the size of the force's component
  along that normal (the friction force is across it);
- its tributary area is its lumped share of those faces: a quarter of each
  quadrilateral's area, a third of each triangle's.

So the pressure integrated over one side of a flat contact (the lumped areas times the
nodal pressures) is the sum of the normal forces that side gets: the interface's
``normal_force`` of ``contacts.csv``; a node at the edge of a block pressed on a plate
takes the area of the block's face only, not of its side. Every rank computes every
surface node's pressure alike from the surface gathered at the output step (only then: the
loads cost nothing in the steps between outputs).
"""

from __future__ import annotations

import numpy as np

__all__ = ["ContactLoads"]

# The faces that carry a node's force are within this angle of its line: cos 60 degrees.
FACING = 0.5


class ContactLoads:
    """The nodal contact force and pressure of the interfaces ``contacts`` on the owned
    nodes of the state (their global numbers ``owned_global``), communicator ``comm``."""

    def __init__(self, contacts, comm, owned_global: np.ndarray):
        self.contacts, self.comm = list(contacts), comm
        self.owned_global = np.asarray(owned_global, dtype=np.int64)

    def force(self) -> np.ndarray:
        """The contact force on each owned node (N, rows of 3)."""
        total = np.zeros((len(self.owned_global), 3))
        for contact in self.contacts:
            rows, force, _ = contact.nodal_forces()
            total[rows] += force
        return total

    def pressure(self, s) -> np.ndarray:
        """The contact pressure at each owned node of ``s`` (Pa; collective)."""
        total = np.zeros(len(self.owned_global))
        for contact in self.contacts:
            rows, force, segments = contact.nodal_forces()
            rows = np.asarray(rows, dtype=np.int64)
            _, first = np.unique(np.sort(segments, axis=1), axis=0, return_index=True)
            segments = segments[np.sort(first)]  # a face in two passes counts once
            x = s.X[rows] + s.u[rows]
            pieces = self.comm.allgather((self.owned_global[rows], x, np.asarray(force)))
            ids = np.concatenate([p[0] for p in pieces])
            order = np.argsort(ids)
            ids = ids[order]
            x = np.concatenate([p[1] for p in pieces]).reshape(-1, 3)[order]
            f = np.concatenate([p[2] for p in pieces]).reshape(-1, 3)[order]
            faces = np.where(segments >= 0, np.searchsorted(ids, np.maximum(segments, 0)), -1)
            every = _nodal_pressure(x, f, faces)
            total[rows] += every[np.searchsorted(ids, self.owned_global[rows])]
        return total


def _nodal_pressure(x: np.ndarray, f: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """The contact pressure (Pa) at nodes at ``x`` (m) with forces ``f`` (N) on the
    surface of ``faces`` (rows of 4 node indices, -1 as the 4th of a triangle)."""
    triangle = faces[:, 3] < 0
    p = x[np.where(faces >= 0, faces, faces[:, :1])]  # (faces, 4, 3)
    quad = np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 1])
    tri = np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])
    area_vector = 0.5 * np.where(triangle[:, None], tri, quad)  # normal x area, m^2
    area = np.linalg.norm(area_vector, axis=1)
    share = area / np.where(triangle, 3.0, 4.0)
    corner = faces >= 0
    node = faces[corner]  # each (face, corner) pair
    a = np.repeat(area_vector[:, None], 4, axis=1)[corner]
    lumped = np.repeat(share[:, None], 4, axis=1)[corner]
    fn = f[node]
    along = np.einsum("ij,ij->i", a, fn)
    size = np.linalg.norm(a, axis=1) * np.linalg.norm(fn, axis=1)
    facing = np.abs(along) >= FACING * size
    # Nodes none of whose faces faces the force take all of them.
    any_facing = np.zeros(len(x), dtype=bool)
    any_facing[node[facing]] = True
    taken = facing | ~any_facing[node]
    normal, tributary = np.zeros((len(x), 3)), np.zeros(len(x))
    side = np.where(along < 0.0, -1.0, 1.0)
    np.add.at(normal, node[taken], side[taken, None] * a[taken])
    np.add.at(tributary, node[taken], lumped[taken])
    length = np.linalg.norm(normal, axis=1)
    loaded = (length > 0.0) & (tributary > 0.0) & np.any(f != 0.0, axis=1)
    out = np.zeros(len(x))
    n = normal[loaded] / length[loaded, None]
    out[loaded] = np.abs(np.einsum("ij,ij->i", f[loaded], n)) / tributary[loaded]
    return out
