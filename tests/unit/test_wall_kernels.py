"""The compiled passes of the wall condition (kernels/wall.c) against the NumPy code they
replace: the contact test, the impulses, their application, the sums of works, the
clearance of the near set and the bound on the nodes' travel.

The NumPy reference below is the per-step arithmetic of ``walls/constraint.py`` before it
was compiled (test, ``_impulses``, the works). The passes repeat it operation for
operation, so their results are the same to the bit where NumPy's matrix products sum
three products in order (the reference BLAS of the Debian leg). Where a BLAS fuses them
(OpenBLAS on the PyPI leg), distances, normal speeds and patch coordinates may differ in
the last bit: there they agree to round-off, and the test lists the same nodes.
"""

import numpy as np
import pytest

from rwall_fem.kernels import load
from rwall_fem.walls.contact import ContactPasses
from rwall_fem.walls.shapes import CylinderWall, ParallelogramWall, PlaneWall, SphereWall

RNG = np.random.default_rng(20261202)
SHAPES = {
    "plane": lambda: PlaneWall([0.1, -0.2, 0.3], [0.4, 0.5, 1.2]),
    "parallelogram": lambda: ParallelogramWall(
        [-0.5, -0.4, 0.1], [0.6, -0.3, 0.2], [-0.4, 0.7, 0.0]
    ),
    "cylinder": lambda: CylinderWall([0.0, 0.1, -0.2], [0.3, 1.0, 0.1], diameter=0.8),
    "sphere": lambda: SphereWall([0.1, 0.0, -0.1], diameter=1.2),
}


def sequential_blas() -> bool:
    """Whether NumPy's matrix product sums three products in order, without fused
    multiply-adds (then the passes match it to the bit)."""
    x, y = RNG.standard_normal((500, 3)), RNG.standard_normal(3)
    return bool(np.array_equal(x @ y, (x[:, 0] * y[0] + x[:, 1] * y[1]) + x[:, 2] * y[2]))


def same(a, b, scale=1.0):
    """Equal to the bit with a sequential BLAS, else to round-off of values of ``scale``."""
    if sequential_blas():
        np.testing.assert_array_equal(a, b)
    else:
        np.testing.assert_allclose(a, b, rtol=1e-13, atol=4 * np.finfo(float).eps * scale)


class State:
    """Nodes near the surface of ``shape``: positions X + u, velocities, accelerations."""

    def __init__(self, shape, n=400):
        # Points of the surface (or its plane) moved along the normal by up to +-10 um:
        # about as far as a node and the wall travel in a step of step_of.
        x = RNG.uniform(-0.6, 0.6, (n, 3))
        normals = np.broadcast_to(shape.normals(x), (n, 3))
        x += normals * (RNG.uniform(-1e-5, 1e-5, (n, 1)) - shape.distance(x)[:, None])
        self.u = RNG.uniform(-1e-4, 1e-4, (n, 3))
        self.X = x - self.u
        self.v = RNG.uniform(-20.0, 20.0, (n, 3))
        self.a = RNG.uniform(-1e7, 1e7, (n, 3))
        self.mass = RNG.uniform(1e-4, 1e-3, n)


def numpy_find(shape, s, near, dt_v, dt, offset, wall_next, velocity):
    """The contact test of the NumPy code: positions in ``near`` and targets."""
    v_pred = s.v[near] + dt_v * s.a[near]
    x_now = s.X[near] + s.u[near]
    x_pred = x_now + dt * v_pred
    crossing = shape.distance(x_pred, wall_next) < 0.0
    if shape.kind == "parallelogram":
        crossing &= shape.inside_patch(x_pred, wall_next)
    hits = np.flatnonzero(crossing)
    target = np.zeros(len(hits))
    if shape.kind == "parallelogram" and len(hits):
        d_now = shape.distance(x_now[hits], offset)
        normal_speed = np.abs((v_pred[hits] - velocity) @ shape.normal)
        shallow = d_now >= -2.0 * dt * normal_speed
        hits, d_now = hits[shallow], d_now[shallow]
        target = np.maximum(-d_now, 0.0) / dt
    normals = np.broadcast_to(shape.normals(x_now[hits], offset), (len(hits), 3))
    return hits, target, normals, v_pred[hits], s.v[near][hits]


