"""The nodes a segment leaves out of its search (Radioss TYPE7 Irem_gap 2, ``[[contact]]``
exclude_within_gap; OpenRadioss ``get_list_remnode.F90``, applied in the sort as
``i7trivox.F`` does; ``kernels/contact_remove.c``).

A strip of 1 mm quadrilaterals, 3 wide, folded into a U: a bottom leg of 10 cells at z = 0,
a wall of 2 cells, a top leg of 10 cells back over the bottom one at z = 2 mm; a
self-contact of constant gap 2.5 mm (more than the cells: a node is within the gap of its
own leg's shells one and two cells away, beyond the shells that hold it). The rule, worked
here independently of the code: segment j leaves out every node whose distance to j along
the mesh (the shortest path from j's nodes over the sides and diagonals of the shells,
Dijkstra) is at most sqrt 2 x the gap, 3.54 mm. So:

- the candidates of the sort with the lists are those without them less exactly the pairs
  the rule removes;
- a node of the top leg over the middle of the bottom one keeps the bottom leg's shells
  under it (11 mm away along the mesh, round the wall: the far fold), and loses its own
  leg's shells two cells away (2 mm along the mesh, 2 mm from it: within the gap).
"""

import heapq
import math
from types import SimpleNamespace

import numpy as np
from mpi4py import MPI

from rwall_fem.contact import _Removal
from rwall_fem.contact.interface import ContactInterface, Pass

H, GAP, LEG, WALL, WIDE = 1e-3, 2.5e-3, 10, 2, 3


def u_strip() -> tuple[np.ndarray, np.ndarray]:
    """Positions (m) and quadrilaterals of the folded strip (node = u (WIDE + 1) + y)."""
    cells = 2 * LEG + WALL
    u, y = np.meshgrid(np.arange(cells + 1), np.arange(WIDE + 1), indexing="ij")
    u, y = u.ravel(), y.ravel()
    x = np.where(u <= LEG, u, np.where(u <= LEG + WALL, LEG, 2 * LEG + WALL - u))
    z = np.clip(u - LEG, 0, WALL)
    X = np.stack([x * H, y * H, z * H], axis=1).astype(float)
    a = (u.reshape(cells + 1, WIDE + 1)[:-1, :-1] * (WIDE + 1)
         + y.reshape(cells + 1, WIDE + 1)[:-1, :-1]).ravel()  # fmt: skip
    quads = np.stack([a, a + WIDE + 1, a + WIDE + 2, a + 1], axis=1).astype(np.int64)
    return X, quads


def along_the_mesh(X, quads, start) -> np.ndarray:
    """Dijkstra's distances (m) from the nodes ``start`` over the sides and diagonals."""
    edges = {}
    for q in quads:
        for a in q:
            for b in q:
                if a != b:
                    edges.setdefault(int(a), set()).add(int(b))
    dist = np.full(len(X), math.inf)
    heap = [(0.0, int(s)) for s in start]
    for _, s in heap:
        dist[s] = 0.0
    while heap:
        d, a = heapq.heappop(heap)
        if d > dist[a]:
            continue
        for b in edges[a]:
            e = d + float(np.linalg.norm(X[b] - X[a]))
            if e < dist[b]:
                dist[b] = e
                heapq.heappush(heap, (e, b))
    return dist


def candidates(X, ps) -> set[tuple[int, int]]:
    """The (node, segment) pairs of the interface's sort over pass ``ps`` (COMM_SELF)."""
    n = len(X)
    state = SimpleNamespace(X=X, u=np.zeros_like(X), v=np.zeros_like(X), mass=np.ones(n),
                            a=np.zeros_like(X), dt_previous=1e-7)  # fmt: skip
    interface = ContactInterface("strip", np.arange(n, dtype=np.int64), [ps], gap=GAP,
                                 friction=0.0, alpha=1.0, margin=H, state=state,
                                 comm=MPI.COMM_SELF, owned_global=np.arange(n))  # fmt: skip
    interface._read(state)
    interface._sort()
    (done,) = interface.passes
    out = set()
    for i, s in enumerate(done.secondary):
        for j in done.candidates[done.offsets[i] : done.offsets[i + 1]]:
            out.add((int(s), int(j)))
    return out


