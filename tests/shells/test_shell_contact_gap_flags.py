"""The variable gap's scale and bounds, and the bounds of the penalty stiffness, act as
Radioss's TYPE7 (``[[contact]]`` gap_scale, gap_max, gap_size_share, stiffness_min,
stiffness_max; Fscalegap, Gap_max, %mesh_size, Stmin, Stmax).

Two parallel steel plates of shells 1.5 mm thick in 0.5 mm quadrilaterals (the lower 4 x 4
mm, the upper 3 x 3 mm over its middle, its nodes a quarter cell off the lower's) close at
a constant speed w, the lower plate main, the upper secondary, both passes. Until they
touch they move rigidly, so their mid-surfaces' separation d is the initial one less w t.
References independent of the code (``i7sti3.F``, ``i7cor3.F``):

- the contact starts at the first step whose positions have d below the pair gap
  g = max(floor, min(min(s_1, size h) + min(s_2, size h), gap_max)), s = scale x t/2 each
  plate's share, h = 0.5 mm, the floor min(scale x t, h / 2) (Radioss's
  default Gapmin, not bounded by Gap_max): d^n < g <= d^(n-1) (one step of travel,
  w dt = 1.7 um, 0.6 % of g);
- the force at that step is the penalty law's at penetration p = g - d on every node in
  contact, -k0 g ln(d / g) each (``kernels/contact.c``; no damping), k0 = E t bounded by
  stiffness_min and stiffness_max: within 1e-9.
"""

import math

import numpy as np
import pytest
from mpi4py import MPI

from rwall_fem import build_simulation, parse_scene

comm = MPI.COMM_WORLD
T, H, E = 1.5e-3, 5e-4, 210e9  # m, m, Pa
STEEL = {"model": "linear_elastic", "density": 7850.0, "young": E, "poisson": 0.3}
W = 20.0  # m/s: the closing speed

GEO = """h = 0.0005;
Point(1) = {{0, 0, 0, h}};
ax[] = Extrude {{0.004, 0, 0}} {{ Point{{1}}; Layers{{8}}; Recombine; }};
ay[] = Extrude {{0, 0.004, 0}} {{ Line{{ax[1]}}; Layers{{8}}; Recombine; }};
Physical Surface("lower") = {{ay[1]}};
Point(101) = {{0.000625, 0.000625, {d0}, h}};
bx[] = Extrude {{0.003, 0, 0}} {{ Point{{101}}; Layers{{6}}; Recombine; }};
by[] = Extrude {{0, 0.003, 0}} {{ Line{{bx[1]}}; Layers{{6}}; Recombine; }};
Physical Surface("upper") = {{by[1]}};
"""


def plates(directory, d0: float, contact: dict, end_time: float, dt=None) -> dict:
    path = directory / f"plates_{d0:.6e}.geo"
    if comm.rank == 0:
        directory.mkdir(parents=True, exist_ok=True)
        path.write_text(GEO.format(d0=d0))
    comm.Barrier()
    raw = {
        "run": {"end_time": end_time},
        "mesh": {"file": str(path)},
        "material": STEEL,
        "element": {"thickness": T},
        "part": [{"name": "lower", "initial": {"velocity": [0.0, 0.0, 0.5 * W]}},
                 {"name": "upper", "initial": {"velocity": [0.0, 0.0, -0.5 * W]}}],
        "contact": [{"main": ["lower"], "secondary": ["upper"], "damping": 0.0} | contact],
        "output": {"plot": False, "frames": 0},
    }  # fmt: skip
    if dt is not None:
        raw["run"]["dt"] = dt
    return raw


class FirstTouch:
    """Recorder: at each step n (before its update), the plates' separation (m,
    mid-surfaces, of the positions x^n) and, at the first step with nodes in contact,
    the contacts and the normal force (N), summed over the ranks."""

    def __init__(self, sim, d0):
        self.sim, self.contact = sim, sim.contacts[0]
        self.upper = sim.state.X[:, 2] > 0.5 * d0
        self.separations, self.touch = [], None
        sim.recorders.append(self)

    def due(self, s):
        return True

    def record(self, sim, s):
        z, up = s.X[:, 2] + s.u[:, 2], self.upper  # the rank's owned nodes
        sums = comm.allreduce(np.array([z[up].sum(), up.sum(), z[~up].sum(), (~up).sum()]))
        contacts = comm.allreduce(int(self.contact.contacts))
        if self.touch is None and contacts:
            force = comm.allreduce(float(self.contact.normal_force))
            self.touch = (len(self.separations), contacts, force)
        self.separations.append(sums[0] / sums[1] - sums[2] / sums[3])

    def close(self, sim):
        pass