def numpy_impulses(slide, friction, alpha, m, n, w, target, kept):
    """``RigidWall._impulses`` of the NumPy code (m as a column)."""
    wn = np.einsum("ij,ij->i", w, n)
    normal = m * (target - wn)[:, None] * n
    slip = np.zeros(len(w), dtype=bool)
    if slide == "free":
        return normal, None, slip
    stick = -m * (w - wn[:, None] * n)
    if slide == "tied":
        return normal, stick, slip
    if kept is not None:
        stick = alpha * stick + (1.0 - alpha) * kept
    limit = friction * np.linalg.norm(normal, axis=1)
    size = np.linalg.norm(stick, axis=1)
    slip = size > limit
    stick[slip] *= (limit[slip] / size[slip])[:, None]
    return normal, stick, slip


def step_of():
    """A step of a wall moving at 3 m/s: dt_v, dt, offset, next offset, velocity."""
    dt = 2e-7
    velocity = np.array([1.0, -2.0, 2.0])
    offset = np.array([1e-5, 2e-5, -1e-5])
    return 1.5 * dt, dt, offset, offset + dt * velocity, velocity


@pytest.mark.parametrize("kind", SHAPES)
def test_the_contact_test_lists_the_nodes_numpy_does(kind):
    shape = SHAPES[kind]()
    s = State(shape)
    near = np.sort(RNG.choice(len(s.mass), 300, replace=False)).astype(np.int64)
    dt_v, dt, offset, wall_next, velocity = step_of()
    passes = ContactPasses(shape, s)
    k = passes.find(near, dt_v, dt, offset, wall_next, velocity)
    hits, target, normals, predicted, previous = numpy_find(
        shape, s, near, dt_v, dt, offset, wall_next, velocity
    )
    assert 10 < k < 290  # some nodes in contact, some not
    np.testing.assert_array_equal(passes.hits[:k], hits)
    np.testing.assert_array_equal(passes.nodes[:k], near[hits])
    np.testing.assert_array_equal(passes.mass[:k], s.mass[near[hits]])
    np.testing.assert_array_equal(passes.predicted[:k], predicted)
    np.testing.assert_array_equal(passes.previous[:k], previous)
    same(passes.normals[:k], normals)
    same(passes.target[:k], target, scale=1.0 / dt)  # distances of points about 1 m out


@pytest.mark.parametrize("slide", ["free", "tied", "friction", "filtered"])
def test_impulses_applied_and_booked_as_numpy_does(slide):
    shape = SHAPES["sphere"]()
    s = State(shape)
    near = np.arange(len(s.mass), dtype=np.int64)
    dt_v, dt, offset, wall_next, velocity = step_of()
    passes = ContactPasses(shape, s)
    k = passes.find(near, dt_v, dt, offset, wall_next, velocity)
    m, n = passes.mass[:k, None].copy(), passes.normals[:k].copy()
    vs, target = passes.predicted[:k].copy(), passes.target[:k].copy()
    kept = RNG.uniform(-1e-6, 1e-6, (k, 3)) if slide == "filtered" else None
    law = "friction" if slide == "filtered" else slide
    passes.impulses(k, law, 0.3, 0.25, velocity, kept)
    normal, tangential, slip = numpy_impulses(law, 0.3, 0.25, m, n, vs - velocity, target, kept)
    np.testing.assert_array_equal(passes.normal[:k], normal)
    if tangential is not None:
        np.testing.assert_array_equal(passes.tangential[:k], tangential)
        np.testing.assert_array_equal(passes.slip[:k], slip)
    if law == "friction":
        assert 0 < slip.sum() < k  # some slip, some stick

    a = s.a.copy()
    before, final = np.array([0.5, 0.1, -0.2]), np.array([0.4, 0.2, -0.1])
    sums, works = passes.apply(k, tangential is not None, dt_v, before)
    impulse = normal if tangential is None else normal + tangential
    a[passes.nodes[:k]] += impulse / (m * dt_v)
    np.testing.assert_array_equal(s.a, a)
    np.testing.assert_array_equal(sums[0], normal.sum(axis=0))
    np.testing.assert_array_equal(sums[2], impulse.sum(axis=0))
    if tangential is not None:
        np.testing.assert_array_equal(sums[1], tangential.sum(axis=0))

    assert works[0] == (normal * (passes.previous[:k] - before)).sum()
    nodes = passes.nodes[:k].copy()
    assert passes.work(normal, None, final, nodes) == ((normal * (s.v[nodes] - final)).sum(), 0)
    if tangential is not None:
        assert works[1] == (tangential * (passes.previous[:k] - before)).sum()
        works = passes.work(normal, tangential, final, nodes)
        assert works[1] == (tangential * (s.v[nodes] - final)).sum()


