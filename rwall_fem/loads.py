"""External loads, added masses and Rayleigh damping (Radioss /CLOAD, /PLOAD, /ADMAS,
/DAMP; a scene's ``[[load]]``, ``[[added_mass]]`` and ``[damping]``).

Each load is a body force of the pipeline (:mod:`rwall_fem.solver`): it adds its force
over the nodal mass to ``state.a`` at step n, and books its work at mid-step velocities
like every other force (:mod:`rwall_fem.output.energy`): dt^n/2 f^n . v^{n-1/2} at step
n, dt^n/2 f^n . v^{n+1/2} at step n + 1, with the velocities the update left. The shadow kinetic energy then changes by exactly that work, so
the balance closes to round-off whatever the force.

- :class:`NodalForce`: a force (N) on each node of a node set, or a total spread equally,
  times a factor of time;
- :class:`Pressure`: a follower pressure (Pa) on the outer faces of a face group, on the
  faces' current areas and normals: a quadrilateral of nodes x1..x4 takes
  -p (x3 - x1) x (x4 - x2) / 2 (exact for a bilinear face), a triangle -p (x2 - x1) x
  (x3 - x1) / 2, in equal shares to its distinct nodes (Radioss's one-point face; a
  quadrilateral with a repeated node is a triangle);
- :class:`RayleighDamping`: -alpha m v - beta K0 v^{n-1/2} on a node set, K0 the stiffness
  at rest (one more pass of the elastic kernels per step when beta > 0);
- :func:`added_masses`: the masses of ``[[added_mass]]``, added to the nodes before the
  stable step is found.
"""

from __future__ import annotations

import math

import numpy as np

from rwall_fem import _compat
from rwall_fem.elements import GhostedField

__all__ = [
    "Factor",
    "NodalForce",
    "Pressure",
    "RayleighDamping",
    "added_masses",
    "damped_step_factor",
    "outer_faces",
]

# The faces of DOLFINx's reference cells (local vertex numbers), each in a cyclic order.
_FACES = {
    "hexahedron": np.array(
        [[0, 1, 3, 2], [0, 1, 5, 4], [0, 2, 6, 4], [1, 3, 7, 5], [2, 3, 7, 6], [4, 5, 7, 6]]
    ),
    "tetrahedron": np.array([[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]]),
}


class Factor:
    """The factor f(t) of a load: rows (t, y), linear between them, held outside; None: 1."""

    def __init__(self, rows):
        rows = np.asarray(rows if rows is not None else [(0.0, 1.0)], dtype=float)
        self.t, self.y = rows[:, 0], rows[:, 1]

    def __call__(self, t: float) -> float:
        return float(np.interp(t, self.t, self.y))


class _MidStepWork:
    """The work (J) of a force on this rank's owned ``nodes``, booked at mid-step
    velocities: :meth:`_book` at step n takes f^n and v^{n-1/2}; the v^{n+1/2} half is
    settled at the next step (or before a mass change, :meth:`settle`)."""

    def _start_books(self, nodes: np.ndarray) -> None:
        self.nodes = np.asarray(nodes, dtype=np.int32)
        self.done = 0.0  # J, the finished halves
        self._force = np.zeros((len(self.nodes), 3))  # f^n on the nodes, N
        self._half = 0.0  # dt^n / 2 of the pending v^{n+1/2} half (0: none)

    def _book(self, state, force: np.ndarray) -> None:
        self.settle(state)
        self._force[:] = force
        self._half = 0.5 * state.dt_velocity
        self.done += self._half * float(np.sum(force * state.v[self.nodes]))

    def settle(self, state) -> None:
        """Book the v^{n+1/2} half of the latest step with the velocities the nodes have."""
        if self._half:
            self.done += self._half * float(np.sum(self._force * state.v[self.nodes]))
            self._half = 0.0

    def work(self, state) -> float:
        """Work on this rank's nodes up to step n (J), after the update of step n: the
        first half only of step n, as the shadow kinetic energy K^n books it."""
        return self.done

    def checkpoint_state(self) -> dict[str, np.ndarray]:
        """The work so far, the pending half's dt/2 and the latest force."""
        return {"books": np.array([self.done, self._half]), "force": self._force}

    def restore_state(self, arrays: dict[str, np.ndarray]) -> None:
        self.done, self._half = arrays["books"].tolist()
        self._force[:] = arrays["force"]


class NodalForce(_MidStepWork):
    """A force ``force`` (N, 3 components) on each of the owned ``nodes``, times
    ``factor(t)``."""

    def __init__(self, name: str, nodes: np.ndarray, force, factor: Factor):
        self.name = name
        self.force = np.asarray(force, dtype=float)
        self.factor = factor
        self._start_books(nodes)

    def accelerate(self, state) -> None:
        f = self.force * self.factor(state.t)
        state.a[self.nodes] += f * state.inv_mass[self.nodes, None]
        self._book(state, np.broadcast_to(f, self._force.shape))