def touch(directory, d0, contact, end_time, dt=None):
    sim = build_simulation(parse_scene(plates(directory, d0, contact, end_time, dt),
                                       source="test"), comm, directory)  # fmt: skip
    watch = FirstTouch(sim, d0)
    assert sim.run() == "done"
    return sim, watch


def expected_gap(scale=1.0, gap_max=math.inf, share=0.4) -> float:
    """Radioss's pair gap of the two plates (one thickness, one mesh)."""
    one = min(scale * 0.5 * T, share * H)
    return max(min(scale * T, 0.5 * H), min(2.0 * one, gap_max))


CASES = {
    "default": ({}, expected_gap()),  # 0.4 mm: the size share
    "gap_size_share": ({"gap_size_share": 0.3}, expected_gap(share=0.3)),  # 0.3 mm
    "gap_max": ({"gap_max": 3.5e-4}, expected_gap(gap_max=3.5e-4)),  # 0.35 mm
    "gap_scale": ({"gap_scale": 0.2}, expected_gap(scale=0.2)),  # 0.3 mm
    "gap_max_below_floor": ({"gap_max": 2e-4}, expected_gap(gap_max=2e-4)),  # 0.25 mm
}


@pytest.mark.parametrize("name", list(CASES))
def test_the_contact_starts_at_the_bounded_gap(name, shared_dir):
    contact, g = CASES[name]
    d0 = 4.5e-4
    sim, watch = touch(shared_dir / name, d0, contact, (d0 - g) / W + 2e-6)
    k, contacts, _ = watch.touch
    d = watch.separations
    print(f"{name}: pair gap {g:.4e} m, interface's largest {sim.contacts[0].gap_max:.4e} m; "
          f"first contact at step {k}: d^n {d[k]:.6e} m, d^(n-1) {d[k - 1]:.6e} m, "
          f"{contacts} nodes")
    assert sim.contacts[0].gap_max == pytest.approx(g, rel=1e-12)
    assert d[k] < g <= d[k - 1]
    assert d[k - 1] - d[k] <= 1e-2 * g  # one step of travel, 1.7 um


@pytest.mark.parametrize(
    "bounds, k0",
    [({}, E * T), ({"stiffness_max": 1e8}, 1e8), ({"stiffness_min": 1e9}, 1e9),
     ({"stiffness_scale": 2.0, "stiffness_max": 5e8}, 5e8)],
    ids=["none", "max", "min", "scaled_then_bounded"],
)
def test_the_force_starts_with_the_bounded_stiffness(bounds, k0, shared_dir):
    g = expected_gap()
    d0 = g + 2.1e-7  # the first contact 1/4 of a step's travel (0.4 um) inside the gap
    name = "k_" + "_".join(f"{k}{v:g}" for k, v in bounds.items())
    sim, watch = touch(shared_dir / name, d0, bounds, 2e-7 / W + 1e-7, dt=2e-9)
    k, contacts, force = watch.touch
    d = watch.separations[k]
    each = -k0 * g * math.log(d / g)
    print(f"{bounds}: k0 range {sim.contacts[0].k0_range}, {contacts} nodes at d {d:.9e} m, "
          f"force {force:.6e} N, closed form {contacts * each:.6e} N")
    assert sim.contacts[0].k0_range == pytest.approx((k0, k0), rel=1e-12)
    assert force == pytest.approx(contacts * each, rel=1e-9)


# Different shells: Radioss's Gap_max bounds a pair's variable gap, not each shell's share
# (``[[contact]]`` gap_max; ``i7cor3.F``: GAPV = max(GAPMIN, min(GAP_S + GAP_M, GAPMAX))).
#
# Two parallel steel plates of different shells close at a constant speed w, both passes: the
# lower 2 mm thick in 3 mm quadrilaterals (12 x 12 mm), the upper 0.5 mm thick in 2 mm
# quadrilaterals (8 x 8 mm over its middle, its nodes a quarter cell off the lower's);
# gap_max 0.8 mm. Until they touch they move rigidly, so their mid-surfaces' separation d is
# the initial one less w t. The shares (t/2; the size share 0.4 x side, 1.2 and 0.8 mm, does
# not bind) are 1 and 0.25 mm, the floor min(thinnest t, half the shortest side) = 0.5 mm, so
# Radioss's pair gap is max(0.5, min(1 + 0.25, 0.8)) = 0.8 mm each way; a share capped at
# gap_max / 2 would give 0.25 + 0.4 = 0.65 mm. The contact starts at the first step whose
# positions have d below 0.8 mm: d^n < g <= d^(n-1) (one step of travel, under 1 % of g).
GAP_MAX = 8e-4  # m
PAIR_GAP = max(5e-4, min(1e-3 + 2.5e-4, GAP_MAX))  # Radioss's, hand-computed: 0.8 mm

