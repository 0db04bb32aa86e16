"""Self-contact leaves out of a node's search only the segments that hold it, as
OpenRadioss's sort does (``i7trivox.F``: a secondary node that is one of the segment's
nodes is skipped, nothing else without Irem_gap 2); the segments around its own, which
share a node with them, stay candidates, and a sharp fold meets them.

A sheet of shells folded at a right angle along the y axis: flap A in the plane z = 0 (x
from 0 to 2 H), flap B in the plane x = 0 (z from 0 to 2 H), each two cells long and one
wide (H = 1 mm), the fold's nodes shared. Worked by hand: the node P of flap A at x = H
holds A's two cells; B's first cell shares the fold's nodes with A's first cell (a
neighbour of P's own cells), and is H from P (its closest point on the fold), within the
gap of 1.2 H; B's second cell is sqrt(2) H from P, beyond the gap. So P's candidates
include B's first cell and none of A's, and the pass pushes P away from B (+x): were the
neighbours left out, no node would be in contact at all. The forces are checked against
the fold's mirror symmetry (x <-> z) and action and reaction (they sum to zero).
"""

from types import SimpleNamespace

import numpy as np
from mpi4py import MPI

from rwall_fem.contact.interface import ContactInterface, Pass

H = 1e-3  # m
GAP = 1.2 * H


def folded_sheet() -> tuple[np.ndarray, np.ndarray]:
    """Positions (m) and quadrilaterals of the sheet folded at a right angle."""
    along = np.array([0.0, H, 2 * H])
    fold = [[0.0, y, 0.0] for y in (0.0, H)]  # nodes 0, 1
    flap_a = [[x, y, 0.0] for x in along[1:] for y in (0.0, H)]  # nodes 2..5
    flap_b = [[0.0, y, z] for z in along[1:] for y in (0.0, H)]  # nodes 6..9
    X = np.array(fold + flap_a + flap_b)
    quads = np.array([[0, 2, 3, 1], [2, 4, 5, 3],  # flap A
                      [0, 1, 7, 6], [6, 7, 9, 8]], dtype=np.int64)  # flap B  # fmt: skip
    return X, quads


def test_a_fold_meets_the_segments_next_to_a_nodes_own():
    X, quads = folded_sheet()
    n = len(X)
    state = SimpleNamespace(X=X, u=np.zeros_like(X), v=np.zeros_like(X), mass=np.full(n, 1e-4),
                            a=np.zeros_like(X), dt_previous=1e-7)  # fmt: skip
    k0 = 1e6  # N/m
    ps = Pass(np.arange(n, dtype=np.int64), quads, np.full(len(quads), k0),
              np.full(len(quads), -1e-4))  # fmt: skip
    interface = ContactInterface("fold", np.arange(n, dtype=np.int64), [ps], gap=GAP,
                                 friction=0.0, alpha=1.0, margin=H, state=state,
                                 comm=MPI.COMM_SELF, owned_global=np.arange(n))  # fmt: skip
    interface.accelerate(state)
    ps = interface.passes[0]
    node = 2  # P: flap A at x = H, y = 0
    mine = set(ps.candidates[ps.offsets[node] : ps.offsets[node + 1]].tolist())
    assert 2 in mine  # B's first cell: shares the fold's nodes with P's own first cell
    assert not mine & {0, 1}  # A's cells hold P
    # The forces: P pushed away from B (+x); the fold's mirror image (x <-> z) gets the
    # mirror image of every force (P's is node 6's); action and reaction sum to zero.
    f = state.a * state.mass[:, None]
    mirror = np.array([0, 1, 6, 7, 8, 9, 2, 3, 4, 5])  # node of the mirror image, x <-> z
    scale = np.abs(f).max()
    print(f"force on P {f[node]} N, on its mirror image {f[6]} N")
    assert f[node, 0] > 0.0
    assert np.allclose(f[mirror][:, ::-1], f, rtol=0.0, atol=1e-12 * scale)
    assert np.allclose(f.sum(axis=0), 0.0, rtol=0.0, atol=1e-12 * scale)