def outer_faces(V, facets: np.ndarray) -> np.ndarray:
    """The nodes (local indices of ``V``, owned and ghost) of the owned exterior facets
    among ``facets`` (local facet indices), each in the cyclic order whose right-hand
    normal points out of the body: shape (faces, 4) on hexahedra, (faces, 3) on tetrahedra."""
    from dolfinx import mesh

    msh = V.mesh
    tdim = msh.topology.dim
    msh.topology.create_connectivity(tdim - 1, tdim)
    msh.topology.create_connectivity(tdim, tdim - 1)
    owned = msh.topology.index_map(tdim - 1).size_local
    exterior = mesh.exterior_facet_indices(msh.topology)
    facets = np.intersect1d(np.intersect1d(facets, exterior), np.arange(owned))
    table = _FACES[msh.topology.cell_type.name]
    f_to_c = msh.topology.connectivity(tdim - 1, tdim)
    c_to_f = msh.topology.connectivity(tdim, tdim - 1)
    cell_dofs = _compat.cell_nodes(V)
    X = V.tabulate_dof_coordinates()
    cells = f_to_c.array[f_to_c.offsets[facets]]  # an exterior facet's one cell
    local = np.argmax(c_to_f.array.reshape(-1, len(table))[cells] == facets[:, None], axis=1)
    faces = np.take_along_axis(cell_dofs[cells], table[local], axis=1).astype(np.int32)
    centres = X[cell_dofs[cells]].mean(axis=1)
    outward = np.einsum("ij,ij->i", area_vectors(X, faces), X[faces].mean(axis=1) - centres)
    faces[outward < 0] = faces[outward < 0][:, ::-1]
    return faces


def area_vectors(x: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Each face's area times its right-hand unit normal (m^2), at the coordinates ``x``."""
    p = x[faces]
    if faces.shape[1] == 4:
        return 0.5 * np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 1])
    return 0.5 * np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0])


class Pressure(_MidStepWork):
    """A pressure ``pressure`` (Pa) times ``factor(t)`` on the outward-ordered ``faces``
    (nodes of ``V``, owned and ghost: :func:`outer_faces`), following the current
    coordinates X + u of the displacement field ``u`` (a
    :class:`~rwall_fem.elements.GhostedField`, its ghosts scattered by the internal force
    earlier in the step). Collective at every step (the ghosts' shares go to their owners)."""

    def __init__(self, name: str, V, faces: np.ndarray, pressure: float, factor: Factor, u):
        self.name = name
        self.pressure, self.factor = float(pressure), factor
        self.faces, self.u = faces, u
        # Each distinct node of a face takes an equal share: a quadrilateral with a repeated
        # node (a degenerate hexahedron's face) is a triangle, its nodes a third each.
        corners = faces.shape[1]
        repeat = np.zeros(faces.shape, dtype=bool)
        for k in range(1, corners):  # 3 or 4 corners, all faces at once
            repeat[:, k] = (faces[:, :k] == faces[:, k : k + 1]).any(axis=1)
        self.shares = np.where(repeat, 0.0, 1.0) / (~repeat).sum(axis=1, keepdims=True)
        self.X = V.tabulate_dof_coordinates()  # owned and ghost rows, m
        self.f = GhostedField(V)
        self.f.array[self.faces.ravel()] = 1.0
        self.f.scatter_reverse_add()
        owned = V.dofmap.index_map.size_local
        self._start_books(np.flatnonzero(self.f.owned[:, 0] > 0))
        self._owned = owned

    def accelerate(self, state) -> None:
        f = self.f
        f.array.fill(0.0)
        p = self.pressure * self.factor(state.t)
        if len(self.faces):
            force = -p * area_vectors(self.X + self.u.array, self.faces)
            for corner in range(self.faces.shape[1]):  # 3 or 4 corners, all faces at once
                np.add.at(f.array, self.faces[:, corner], self.shares[:, corner, None] * force)
        f.scatter_reverse_add()
        loaded = f.owned[self.nodes]
        state.a[self.nodes] += loaded * state.inv_mass[self.nodes, None]
        self._book(state, loaded)


class RayleighDamping(_MidStepWork):
    """The damping forces -alpha m v - beta K0 v on the owned ``nodes`` (alpha 1/s, beta
    s), v = v^{n-1/2} (explicit); K0 v is the elastic ``body``'s force at the displacement
    v (:meth:`~rwall_fem.body.Body.forces`). Its work is its own column, ``damping_work``."""

    name = "damping"
    column = "damping_work"

    def __init__(self, nodes: np.ndarray, alpha: float, beta: float, body=None):
        self.alpha, self.beta, self.body = float(alpha), float(beta), body
        self._start_books(nodes)

    def accelerate(self, state) -> None:
        nodes = self.nodes
        v = state.v[nodes]
        f = -self.alpha * state.mass[nodes, None] * v
        if self.beta:
            f -= self.beta * self.body.forces(state.v)[nodes]
        state.a[nodes] += f * state.inv_mass[nodes, None]
        self._book(state, f)


def damped_step_factor(alpha: float, beta: float, dt_stable: float) -> float:
    """The factor sqrt(1 + xi^2) - xi on the stable step ``dt_stable`` (s) of Rayleigh
    damping evaluated at v^{n-1/2}, xi = alpha / (2 omega) + beta omega / 2 at omega_max =
    2 / dt_stable: the central difference with a damping force of the lagged velocity is
    stable for omega dt <= 2 (sqrt(1 + xi^2) - xi) (LS-DYNA's and Radioss's rule)."""
    omega = 2.0 / dt_stable
    xi = alpha / (2.0 * omega) + beta * omega / 2.0
    return 1.0 / (math.hypot(1.0, xi) + xi)  # sqrt(1 + xi^2) - xi without cancellation


def added_masses(specs, nodes_of, owned: int, comm) -> np.ndarray:
    """The mass (kg) each owned node gets from the ``[[added_mass]]`` tables ``specs``;
    ``nodes_of(i, group)`` gives the owned nodes of table i's node set."""
    added = np.zeros(owned)
    for i, spec in enumerate(specs):
        nodes = nodes_of(i, spec.group)
        mass = spec.mass
        if spec.per == "set":
            mass = mass / max(comm.allreduce(len(nodes)), 1)
        added[nodes] += mass
    return added
