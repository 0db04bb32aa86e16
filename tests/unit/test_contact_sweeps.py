"""The sweeps of a contact interface's surface nodes around its passes (``kernels/contact.c``:
``contact_read`` before, ``contact_apply`` after), on a node falling onto a flat segment.

References: the penalty law of docs/theory.md ("Contact between parts"), f = -k0 g
ln(1 - p / g) at the penetration p = g - d (d the node's height over the segment), its
tangent k0 / (1 - p / g) and energy E = k0 g^2 ((1 - x) ln(1 - x) + x), x = p / g; the
work of the contact force on a node moving at a constant velocity is -dE (the power the
sweeps give, summed over the steps, against the closed form); the nodal step sqrt(2 m / k)
of the springs alone, sqrt(m / (e + k / 2)) with the cells' term e (docs/theory.md, contact's
"Stable step").
"""

import math

import numpy as np
import pytest

from rwall_fem.kernels import load

K0, GAP, SIZE = 1e7, 1e-4, 1e-3
# The state's rows of the surface's local nodes 0..4 (the segment's corners 0..3, the
# falling node 4): a permutation, and a state node (4) that is not on the surface.
ROWS = np.array([5, 3, 1, 0, 2], dtype=np.int64)


class Surface:
    """A 1 mm square segment at z = 0 (local nodes 0..3, 1000 kg each: they hardly take
    part in the step) and a 1 g node (local 4) over its middle, in a state of 6 nodes."""

    def __init__(self):
        self.ffi, self.lib = load()
        self.X = np.zeros((6, 3))
        self.X[ROWS] = [[0, 0, 0], [SIZE, 0, 0], [SIZE, SIZE, 0], [0, SIZE, 0],
                        [0.5 * SIZE, 0.5 * SIZE, 0]]  # fmt: skip
        self.u, self.v, self.a = np.zeros((6, 3)), np.zeros((6, 3)), np.zeros((6, 3))
        self.mass = np.full(6, 7.0)
        self.mass[ROWS] = [1e3, 1e3, 1e3, 1e3, 1e-3]
        self.x, self.vs, self.ms = np.zeros((5, 3)), np.zeros((5, 3)), np.zeros(5)
        self.force, self.stiffness, self.kept = np.zeros((5, 3)), np.zeros(5), np.zeros((5, 3))
        self.segments = np.array([[0, 1, 2, 3]], dtype=np.int64)
        self.tangential, self.gaps = np.zeros((1, 3)), np.full(1, np.inf)
        self.prm = self.ffi.new("contact_params *")
        self.prm.gap, self.prm.cap, self.prm.friction = GAP, 0.99, 0.0
        self.prm.damping, self.prm.alpha, self.prm.dt, self.prm.reach = 0.0, 1.0, 1e-8, GAP
        self.pass_out = np.zeros(11)

    def p(self, a, kind="double[]"):
        return self.ffi.from_buffer(kind, a) if a is not None else self.ffi.NULL

    def read(self, kept=None, sorted_at=None, listed=None, packed=None):
        """contact_read: [power, moved since sorted_at, moved since listed]."""
        out = np.zeros(3)
        p = self.p
        self.lib.contact_read(5, p(ROWS, "int64_t[]"), p(self.X), p(self.u), p(self.v),
                              p(self.mass), p(packed), p(self.x), p(self.vs), p(self.ms),
                              p(kept), p(sorted_at), p(listed), p(out))  # fmt: skip
        return out

    def forces(self):
        """The pass of node 4 against the segment (contact_forces); its out."""
        p, one = self.p, np.array([0, 1], dtype=np.int64)
        self.lib.contact_forces(1, p(np.array([4], np.int64), "int64_t[]"), p(one, "int64_t[]"),
                                p(np.zeros(1, np.int64), "int64_t[]"), self.ffi.NULL,
                                p(self.segments, "int64_t[]"), p(np.full(1, K0)), p(np.full(1, 5e-4)), self.ffi.NULL,
                                p(self.x), p(self.vs),
                                p(self.ms), self.prm, p(self.tangential), p(self.gaps),
                                p(self.force), p(self.stiffness), p(self.pass_out))  # fmt: skip
        return self.pass_out

    def apply(self, element=None):
        """contact_apply: [power, nodal step]; ``element`` the cells' term per state row."""
        out = np.zeros(2)
        p = self.p
        self.lib.contact_apply(5, p(ROWS, "int64_t[]"), p(self.force), p(self.stiffness),
                               p(self.ms), p(self.mass), p(self.v), p(self.a), p(self.kept),
                               p(element), p(out))  # fmt: skip
        return out


def penalty(d):
    """The penalty force (N), tangent (N/m) and energy (J) at the height d (m)."""
    x = (GAP - d) / GAP
    return (-K0 * GAP * math.log1p(-x), K0 / (1.0 - x),
            K0 * GAP**2 * ((1.0 - x) * math.log1p(-x) + x))  # fmt: skip


