"""The closest point of a node on a contact surface (``kernels/contact.c``): the side of
the surface a node is on, and the continuity of its force where segments meet.

References: the penalty law of docs/theory.md ("Contact between parts"), f = -k0 g
ln(1 - p / g) at the penetration p = g - d, d the distance to the surface; a node in
front of a face is pushed out along that face's normal, whatever the neighbouring faces.
"""

import math

import numpy as np
import pytest

from rwall_fem.kernels import load

K0, GAP = 1e7, 1e-4


def forces(x, segments, node, *, depth=5e-4, stiffness=False):
    """The contact force (N, rows of 3 on every surface node) of node ``node`` at the
    positions ``x`` (m) against every segment (rows of 4 nodes, -1 for a triangle),
    undamped and frictionless; with ``stiffness``, the contact stiffness (N/m, per node)
    too."""
    ffi, lib = load()
    x = np.ascontiguousarray(x, dtype=float)
    n = len(x)
    segments = np.ascontiguousarray(segments, dtype=np.int64)
    force, springs, out = np.zeros((n, 3)), np.zeros(n), np.zeros(11)
    prm = ffi.new("contact_params *")
    prm.gap, prm.cap, prm.friction, prm.damping, prm.alpha = GAP, 0.99, 0.0, 0.0, 1.0
    prm.dt, prm.reach = 1e-8, max(GAP, depth)

    def p(a, kind="double[]"):
        return ffi.from_buffer(kind, a)

    secondary = np.array([node], np.int64)
    offsets = np.array([0, len(segments)], np.int64)
    candidates = np.arange(len(segments), dtype=np.int64)
    k0 = np.full(len(segments), K0)
    depths = np.full(len(segments), depth)
    v, mass, tangential, gaps = np.zeros((n, 3)), np.ones(n), np.zeros((1, 3)), np.full(1, GAP)
    lib.contact_forces(1, p(secondary, "int64_t[]"), p(offsets, "int64_t[]"),
                       p(candidates, "int64_t[]"), ffi.NULL, p(segments, "int64_t[]"), p(k0),
                       p(depths), ffi.NULL, p(x), p(v), p(mass), prm, p(tangential), p(gaps), p(force),
                       p(springs), p(out))  # fmt: skip
    return (force, springs) if stiffness else force


def spring(d):
    """The penalty force (N) at the distance d (m) from the surface, in front of it."""
    return -K0 * GAP * math.log1p(-(GAP - d) / GAP)


def corner_of_a_block(tilt):
    """The corner region of a block's top face (z = 0 but for a warp of 1e-10 m, two 1 mm
    quadrilaterals along x, outward +z) and its side face (y = 0, outward -y, tilted: its
    top edge is the top face's, its lower edge 1 mm down sits at y = tilt x 1 mm), nodes
    0..5 on the edge and the top, 6..8 the side's lower edge."""
    h, w = 1e-3, 1e-10  # the top face warped by 1e-7 of its size, as a ringing one is
    x = [[0, 0, 0], [h, 0, w], [2 * h, 0, 0], [0, h, w], [h, h, 0], [2 * h, h, w],
         [0, tilt * h, -h], [h, tilt * h, -h], [2 * h, tilt * h, -h]]  # fmt: skip
    top = [[0, 1, 4, 3], [1, 2, 5, 4]]
    side = [[0, 6, 7, 1], [1, 7, 8, 2]]
    return x, top + side


@pytest.mark.parametrize("beyond", [0.0, 1e-11, 1e-9, 1e-6])
@pytest.mark.parametrize("tilt", [3e-4, -3e-4])
@pytest.mark.parametrize("along", [0.4, 1.0])
def test_a_node_over_the_edge_is_in_front_of_the_top_face(along, beyond, tilt):
    """A node 0.98 gap above the top face's edge (over its middle, or over the corner
    that 4 segments share), over the edge or just beyond it (outside
    the block, in front of both faces' pseudo-normal), its side face tilted by +-3e-4 so
    that the node is behind the side face's plane for one sign: it is pushed up by the
    spring of its distance to the edge (1e-4: the warp moves the surface by 5e-7 of the
    distance, the force by 2e-5), not through the side face (which was a force
    2 gaps deep, 10^4 times larger, on a node beside the bars' edge at step 87 of the
    undamped two-bar run)."""
    x, segments = corner_of_a_block(tilt)
    height = 0.98 * GAP
    x.append([along * 1e-3, -beyond, height])
    f = forces(x, segments, len(x) - 1)[-1]
    distance = math.hypot(height, beyond)
    assert f[2] == pytest.approx(spring(distance) * height / distance, rel=1e-4)
    assert abs(f[1]) <= 1e-4 * abs(f[2]) + spring(distance) * beyond / distance * (1 + 1e-4)