def test_the_lists_remove_the_pairs_within_the_gap_along_the_mesh():
    X, quads = u_strip()
    n = len(X)

    def strip_pass():
        return Pass(np.arange(n, dtype=np.int64), quads, np.full(len(quads), 1e6),
                    np.full(len(quads), -1e-4))  # fmt: skip

    listed = strip_pass()
    removal = _Removal(np.ascontiguousarray(X), np.zeros(n), np.full(n, np.inf), False, GAP,
                       math.inf)  # fmt: skip
    listed.removed = removal.lists(listed, 0)
    within = math.sqrt(2.0) * GAP
    rule = set()
    for j, q in enumerate(quads):
        dist = along_the_mesh(X, quads, q)
        rule |= {(int(s), j) for s in np.flatnonzero(dist <= within) if s not in q}
    without, with_lists = candidates(X, strip_pass()), candidates(X, listed)
    print(f"{len(without)} candidate pairs without the lists, {len(with_lists)} with; "
          f"the rule removes {len(rule)} pairs of which {len(rule & without)} are candidates")
    assert len(rule & without) > 0
    assert with_lists == without - rule
    # A node of the top leg over the middle of the bottom one (x = 5 mm, y = 1 mm)
    node = (LEG + WALL + 5) * (WIDE + 1) + 1
    assert np.allclose(X[node], [5 * H, H, WALL * H])
    below = [j for j, q in enumerate(quads) if np.all(X[q, 2] == 0.0)
             and X[q, 0].min() == 4 * H and X[q, 1].min() == 0.0]  # fmt: skip
    beside = [j for j, q in enumerate(quads) if np.all(X[q, 2] == WALL * H)
              and X[q, 0].min() == 2 * H and X[q, 1].min() == 0.0]  # fmt: skip
    assert along_the_mesh(X, quads, quads[below[0]])[node] >= 11 * H - 1e-12
    assert (node, below[0]) in with_lists  # the far fold stays
    assert (node, beside[0]) in without and (node, beside[0]) not in with_lists


def test_after_erosion_the_segments_keep_their_lists_of_the_start():
    """The strip's bottom leg cut across by erosion (its row of 3 shells from x = 4 to 5
    mm): a pass built again without them gives each shell left the list it had at the
    start, as Radioss builds its lists once (the Dijkstra rule on the whole strip at the
    start); a walk over the shells left would not: a node across the crack, 1 mm from the
    shells before it, has no way to them along the shells left, and would become their
    contact (gap 2.5 mm)."""
    X, quads = u_strip()
    n = len(X)
    crack = np.flatnonzero((X[quads[:, 0], 2] == 0.0) & (X[quads].min(axis=1)[:, 0] == 4 * H)
                           & (X[quads].max(axis=1)[:, 0] == 5 * H))  # fmt: skip
    assert len(crack) == WIDE
    left = np.setdiff1d(np.arange(len(quads)), crack)

    def strip_pass(rows):
        return Pass(np.arange(n, dtype=np.int64), quads[rows], np.full(len(rows), 1e6),
                    np.full(len(rows), -1e-4))  # fmt: skip

    removal = _Removal(np.ascontiguousarray(X), np.zeros(n), np.full(n, np.inf), False, GAP,
                       math.inf)  # fmt: skip
    start = strip_pass(np.arange(len(quads)))
    start.removed = removal.lists(start, 0)
    after = strip_pass(left[::-1])  # in another order, as a rebuilt surface may be
    after.removed = removal.lists(after, 0)
    within = math.sqrt(2.0) * GAP
    rule = set()
    for j, q in enumerate(quads[left[::-1]]):
        dist = along_the_mesh(X, quads, q)  # the whole strip
        rule |= {(int(s), j) for s in np.flatnonzero(dist <= within) if s not in q}
    without, with_lists = candidates(X, strip_pass(left[::-1])), candidates(X, after)
    assert with_lists == without - rule
    # Each shell left has its start list.
    for j, k in enumerate(left[::-1]):
        a, b = after.removed[0][j : j + 2], start.removed[0][k : k + 2]
        assert np.array_equal(after.removed[1][a[0] : a[1]], start.removed[1][b[0] : b[1]])
    # A node across the crack (x = 5 mm, y = 1 mm) and the shell before it (x 3-4 mm)
    node = 5 * (WIDE + 1) + 1
    before = int(np.flatnonzero((X[quads[left[::-1]], 2].max(axis=1) == 0.0)
                                & (X[quads[left[::-1]]].min(axis=1)[:, 0] == 3 * H)
                                & (X[quads[left[::-1]]].min(axis=1)[:, 1] == 0.0))[0])  # fmt: skip
    assert (node, before) in without and (node, before) not in with_lists
    walked = strip_pass(left[::-1])
    walked.removed = removal._walk(walked)  # the walk over the shells left alone
    assert (node, before) in candidates(X, walked)
    # A face the start did not have (as erosion bares in solids; here a triangle of the
    # crack's first shell): its list is the walk's on the surface as it is.
    bared = np.concatenate([quads[left[::-1]], [[*quads[crack[0], :3], -1]]])
    grown = Pass(np.arange(n, dtype=np.int64), bared, np.full(len(bared), 1e6),
                 np.full(len(bared), -1e-4))  # fmt: skip
    grown.removed = removal.lists(grown, 0)
    offsets, ids = removal._walk(grown)
    last = len(bared) - 1
    assert np.array_equal(grown.removed[1][grown.removed[0][last] :], ids[offsets[last] :])
    assert len(ids[offsets[last] :]) > 0
    for j in range(last):
        assert np.array_equal(grown.removed[1][grown.removed[0][j] : grown.removed[0][j + 1]],
                              after.removed[1][after.removed[0][j] : after.removed[0][j + 1]])