def test_read_takes_the_state_rows_and_measures_the_moves():
    """x = X + u, v and m of the state's rows, packed 7 a node; the largest squared moves
    since two earlier positions, NaN when some position is NaN."""
    s = Surface()
    rng = np.random.default_rng(3)
    s.u[:], s.v[:] = rng.normal(size=(6, 3)) * 1e-4, rng.normal(size=(6, 3))
    packed = np.zeros((5, 7))
    before, listed = s.X[ROWS] + rng.normal(size=(5, 3)) * 1e-5, s.X[ROWS].copy()
    out = s.read(sorted_at=before, listed=listed, packed=packed)
    x = s.X[ROWS] + s.u[ROWS]
    np.testing.assert_array_equal(s.x, x)
    np.testing.assert_array_equal(s.vs, s.v[ROWS])
    np.testing.assert_array_equal(s.ms, s.mass[ROWS])
    np.testing.assert_array_equal(packed, np.column_stack([x, s.v[ROWS], s.mass[ROWS]]))
    assert out[0] == 0.0
    assert out[1] == pytest.approx(np.max(np.sum((x - before) ** 2, axis=1)), rel=1e-14)
    assert out[2] == pytest.approx(np.max(np.sum((x - listed) ** 2, axis=1)), rel=1e-14)
    before[2, 1] = np.nan
    assert math.isnan(s.read(sorted_at=before, listed=listed)[1])


def test_a_falling_node_is_pushed_out_and_the_power_is_the_penalty_energy_rate():
    """Node 4 falls at 1 m/s from 0.9 to 0.1 gap over the segment (the state moved by hand,
    2000 steps): each step its force is the spring's, +z, its acceleration f / m, the
    corners' -f/4 / m; the step is sqrt(2 m / k) with the spring's tangent; the forces are
    kept and the sweep's arrays zeroed; the power of the kept forces at the next read
    equals the apply's (a constant velocity), and their work over the fall is the
    penalty energy stored, -dE, to the rectangle rule's error (7e-4 here)."""
    s = Surface()
    w, steps = 1.0, 2000
    top, bottom = 0.9 * GAP, 0.1 * GAP
    dt = (top - bottom) / (w * steps)
    s.v[ROWS[4]] = [0.0, 0.0, -w]
    work = 0.0
    for n in range(steps):
        d = top - w * n * dt
        s.u[ROWS[4], 2] = d
        s.a[:] = 0.0
        power_read = s.read(kept=s.kept)[0]
        if n:
            assert power_read == pytest.approx(power, rel=1e-15)
        out = s.forces()
        f, tangent, _ = penalty(d)
        assert s.force[4] == pytest.approx([0.0, 0.0, f], rel=1e-9, abs=1e-9 * f)
        assert out[6] == 1.0 and out[7] == pytest.approx(penalty(d)[2], rel=1e-9)
        power, step = s.apply()
        assert step == pytest.approx(math.sqrt(2.0 * 1e-3 / tangent), rel=1e-12)
        np.testing.assert_array_equal(s.kept[4], s.pass_out[:3])
        assert s.a[ROWS[4], 2] == pytest.approx(f / 1e-3, rel=1e-9)
        np.testing.assert_allclose(s.a[ROWS[:4], 2], -0.25 * f / 1e3, rtol=1e-9)
        assert not s.force.any() and not s.stiffness.any()
        assert power == pytest.approx(-w * f, rel=1e-9)
        work += power * dt
    stored = penalty(bottom + w * dt)[2] - penalty(top)[2]  # from the first to the last
    assert work == pytest.approx(-stored, rel=1.5e-3)


def test_the_sweeps_skip_no_term_that_counts():
    """A node without force adds nothing to the sums, but a non-finite velocity at a zero
    force still makes the power NaN (as 0 x inf does), and a zero force still turns an
    acceleration of -0 into +0 (as -0 + 0 / m does), so that skipping the nodes out of
    contact changes no bit."""
    s = Surface()
    s.v[ROWS[1]] = [np.inf, 0.0, 0.0]
    assert math.isnan(s.read(kept=np.zeros((5, 3)))[0])
    s.a[ROWS[2]] = [-0.0, 1.0, -0.0]
    s.force[2] = [0.0, 0.0, -0.0]
    s.apply()
    assert not np.signbit(s.a[ROWS[2], 0]) and np.signbit(s.a[ROWS[2], 2])
    assert s.a[ROWS[2], 1] == 1.0


def test_the_nodal_step_joins_the_cells_and_the_springs_node_by_node():
    """With the cells' term e per state row (N/m), the step is min sqrt(m / (e + k / 2))
    over the nodes with k > 0, by hand: the falling node's spring k at 0.5 gap (tangent
    2 k0) and the corners' w k = k / 4 each; e large on the falling node, so that a corner,
    of a million times its mass, with e small, cannot set it; no k, no term."""
    s = Surface()
    s.X[ROWS[4], 2] = 0.5 * GAP
    s.read()
    s.forces()
    k = s.stiffness.copy()
    assert k[4] == pytest.approx(2.0 * K0, rel=1e-12)
    np.testing.assert_allclose(k[:4], 0.25 * k[4], rtol=1e-12)
    element = np.zeros(6)
    element[ROWS] = [1.0, 2.0, 3.0, 4.0, 3e9]
    element[4] = 1e30  # a state row off the surface: never read
    step = s.apply(element)[1]
    m = s.mass[ROWS]
    hand = min(math.sqrt(m[i] / (element[ROWS[i]] + 0.5 * k[i])) for i in range(5))
    assert hand == math.sqrt(1e-3 / (3e9 + K0))
    assert step == pytest.approx(hand, rel=1e-14)
    s.forces()
    assert s.apply(np.zeros(6))[1] == pytest.approx(math.sqrt(2 * 1e-3 / k[4]), rel=1e-14)
    assert s.apply(element)[1] == math.inf  # no spring: no nodal step