@pytest.mark.parametrize("n", [0, 1, 2, 7, 8, 9, 15, 16, 17, 100, 127, 128, 129, 255, 256, 1000,
                               2731, 8191, 8192, 8193, 20000])  # fmt: skip
def test_sums_are_numpys_pairwise_sums(n):
    ffi, lib = load()
    values = RNG.standard_normal(n) * 10.0 ** RNG.uniform(-8, 8, n)
    total = lib.numpy_sum(n, ffi.from_buffer("double[]", values))
    if n <= 8192:
        assert total == values.sum()
    else:  # NumPy 1 sums in blocks of its buffer, NumPy 2 at once
        assert total == pytest.approx(values.sum(), rel=1e-12)


@pytest.mark.parametrize("kind", SHAPES)
def test_clearance_is_the_shapes(kind):
    shape = SHAPES[kind]()
    s = State(shape)
    s.u[:] = RNG.uniform(-0.5, 0.5, s.u.shape)  # nodes everywhere, beside patches too
    nodes = np.sort(RNG.choice(len(s.mass), 250, replace=False)).astype(np.int64)
    offset = np.array([0.01, -0.02, 0.03])
    clearance, largest = ContactPasses(shape, s).clearance(nodes, offset)
    x = s.X[nodes] + s.u[nodes]
    same(clearance, shape.clearance(x, offset))
    assert largest == np.abs(x).max()


def test_the_bound_on_travel_is_the_largest_component():
    shape = SHAPES["plane"]()
    s = State(shape)
    nodes = np.sort(RNG.choice(len(s.mass), 101, replace=False)).astype(np.int64)
    passes = ContactPasses(shape, s)
    assert passes.largest(nodes) == (np.abs(s.v[nodes]).max(), np.abs(s.a[nodes]).max())
    span = np.arange(37, 37 + 203)  # a range of nodes: the contiguous pass
    assert passes.largest(span, (37, 240)) == (np.abs(s.v[span]).max(), np.abs(s.a[span]).max())
    s.v[nodes[3], 1] = np.nan  # left out: such a node fails its test
    s.a[nodes[5], 2] = -np.inf
    s.v[100, 2], s.a[200, 0] = np.nan, -np.inf
    speed, acceleration = passes.largest(nodes)
    assert speed == np.nanmax(np.abs(s.v[nodes])) and acceleration == np.inf
    assert passes.largest(span, (37, 240)) == (np.nanmax(np.abs(s.v[span])), np.inf)
    s.a[200, 0] = 0.0
    assert passes.largest(span, (37, 240))[1] == np.abs(s.a[span]).max()