PAIR_GEO = """Point(1) = {{0, 0, 0}};
ax[] = Extrude {{0.012, 0, 0}} {{ Point{{1}}; Layers{{4}}; Recombine; }};
ay[] = Extrude {{0, 0.012, 0}} {{ Line{{ax[1]}}; Layers{{4}}; Recombine; }};
Physical Surface("thick") = {{ay[1]}};
Point(101) = {{0.00275, 0.00275, {d0}}};
bx[] = Extrude {{0.008, 0, 0}} {{ Point{{101}}; Layers{{4}}; Recombine; }};
by[] = Extrude {{0, 0.008, 0}} {{ Line{{bx[1]}}; Layers{{4}}; Recombine; }};
Physical Surface("thin") = {{by[1]}};
"""


def test_the_contact_of_different_shells_starts_at_the_bounded_pair_gap(shared_dir):
    d0 = 1.1e-3
    directory = shared_dir / "pair_gap"
    path = directory / "plates.geo"
    if comm.rank == 0:
        directory.mkdir(parents=True, exist_ok=True)
        path.write_text(PAIR_GEO.format(d0=d0))
    comm.Barrier()
    raw = {
        "run": {"end_time": (d0 - PAIR_GAP) / W + 2e-6},
        "mesh": {"file": str(path)},
        "material": STEEL,
        "part": [{"name": "thick", "element": {"thickness": 2e-3},
                  "initial": {"velocity": [0.0, 0.0, 0.5 * W]}},
                 {"name": "thin", "element": {"thickness": 5e-4},
                  "initial": {"velocity": [0.0, 0.0, -0.5 * W]}}],
        "contact": [{"main": ["thick"], "secondary": ["thin"], "damping": 0.0,
                     "gap_max": GAP_MAX}],
        "output": {"plot": False, "frames": 0},
    }  # fmt: skip
    sim = build_simulation(parse_scene(raw, source="test"), comm, directory)
    watch = FirstTouch(sim, d0)
    assert sim.run() == "done"
    k, contacts, _ = watch.touch
    d = watch.separations
    print(f"pair gap {PAIR_GAP:.4e} m, interface's largest {sim.contacts[0].gap_max:.4e} m; "
          f"first contact at step {k}: d^n {d[k]:.6e} m, d^(n-1) {d[k - 1]:.6e} m, "
          f"{contacts} nodes")
    assert sim.contacts[0].gap_max == pytest.approx(PAIR_GAP, rel=1e-12)
    assert d[k] < PAIR_GAP <= d[k - 1]
    assert d[k - 1] - d[k] <= 1e-2 * PAIR_GAP


# Different meshes: Radioss's Igap 3 bounds a pair's gap by the sum of the two sides' size
# shares, not each side's share by its own (``i7cor3.F``: GAPV = max(GAPMIN, min(GAP_S +
# GAP_M, GAP_S_L + GAP_M_L, GAPMAX)), ``i7sti3.F``: GAP_M_L = %mesh_size x the segment's
# shortest side, GAP_S_L the least of it over the node's shells).
#
# Two parallel steel plates close at a constant speed w: the lower 2 mm thick in 1 mm
# quadrilaterals (12 x 12 mm), the upper 0.5 mm thick in 2 mm quadrilaterals (8 x 8 mm over
# its middle, its nodes a quarter of a lower cell off the lower's). Hand-computed with the
# default %mesh_size 0.4: thickness shares t/2 = 1 and 0.25 mm (sum 1.25 mm), size shares
# 0.4 x h = 0.4 and 0.8 mm (sum 1.2 mm), floor min(thinnest t, half the shortest side) =
# 0.5 mm: the pair's gap max(0.5, min(1.25, 1.2)) = 1.2 mm, both ways (a node of either
# plate against a segment of the other: the same two sums). Each share capped by its own
# size would give min(1, 0.4) + min(0.25, 0.8) = 0.65 mm. Within each plate the gap of a
# node against its own plate's shells is min(2 t/2, 0.8 h) (0.8 and 0.5 mm), below the
# distance to the nearest shell it is not kept off (h): no contact within a plate. The
# contact starts at the first step whose positions have d below 1.2 mm: d^n < g <= d^(n-1)
# (one step of travel, under 1 % of g), both as a single surface (self = true over both
# plates: Radioss's single-surface TYPE7) and two-sided.
SIZE_PAIR_GAP = max(5e-4, min(1e-3 + 2.5e-4, 0.4 * (1e-3 + 2e-3)))  # 1.2 mm

