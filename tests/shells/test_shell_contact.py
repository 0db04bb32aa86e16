"""Self-contact of a body of shells (Radioss /INTER/TYPE7 on shells): a square steel tube
crushed by a heavy plane folds onto itself, and its folds no longer pass through each
other.

References independent of the code:

- until the first node comes within the gap of a segment the contact adds nothing: the
  run with self-contact is the run without it, to round-off;
- no node gets through a shell: every node's distance to every segment that does not hold
  it (measured here in NumPy, the quadrilaterals as two triangles)
  stays above half the gap (half the sum of the thicknesses, 1.5 mm), at every
  sampled step (every 5th);
- folds that bear on each other instead of passing through carry load: after the first
  contact the press's impulse is at least 3 % above the run without contact (6 % here), and the
  plastic work 2 % (4 % here; OpenRadioss on the peer tube: 8 % more plastic work with contact);
- the energy books close as for plastic shells (1e-6 of the impact energy).
"""

import numpy as np
import pytest
from conftest import COLUMN, run
from mpi4py import MPI

from rwall_fem import build_simulation, parse_scene

GAP = 1.5e-3  # m: half the sum of the thicknesses (the default variable gap)


def tube(contact: bool) -> dict:
    """A 40 x 40 mm steel tube (1.5 mm, 80 mm long, shells of 4 mm) on a fixed floor,
    crushed by a 50 kg plane at 15 m/s for 2.2 ms."""
    raw = {
        "run": {"end_time": 2.2e-3},
        "mesh": {"shape": "tube", "section": "square", "width": 0.04, "length": 0.08,
                 "element_size": 0.004, "cell": "quadrilateral",
                 "trigger_amplitude": 3e-4, "trigger_wavelength": 0.024},
        "material": {"model": "elastic_plastic", "density": 7850.0, "young": 210e9,
                     "poisson": 0.3, "hardening": "linear", "yield_stress": 300e6,
                     "hardening_modulus": 600e6},
        "element": {"thickness": 1.5e-3},
        "wall": [
            {"kind": "plane", "point": [0.0, 0.0, -1e-4], "normal_point": [0.0, 0.0, 1.0]},
            {"kind": "plane", "point": [0.0, 0.0, 0.0801], "normal_point": [0.0, 0.0, 0.0],
             "motion": {"mass": 50.0, "velocity": [0.0, 0.0, -15.0]}},
        ],
        "output": {"plot": False},
    }  # fmt: skip
    if contact:
        raw["contact"] = [{"self": True}]
    return raw


def point_triangle_distance(p, a, b, c):
    """Distances (m) of points p from triangles (a, b, c), all (k, 3)."""
    ab, ac, ap = b - a, c - a, p - a
    n = np.cross(ab, ac)
    nn = np.einsum("ij,ij->i", n, n)
    # Barycentric coordinates of the projection onto the plane.
    v = np.einsum("ij,ij->i", np.cross(ap, ac), n) / nn
    w = np.einsum("ij,ij->i", np.cross(ab, ap), n) / nn
    inside = (v >= 0) & (w >= 0) & (v + w <= 1)
    plane = np.abs(np.einsum("ij,ij->i", ap, n)) / np.sqrt(nn)

    def to_side(s, e):
        d = e - s
        t = np.clip(np.einsum("ij,ij->i", p - s, d) / np.einsum("ij,ij->i", d, d), 0, 1)
        return np.linalg.norm(p - (s + t[:, None] * d), axis=1)

    sides = np.minimum.reduce([to_side(a, b), to_side(b, c), to_side(c, a)])
    return np.where(inside, plane, sides)