def numpy_coupled_velocity(mass, held, predicted, m, n, vs, target, tied, extra=None):
    """``RigidWall._coupled_velocity`` of the NumPy code (m as a column): the main node's
    velocity solving (M + sum m_i P_i) V = M V* + sum m_i (P_i v*_i - n_i b_i) - extra."""
    eye = np.eye(3)
    outer = 0.0 if tied.all() else np.einsum("ij,ik->ijk", n, n)
    P = np.where(tied[:, None, None], eye, outer)
    matrix = np.einsum("i,ijk->jk", m[:, 0], P)
    rhs = np.einsum("i,ijk,ik->j", m[:, 0], P, vs) - np.sum(m * target[:, None] * n, axis=0)
    if extra is not None:
        rhs -= extra.sum(axis=0)
    sums = np.concatenate([matrix.ravel(), rhs])
    matrix, rhs = mass * eye + matrix, mass * predicted + rhs
    matrix[held], rhs[held] = eye[held], predicted[held]
    return sums, np.linalg.solve(matrix, rhs)


@pytest.mark.parametrize("slide", ["free", "tied", "friction"])
@pytest.mark.parametrize("held", ["", "xy"])
def test_main_node_coupling_is_numpys(slide, held):
    """The compiled sums of the main node's equations and the velocity solved from them
    (a division when all nodes are tied: LAPACK's solve of a diagonal system) are the
    NumPy code's to the bit."""
    from mpi4py import MPI

    from rwall_fem.walls import RigidWall
    from rwall_fem.walls.motion import MainNodeMotion

    shape = SHAPES["sphere"]()
    s = State(shape, n=3000)  # many contacts: sums over more than one einsum buffer
    near = np.arange(len(s.mass), dtype=np.int64)
    dt_v, dt, offset, wall_next, velocity = step_of()
    motion = MainNodeMotion(0.02, velocity, held=held)
    wall = RigidWall(shape, near, "w", slide=slide, friction=0.2, motion=motion,
                     comm=MPI.COMM_SELF)  # fmt: skip
    passes = ContactPasses(shape, s)
    k = passes.find(near, dt_v, dt, offset, wall_next, velocity)
    assert k > 500
    m, n = passes.mass[:k, None].copy(), passes.normals[:k].copy()
    vs, target = passes.predicted[:k].copy(), passes.target[:k].copy()
    tied = np.full(k, slide == "tied")
    sums, expected = numpy_coupled_velocity(0.02, motion.held, velocity, m, n, vs, target, tied)
    np.testing.assert_array_equal(passes.coupling(k, slide == "tied"), sums)
    np.testing.assert_array_equal(wall._coupled_velocity(velocity, passes, k), expected)
    totals = passes.coupling(k, slide == "tied").copy()  # as summed over the ranks
    np.testing.assert_array_equal(passes.velocity(totals, 0.02, velocity, wall._held), expected)
    if slide != "friction":
        return
    passes.impulses(k, slide, 0.2, 1.0, expected)
    slip = passes.slip[:k].copy()
    assert 0 < slip.sum() < k
    extra = np.where(slip[:, None], passes.tangential[:k], 0.0)
    sums, expected = numpy_coupled_velocity(0.02, motion.held, velocity, m, n, vs, target,
                                            ~slip, extra)  # fmt: skip
    np.testing.assert_array_equal(passes.coupling(k, False, slip=True), sums)
    np.testing.assert_array_equal(wall._coupled_velocity(velocity, passes, k, slip=True),
                                  expected)  # fmt: skip


@pytest.mark.parametrize("seed", range(5))
def test_diagonal_solve_is_a_division(seed):
    """LAPACK's solve of a diagonal system divides (the main node's velocity when every
    node is tied takes that path without the solver)."""
    rng = np.random.default_rng(seed)
    d = rng.uniform(0.1, 10.0, (2000, 3)) * 10.0 ** rng.uniform(-3, 3, (2000, 3))
    r = rng.standard_normal((2000, 3)) * 10.0 ** rng.uniform(-3, 3, (2000, 3))
    solved = np.array([np.linalg.solve(np.diag(di), ri) for di, ri in zip(d, r)])
    np.testing.assert_array_equal(solved, r / d)
