"""A body of separate pieces of built-in shapes (``[[piece]]``), against what the scene
declares and against wave theory:

- each piece is where its origin, size and axis put it (the nodes' box to round-off), its
  part's mass is rho x its volume (boxes: exact), the pieces share no node, and their
  regions and face groups carry their names;
- overlapping pieces that no [[contact]] names draw a warning that points to [[contact]];
- two equal nu = 0 bars placed as pieces meet head-on at +v and -v through a [[contact]]:
  by symmetry each is a bar on a rigid wall, and leaves at -v (its impulse 2 m v, 2 %),
  the momenta equal and opposite (1e-6 of m v), the books close to round-off.
"""

import math

import numpy as np
import pytest
from conftest import run
from mpi4py import MPI

from rwall_fem import build_simulation, parse_scene
from rwall_fem.body import piece_overlaps
from rwall_fem.pieces import pieces_mesh

STEEL = {"model": "linear_elastic", "density": 7850.0, "young": 200e9, "poisson": 0.0}
C = math.sqrt(STEEL["young"] / STEEL["density"])
L, A_SIDE, SPEED, H = 0.04, 0.004, 10.0, 0.001


def bars(gap=2e-4, contact=True, end_time=2 * L / C + 1.2e-5):
    """Two 4 x 4 x 40 mm bars along z, ``gap`` apart, at +-10 m/s, as two [[piece]]s; the
    upper one laid along -z (axis [0, 0, -1] about its top end); the run ends 2L/c after
    they touch (the gap closes in 5 us) and some more."""
    raw = {
        "run": {"end_time": end_time},
        "piece": [
            {"name": "lower", "shape": "bar", "size": [A_SIDE, A_SIDE, L], "element_size": H},
            {"name": "upper", "shape": "bar", "size": [A_SIDE, A_SIDE, L], "element_size": H,
             "origin": [0.0, A_SIDE, 2 * L + gap], "axis": [0.0, 0.0, -1.0]},
        ],  # fmt: skip
        "material": STEEL,
        "part": [
            {"name": "lower", "initial": {"velocity": [0, 0, SPEED]}},
            {"name": "upper", "initial": {"velocity": [0, 0, -SPEED]}},
        ],
        "output": {"plot": False},
    }
    if contact:
        raw["contact"] = [{"main": ["upper"], "secondary": ["lower"]}]
    return raw


def part_nodes(sim, name):
    k = [p.name for p in sim.internal.parts].index(name)
    return sim.internal.held[: len(sim.state.mass), k] > 0


def box(sim, name):
    x = sim.state.X[part_nodes(sim, name)]
    low = np.min(sim.comm.allgather(x.min(axis=0, initial=np.inf)), axis=0)
    high = np.max(sim.comm.allgather(x.max(axis=0, initial=-np.inf)), axis=0)
    return low, high


def test_pieces_are_placed_named_and_weighed_as_declared(shared_dir):
    sim = build_simulation(parse_scene(bars(), source="test"), MPI.COMM_WORLD, shared_dir)
    for name, low in (("lower", (0, 0, 0)), ("upper", (0, 0, L + 2e-4))):
        lo, hi = box(sim, name)
        assert np.allclose(lo, low, rtol=0, atol=1e-15)
        assert np.allclose(hi - lo, [A_SIDE, A_SIDE, L], rtol=0, atol=1e-15)
    shared = np.count_nonzero(part_nodes(sim, "lower") & part_nodes(sim, "upper"))
    assert sim.comm.allreduce(shared) == 0
    masses = sim.internal.part_masses
    for k in range(2):
        mass = sim.comm.allreduce(float(masses[:, k].sum()))
        assert mass == pytest.approx(STEEL["density"] * A_SIDE**2 * L, rel=1e-12)
    body = pieces_mesh(MPI.COMM_WORLD, parse_scene(bars(), source="test").pieces)
    assert set(body.volumes) == {"lower", "upper"}
    assert set(body.groups) == {f"{p}_{g}" for p in ("lower", "upper")
                                for g in ("bottom", "top", "sides")}  # fmt: skip


def test_overlapping_pieces_without_contact_point_to_contact(shared_dir):
    raw = bars(gap=-1e-3, contact=False, end_time=1e-7)
    sim = build_simulation(parse_scene(raw, source="test"), MPI.COMM_WORLD, shared_dir)
    warnings = piece_overlaps(sim.internal, sim.state.X, sim.comm)
    assert len(warnings) == 1 and "[[contact]]" in warnings[0], warnings
    assert not piece_overlaps(sim.internal, sim.state.X, sim.comm, [{"lower", "upper"}])


def test_two_bar_pieces_meet_as_on_a_rigid_wall(shared_dir):
    sim = run(bars(), shared_dir)
    s = sim.state
    mass = STEEL["density"] * A_SIDE**2 * L
    momenta = []
    for name in ("lower", "upper"):
        held = part_nodes(sim, name)
        momenta.append(sim.comm.allreduce((s.mass[held, None] * s.v[held]).sum(axis=0)))
    assert momenta[0][2] == pytest.approx(-mass * SPEED, rel=0.02)
    assert abs(momenta[0][2] + momenta[1][2]) <= 1e-6 * mass * SPEED
    assert sim.history.summary["energy"]["max_balance_error"] <= 1e-12