SIZE_GEO = """Point(1) = {{0, 0, 0}};
ax[] = Extrude {{0.012, 0, 0}} {{ Point{{1}}; Layers{{12}}; Recombine; }};
ay[] = Extrude {{0, 0.012, 0}} {{ Line{{ax[1]}}; Layers{{12}}; Recombine; }};
Physical Surface("fine") = {{ay[1]}};
Point(101) = {{0.00225, 0.00225, {d0}}};
bx[] = Extrude {{0.008, 0, 0}} {{ Point{{101}}; Layers{{4}}; Recombine; }};
by[] = Extrude {{0, 0.008, 0}} {{ Line{{bx[1]}}; Layers{{4}}; Recombine; }};
Physical Surface("coarse") = {{by[1]}};
"""


def size_plates(directory, contact: dict, d0: float = 1.6e-3) -> dict:
    path = directory / "plates.geo"
    if comm.rank == 0:
        directory.mkdir(parents=True, exist_ok=True)
        path.write_text(SIZE_GEO.format(d0=d0))
    comm.Barrier()
    return {
        "run": {"end_time": (d0 - SIZE_PAIR_GAP) / W + 3e-6},
        "mesh": {"file": str(path)},
        "material": STEEL,
        "part": [{"name": "fine", "element": {"thickness": 2e-3},
                  "initial": {"velocity": [0.0, 0.0, 0.5 * W]}},
                 {"name": "coarse", "element": {"thickness": 5e-4},
                  "initial": {"velocity": [0.0, 0.0, -0.5 * W]}}],
        "contact": [{"damping": 0.0} | contact],
        "output": {"plot": False, "frames": 0},
    }  # fmt: skip


@pytest.mark.parametrize("contact", [{"self": True}, {"main": ["fine"], "secondary": ["coarse"]}],
                         ids=["single_surface", "two_sided"])  # fmt: skip
def test_different_meshes_touch_at_the_sum_of_the_size_shares(contact, shared_dir):
    directory = shared_dir / ("size_" + "_".join(contact))
    d0 = 1.6e-3
    sim = build_simulation(parse_scene(size_plates(directory, contact, d0), source="test"),
                           comm, directory)  # fmt: skip
    watch = FirstTouch(sim, d0)
    assert sim.run() == "done"
    k, contacts, _ = watch.touch
    d = watch.separations
    print(f"{contact}: pair gap {SIZE_PAIR_GAP:.4e} m; first contact at step {k}: d^n "
          f"{d[k]:.6e} m, d^(n-1) {d[k - 1]:.6e} m, {contacts} nodes")
    assert d[k] < SIZE_PAIR_GAP <= d[k - 1]
    assert d[k - 1] - d[k] <= 1e-2 * SIZE_PAIR_GAP


@pytest.mark.skipif(comm.size == 1, reason="compares a partitioned run with a serial one")
def test_the_sum_of_the_size_shares_does_not_depend_on_the_ranks(shared_dir, tmp_path):
    """The single-surface plates on N ranks against one rank: the contacts.csv columns
    (force, impulse, normal force, energies) to 1e-10 of their scale, the same nodes in
    contact at the same steps (the segments' size shares travel with them between ranks)."""
    d0 = 1.25e-3  # into contact within a few steps
    raw = size_plates(shared_dir / "size_ranks", {"self": True}, d0)
    raw["run"]["end_time"] = 6e-6
    parallel = build_simulation(parse_scene(raw, source="test"), comm, shared_dir / "size_ranks")
    assert parallel.run() == "done"
    serial_dir = tmp_path / f"serial{comm.rank}"
    serial = build_simulation(parse_scene(raw, source="test"), MPI.COMM_SELF, serial_dir)
    assert serial.run() == "done"
    mine, whole = parallel.history.contact(0), serial.history.contact(0)
    assert mine.shape == whole.shape and whole[:, 9].max() > 0
    assert np.array_equal(mine[:, 9], whole[:, 9])
    for columns in (slice(2, 5), slice(5, 8), slice(8, 9), slice(10, 13)):
        scale = np.abs(whole[:, columns]).max()
        assert np.abs(mine[:, columns] - whole[:, columns]).max() <= 1e-10 * scale, columns
