"""The assembled stiffness: block storage, and what any elastic stiffness must satisfy.

References independent of the code: a rigid motion (translation or infinitesimal
rotation) strains nothing, so K maps it to zero force; K is symmetric; and the
block (BAIJ) matrix the solver uses equals DOLFINx's own (AIJ) assembly of the form.
"""

import numpy as np
import pytest
from dolfinx import mesh
from mpi4py import MPI

from rwall_fem import _compat
from rwall_fem.mechanics import stiffness_form, stiffness_matrix
from rwall_fem.scene import Material

STEEL = Material("linear_elastic", density=7850.0, young=210.0e9, poisson=0.3)
CELLS = [mesh.CellType.tetrahedron, mesh.CellType.hexahedron]


def box(cell):
    """A 10 x 6 x 4 mm box of 5 x 3 x 2 cells (coordinates in m)."""
    corners = [np.zeros(3), np.array([0.010, 0.006, 0.004])]
    msh = mesh.create_box(MPI.COMM_WORLD, corners, [5, 3, 2], cell)
    return _compat.vector_space(msh)


def owned_coordinates(V):
    """Coordinates (m) of the rank's owned nodes, in the rows of K."""
    n = V.dofmap.index_map.size_local
    return V.tabulate_dof_coordinates()[:n]


@pytest.mark.parametrize("cell", CELLS, ids=["tet", "hex"])
def test_stiffness_is_a_block_matrix_equal_to_dolfinx_assembly(cell):
    V = box(cell)
    K = stiffness_matrix(V, STEEL)
    assert K.getType().endswith("baij") and K.getBlockSize() == 3
    A = _compat.assemble_matrix(stiffness_form(V, STEEL), "aij")  # the same form, as AIJ
    x, y, z = K.createVecRight(), K.createVecLeft(), K.createVecLeft()
    x.setRandom()
    K.mult(x, y)
    A.mult(x, z)
    # Same entries summed in another order: round-off, 1e-16 per entry seen.
    assert (y - z).norm() <= 1e-13 * z.norm()


@pytest.mark.parametrize("cell", CELLS, ids=["tet", "hex"])
def test_rigid_motions_carry_no_force_and_K_is_symmetric(cell):
    V = box(cell)
    K = stiffness_matrix(V, STEEL)
    X = owned_coordinates(V)
    scale = K.norm()  # N/m (Frobenius norm)
    x, f = K.createVecRight(), K.createVecLeft()
    rotations = [np.cross(axis, X) for axis in np.eye(3)]  # infinitesimal, 1 rad
    translations = [np.broadcast_to(e, X.shape) for e in np.eye(3)]  # 1 m
    for motion in translations + rotations:
        x.array[:] = motion.ravel()
        K.mult(x, f)
        # Zero to the round-off of K's entries (2e-16 seen); a stretch of the same size
        # gives 3e-4 to 6e-4 of scale x displacement.
        assert f.norm() <= 1e-12 * scale * np.abs(motion).max()
    # Symmetry through two random vectors (BAIJ has no MatIsSymmetric): a.Kb = b.Ka.
    a, b = K.createVecRight(), K.createVecRight()
    a.setRandom()
    b.setRandom()
    K.mult(b, f)
    a_Kb = a.dot(f)
    K.mult(a, f)
    assert a_Kb == pytest.approx(b.dot(f), rel=1e-12)