def largest_change(step, count=200):
    """The largest change (N) of the forces on the nodes of two warped quadrilaterals
    sharing an edge (corners off the plane by 1 % of the size) as a node 0.5 gap above
    them moves across the common edge in ``2 count`` steps of ``step`` (m), and the size of
    the force (N)."""
    h = 1e-3
    warp = 1e-5
    x = [[0, 0, 0], [h, 0, warp], [2 * h, 0, 0], [0, h, warp], [h, h, -warp], [2 * h, h, warp]]
    segments = [[0, 1, 4, 3], [1, 2, 5, 4]]
    previous, largest = None, 0.0
    for k in range(-count, count + 1):
        f = forces([*x, [h + k * step, 0.37 * h, 0.5 * GAP]], segments, len(x))
        if previous is not None:
            largest = max(largest, np.abs(f - previous).max())
        previous = f
    return largest, np.abs(f[-1]).max()


def test_the_force_of_a_node_crossing_the_common_edge_of_two_warped_segments_is_continuous():
    """Across the common edge of two warped segments, the two closest points differ (by
    the fold) and which segment is the closest changes: the forces on the segments' nodes
    change continuously, as halving the step halves the largest change (a jump would stay:
    without the blend it was 1e-3 of the force, which round-off placed), and a step of
    1e-12 m changes them by less than 1e-4 of the force."""
    coarse, size = largest_change(1e-12)
    fine, _ = largest_change(0.5e-12, count=400)
    assert coarse <= 1e-4 * size
    assert fine <= 0.6 * coarse


def flat_segment(rng, corners):
    """A random convex quadrilateral (4 corners) or triangle (3) of about 1 mm, flat,
    turned at random in space: its corners (m, rows of 3), unit normal and, per side (from
    corner k to k + 1), its unit outward normal in the segment's plane."""
    angles = np.sort(rng.uniform(0.0, 2.0 * np.pi, corners))
    while np.diff(np.append(angles, angles[0] + 2.0 * np.pi)).max() >= 0.9 * np.pi:
        angles = np.sort(rng.uniform(0.0, 2.0 * np.pi, corners))  # a corner near 180 deg
    radius = rng.uniform(0.6e-3, 1.0e-3, corners)
    plane = np.stack([radius * np.cos(angles), radius * np.sin(angles)], axis=1)
    turn, _ = np.linalg.qr(rng.normal(size=(3, 3)))
    y = np.column_stack([plane, np.zeros(corners)]) @ turn.T + rng.uniform(-1e-3, 1e-3, 3)
    side = np.roll(y, -1, axis=0) - y
    normal = turn[:, 2]
    outward = np.cross(side, normal)
    return y, normal, outward / np.linalg.norm(outward, axis=1, keepdims=True)


@pytest.mark.parametrize("corners", [4, 3])
def test_a_node_is_within_reach_of_a_segment_exactly_to_its_distance(corners):
    """Nodes placed at a known distance d from a flat segment (over its inside along its
    normal; off a side, between its outward normal and the segment's; off a corner, in the
    cone of its two sides' outward normals and the segment's: there the closest point is
    the foot, the side's point, the corner), on either side: within reach (d = (1 - 1e-9)
    reach) each gets a contact stiffness (k0 in front, farther than the gap; behind, within
    the segment's depth, its spring's: the pass's branch-free distances skip no pair within
    reach), just beyond it (1 + 1e-9) none (only pairs within reach compete for the
    node)."""
    rng = np.random.default_rng(corners)
    reach = 5e-4  # the segment's depth: max(gap, depth)
    for _ in range(30):
        y, normal, outward = flat_segment(rng, corners)
        k = rng.integers(corners)
        w = rng.dirichlet(np.ones(corners))
        up = rng.choice([-1.0, 1.0]) * normal
        a, b = rng.uniform(0.0, 1.0, 2)
        t = rng.uniform(0.05, 0.95)
        places = {
            "inside": (w @ y, up),
            "side": ((1 - t) * y[k] + t * y[(k + 1) % corners], np.cos(a) * outward[k]
                     + np.sin(a) * up),
            "corner": (y[k], a * outward[k - 1] + b * outward[k] + rng.uniform() * up),
        }  # fmt: skip
        for where, (foot, direction) in places.items():
            direction = direction / np.linalg.norm(direction)
            segment = [[0, 1, 2, 3 if corners == 4 else -1]]
            for ratio in (1 - 1e-9, 1 + 1e-9):
                x = np.vstack([y, foot + ratio * reach * direction])
                _, springs = forces(x, segment, corners, depth=reach, stiffness=True)
                assert (springs[corners] > 0.0) == (ratio < 1.0), (where, ratio)