class Clearance:
    """Every 5th step: the smallest distance (m) of a surface node from the shells it is
    not excluded from (those that hold it left out, as the contact does)."""

    def __init__(self, sim):
        interface = sim.contacts[0]
        self.comm = sim.comm
        # The whole surface: each rank's segments (global node numbers), from every rank.
        segments = np.concatenate(self.comm.allgather(interface.shares[0].segments))
        self.ids = np.unique(segments)
        self.interface, self.segments = interface, np.searchsorted(self.ids, segments)
        n, m = len(self.ids), len(segments)
        self.excluded = np.zeros((n, m), dtype=bool)  # node i is a corner of segment j
        for k in range(4):
            self.excluded[self.segments[:, k], np.arange(m)] = True
        self.smallest = []
        sim.recorders.append(self)

    def due(self, s):
        return s.step % 5 == 0

    def record(self, sim, s):
        it = self.interface
        ids = np.concatenate(self.comm.allgather(it.ids))
        x = np.concatenate(self.comm.allgather(it.x[: it.n]))
        x = x[np.argsort(ids)][np.searchsorted(np.sort(ids), self.ids)]
        corners = x[self.segments]  # (m, 4, 3)
        centre = corners.mean(axis=1)
        reach = 0.75 * 4e-3 + 2 * GAP
        d = np.linalg.norm(x[:, None, :] - centre[None, :, :], axis=2)
        i, j = np.nonzero((d < reach) & ~self.excluded)
        if not len(i):
            self.smallest.append(np.inf)
            return
        q = corners[j]
        p = x[i]
        first = point_triangle_distance(p, q[:, 0], q[:, 1], q[:, 2])
        second = point_triangle_distance(p, q[:, 0], q[:, 2], q[:, 3])
        self.smallest.append(float(np.minimum(first, second).min()))

    def close(self, sim):
        self.smallest = np.array(self.smallest)


def press(sim) -> dict[str, np.ndarray]:
    walls = sim.history.wall(1)
    return {c: walls[:, COLUMN[c]] for c in ("time", "force_z", "impulse_z")}


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    path = tmp_path_factory.mktemp("tube") if MPI.COMM_WORLD.rank == 0 else None
    path = MPI.COMM_WORLD.bcast(path, root=0)
    sim = build_simulation(parse_scene(tube(True), source="test"), MPI.COMM_WORLD,
                           path / "contact")  # fmt: skip
    clearance = Clearance(sim)
    sim.run()
    return sim, clearance, run(tube(False), path / "free")


def test_no_node_gets_through_a_shell(runs):
    sim, clearance, _ = runs
    assert len(clearance.smallest) > 1000
    assert sim.history.summary["contacts"][0]["gap"] == pytest.approx(GAP, rel=1e-12)
    print(f"smallest clearance {clearance.smallest.min() / GAP:.3f} gap over "
          f"{len(clearance.smallest)} samples")
    assert clearance.smallest.min() >= 0.5 * GAP


def test_the_folds_bear_on_each_other(runs):
    sim, _, free = runs
    a, b = press(sim), press(free)
    contacts = sim.history.contact(0)
    touching = contacts[contacts[:, 9] > 0, 0]  # the column "contacts"
    first = touching.min()
    assert 3e-4 < first < 1.5e-3  # after the first fold has started
    # The same crush up to then (the steps differ a little: the springs of nodes within
    # reach of a segment count in the stable step before they touch).
    impulse = [np.interp(first, r["time"], r["impulse_z"]) for r in (a, b)]
    assert impulse[0] == pytest.approx(impulse[1], rel=2e-3)
    after_contact = a["impulse_z"][-1] - impulse[0]
    after_free = b["impulse_z"][-1] - impulse[1]
    print(f"first contact {first * 1e3:.3f} ms; impulse then {impulse[0]:.4f} / "
          f"{impulse[1]:.4f} N s, after {after_contact:.3f} / {after_free:.3f} N s")
    assert after_contact >= 1.03 * after_free
    work, free_work = (s.history.summary["plastic_work"] for s in (sim, free))
    print(f"plastic work {work:.1f} / {free_work:.1f} J")
    assert work >= 1.02 * free_work


def test_the_books_close(runs):
    sim, _, _ = runs
    summary = sim.history.summary
    print(f"balance {summary['energy']['max_balance_error']:.2e}, steps {summary['steps']}")
    assert summary["energy"]["max_balance_error"] <= 1e-6
    assert summary["contacts"][0]["sorts"] >= 2
