"""ShellForce on a DOLFINx surface mesh of quadrilaterals or triangles (serial and 2 ranks):
quadrilaterals are handed to the kernel counter-clockwise, ghosts and owners add up, a
rigid motion of a tilted plate gives no force, and a linear in-plane velocity gives every
cell the membrane resultant t C eps with no force on the interior nodes (the membrane patch
test through the mesh)."""

import math
from types import SimpleNamespace

import numpy as np
import pytest
from mpi4py import MPI

from rwall_fem import _compat
from rwall_fem.elements import GhostedField
from rwall_fem.meshing import plate_surface_mesh, rotation_to
from rwall_fem.shells.elements import ShellForce, ShellTechnology

E, NU, RHO, T = 210e9, 0.3, 7850.0, 2e-3
ELASTIC = SimpleNamespace(model="linear_elastic", plastic=False, young=E, poisson=NU, density=RHO)
AXIS = np.array([1.0, 1.0, 1.0]) / math.sqrt(3.0)


def tilted_plate(cell):
    body = plate_surface_mesh(MPI.COMM_WORLD, (0.1, 0.2, 0.3), (1.0, 0.5, T), 0.125, cell,
                              axis=AXIS)  # fmt: skip
    V = _compat.vector_space(body.msh)
    fields = [GhostedField(V) for _ in range(3)]
    force = ShellForce(V, ELASTIC, ShellTechnology.choose(cell), *fields, thickness=T)
    return V, force, fields


def run(force, u, v, w, dt):
    for field in (u, v, w):
        field.scatter_forward()
    force.f.array.fill(0.0)
    force.m.array.fill(0.0)
    force.compute(SimpleNamespace(dt_previous=dt))
    force.f.scatter_reverse_add()
    force.m.scatter_reverse_add()
    return force.f.owned, force.m.owned


@pytest.mark.parametrize("cell", ["quadrilateral", "triangle"])
def test_rigid_motion_of_a_tilted_plate(cell):
    V, force, (u, v, w) = tilted_plate(cell)
    X = force.X
    dt, omega, speed = 1e-5, np.array([40.0, -70.0, 20.0]), np.array([1.0, 2.0, -3.0])
    v.array[:] = speed + np.cross(omega, X - 0.3)
    w.array[:] = omega
    u.array[:] = 0.5 * dt * v.array  # the mid-step configuration is X: the motion is rigid there
    f, m = run(force, u, v, w, dt)
    comm = V.mesh.comm
    largest = comm.allreduce(max(np.abs(f).max(initial=0), np.abs(m).max(initial=0)), op=MPI.MAX)
    assert largest <= 1e-12 * E * T * 1e-3
    assert abs(comm.allreduce(force.stored_energy)) <= 1e-12 * 0.5 * E * 1e-6 * T
    assert abs(comm.allreduce(force.hourglass_energy)) <= 1e-12 * 0.5 * E * 1e-6 * T


@pytest.mark.parametrize("cell", ["quadrilateral", "triangle"])
def test_membrane_patch_through_the_mesh(cell):
    V, force, (u, v, w) = tilted_plate(cell)
    X = force.X
    R = rotation_to(AXIS)  # the plate's own x, y, z turned: z along AXIS
    a, b = R @ [1.0, 0.0, 0.0], R @ [0.0, 1.0, 0.0]
    G = 1e-9 * (np.outer(a, a) * 1.0 + np.outer(b, b) * 0.5 + np.outer(a, b) * 0.3)
    dt = 1e-3
    v.array[:] = (X - 0.3) @ G.T / dt
    u.array[:] = 0.5 * dt * v.array
    f, m = run(force, u, v, w, dt)
    eps = np.array([[1.0, 0.15], [0.15, 0.5]]) * 1e-9  # sym(G) in the plate's (a, b)
    c = E / (1 - NU**2)
    sigma = c * ((1 - NU) * eps + NU * np.trace(eps) * np.eye(2))
    N = force.history[0:3]
    np.testing.assert_allclose(N[0] + N[1], T * np.trace(sigma), rtol=1e-9)
    np.testing.assert_allclose(N[0] * N[1] - N[2] ** 2, T**2 * np.linalg.det(sigma), rtol=1e-8)
    s = (X[: len(f)] - [0.1, 0.2, 0.3]) @ R  # plate coordinates in [0, 1] x [0, 0.5]
    inner = (s[:, 0] > 1e-9) & (s[:, 0] < 1 - 1e-9) & (s[:, 1] > 1e-9) & (s[:, 1] < 0.5 - 1e-9)
    comm = V.mesh.comm
    largest = comm.allreduce(np.abs(f).max(initial=0), op=MPI.MAX)
    interior = comm.allreduce(np.abs(f[inner]).max(initial=0), op=MPI.MAX)
    assert largest > 0
    assert interior <= 1e-9 * largest
    assert comm.allreduce(np.abs(m).max(initial=0), op=MPI.MAX) <= 1e-9 * largest * 0.125
