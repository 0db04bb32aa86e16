"""The near lists of a contact pass (``kernels/contact.c``, contact_near;
``ContactInterface._list_near``): until some node has moved half the skin, the pass over
them (skipping the candidates whose distance at the lists was beyond the reach and twice
the move) gives the same forces, to the bit, as the pass over all of the sort's candidates.

Reference: the bound of docs/theory.md ("Search"): every point of a segment is a weighted
mean of its corners, so a node and a segment each moving less than r bring them at most
2 r nearer; a candidate left out of the list was farther than 1.000001 reach + skin from
its node, and is still beyond the distance at which the pass skips it after moves of less
than skin / 2.
"""

from types import SimpleNamespace

import numpy as np
import pytest
from mpi4py import MPI

from rwall_fem.contact.interface import SKIN, ContactInterface, Pass

H, GAP, MARGIN = 1e-3, 0.75e-3, 1e-3  # m: element size, gap, margin


def folded_sheet(m: int, rng) -> tuple[np.ndarray, np.ndarray]:
    """A sheet of m x m quadrilaterals of H folded in zigzag legs of 4 elements, its
    neighbouring legs 0 to 1.6 mm apart, the nodes jittered by 0.05 H: positions (m) and
    quadrilaterals."""
    i, j = np.meshgrid(np.arange(m + 1), np.arange(m + 1), indexing="ij")
    leg, up = np.divmod(i.ravel(), 4)
    rise = np.where(leg % 2 == 0, up, 4 - up) / 4
    X = np.stack([(leg + up / 4) * 0.8e-3, j.ravel() * H, rise * 4 * H], axis=1)
    X += rng.uniform(-0.05 * H, 0.05 * H, X.shape)
    a = (i[:-1, :-1] * (m + 1) + j[:-1, :-1]).ravel()
    return X, np.stack([a, a + m + 1, a + m + 2, a + 1], axis=1).astype(np.int64)


def pass_forces(interface: ContactInterface, ps: Pass, offsets, candidates,
                listed=None) -> np.ndarray:  # fmt: skip
    """The forces (N), the contact stiffness (N/m), the friction forces and own gaps and
    the books of one pass over the candidate lists given, with their distances at the near
    lists ``listed`` (m) or without (None: all sought)."""
    p, lib = interface._pointer, interface.lib
    x, v, mass, force, stiffness = interface._surface[:5]
    interface.force[:] = 0.0
    tangential, gaps, out = ps.tangential.copy(), ps.gaps.copy(), np.zeros(11)
    lib.contact_forces(len(ps.secondary), p(ps.secondary, "int64_t[]"),
                       p(offsets, "int64_t[]"), p(candidates, "int64_t[]"),
                       interface.ffi.NULL if listed is None else p(listed),
                       p(ps.segments, "int64_t[]"), p(ps.stiffness), p(ps.depth),
                       p(ps.size), x, v,
                       mass, interface._params, p(tangential), p(gaps), force, stiffness,
                       p(out))  # fmt: skip
    found = np.concatenate([interface.force.ravel(), interface.stiffness, tangential.ravel(),
                            gaps, out])  # fmt: skip
    interface.stiffness[:] = 0.0
    return found


def two_plates(m: int, rng) -> tuple[np.ndarray, np.ndarray]:
    """Two plates of m x m quadrilaterals of H, 0.1 mm farther apart than the gap (out of
    reach until they have closed 0.1 mm), the nodes jittered by 0.01 H: positions (m) and
    quadrilaterals."""
    i, j = np.meshgrid(np.arange(m + 1), np.arange(m + 1), indexing="ij")
    plate = np.stack([i.ravel() * H, j.ravel() * H, np.zeros(i.size)], axis=1)
    X = np.concatenate([plate, plate + [0.0, 0.0, GAP + 1e-4]])
    X += rng.uniform(-0.01 * H, 0.01 * H, X.shape)
    a = (i[:-1, :-1] * (m + 1) + j[:-1, :-1]).ravel()
    quads = np.stack([a, a + m + 1, a + m + 2, a + 1], axis=1)
    return X, np.concatenate([quads, quads + (m + 1) ** 2]).astype(np.int64)


@pytest.mark.parametrize("shape", ["folded sheet", "two plates"])
def test_the_near_lists_give_the_forces_of_all_candidates(shape):
    rng = np.random.default_rng(7)
    X, quads = folded_sheet(24, rng) if shape == "folded sheet" else two_plates(12, rng)
    n = len(X)
    state = SimpleNamespace(X=X, u=np.zeros_like(X), v=rng.normal(0.0, 1.0, X.shape),
                            mass=np.full(n, 1e-4), a=np.zeros_like(X), dt_previous=1e-7)  # fmt: skip
    ps = Pass(np.arange(n, dtype=np.int64), quads, np.full(len(quads), 1e6),
              np.full(len(quads), -0.5 * GAP))  # fmt: skip
    interface = ContactInterface("near", np.arange(n, dtype=np.int64), [ps], gap=GAP,
                                 friction=0.2, alpha=1.0, margin=MARGIN, state=state,
                                 comm=MPI.COMM_SELF, owned_global=np.arange(n))  # fmt: skip
    interface._read(state)
    interface._sort()
    ps = interface.passes[0]
    listed = int(ps.near_offsets[-1])
    assert 0 < listed < 0.5 * ps.offsets[-1]  # the lists are shorter than the candidates
    step = SKIN * MARGIN / 2.0 * 0.999  # the most a node may move before the lists go stale
    if shape == "folded sheet":  # the legs move toward their neighbours on one side
        leg = (X[:, 0] // (4 * 0.8e-3)).astype(int)
        toward = np.where(leg % 2 == 0, 1.0, -1.0)[:, None] * [1.0, 0.0, 0.0]
    else:  # the plates toward each other
        toward = np.where(X[:, 2] > 0.5 * GAP, -1.0, 1.0)[:, None] * [0.0, 0.0, 1.0]
    direction = toward + rng.normal(0.0, 0.1, X.shape)  # a little askew
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    for fraction in (0.0, 0.5, 1.0):
        state.u[:] = fraction * step * direction  # in place: the interface reads it
        moved = interface._read(state)[2]  # since the lists
        assert not interface._near_stale(moved)
        near = pass_forces(interface, ps, ps.near_offsets, ps.near, ps.near_distance)
        every = pass_forces(interface, ps, ps.offsets, ps.candidates)
        assert np.array_equal(near, every)
    assert near[-5] > 0  # some nodes in contact at the end (out[6])
    state.u[:] = 1.01 * SKIN * MARGIN / 2.0 * direction
    assert interface._near_stale(interface._read(state)[2])
