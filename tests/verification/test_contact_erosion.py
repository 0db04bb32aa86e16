"""Contact with erosion: a deformable projectile perforates a plate whose cells fail
(docs/theory.md, "Contact between parts", erosion).

A 1.5 x 1.5 x 3 mm steel projectile (elasto-plastic, no failure) strikes a free 6 x 6 x 2
mm plate (elasto-plastic, failing at a plastic strain of 0.3) at 900 m/s; 0.5 mm cells (4
layers through the plate: 576 + 54 hexahedra), one [[contact]] between the two. The
projectile's nodes lie off the centres and diagonals of the plate's faces (0.1 and 0.2 mm
from their edges), where two segments would tie for a node (an open question of the
contact itself, docs/theory.md "MPI"). References independent of the code:

- the surface of the plate after the run is the boundary of its live cells, built from
  scratch (the faces of eroded cells left it, the faces they bared joined it): the same
  faces, orientations, stiffnesses and depths;
- no projectile node is ever inside a live plate cell by more than the gap (checked at every
  step against the cells' face planes): the projectile meets the bared faces, and goes
  through only where cells eroded (seen: never inside; a surface that drops the eroded
  cells' faces but does not take the bared ones lets nodes 4 gaps deep into the layers
  under them, and cells invert);
- the projectile gets through (its nose below the plate), so cells eroded under it;
- the books close as the erosion tests' do, to round-off (max balance error <= 1e-12 of
  the initial energy): the contact's work is booked at mid-step velocities, the eroded
  cells take their internal energy with them, and a spring on a face that leaves the
  surface keeps in contact_energy the work done on it;
- the total momentum of the free body is kept: the contact forces are equal and opposite
  (1e-9 of the projectile's).
"""

import copy

import numpy as np
import pytest
from conftest import StopAt, run
from mpi4py import MPI
from test_contact import boxes_geo, write_geo

from rwall_fem import build_simulation, parse_scene
from rwall_fem.contact.surface import boundary_faces

H = 5e-4  # m, the cells
SPEED = 900.0  # m/s
PLATE = (0.0, 0.0, 0.0), (6e-3, 6e-3, 2e-3)
PROJECTILE = (2.1e-3, 2.2e-3, 2.1e-3), (1.5e-3, 1.5e-3, 3e-3)
STEEL = {"model": "elastic_plastic", "density": 7850.0, "young": 200e9, "poisson": 0.3,
         "hardening": "linear", "hardening_modulus": 1e9}  # fmt: skip


def perforation(directory, end_time=1.2e-5):
    geo = boxes_geo([("plate", *PLATE), ("projectile", *PROJECTILE)], H)
    return {
        "run": {"end_time": end_time},
        "mesh": {"file": str(write_geo(directory, "perforation.geo", geo))},
        "material": STEEL | {"yield_stress": 400e6},
        "part": [
            {"name": "plate", "material": STEEL | {
                "yield_stress": 300e6,
                "failure": {"criterion": "plastic_strain", "plastic_strain": 0.3}}},
            {"name": "projectile", "material": STEEL | {"yield_stress": 1.5e9},
             "initial": {"velocity": [0, 0, -SPEED]}},
        ],  # fmt: skip
        "contact": [{"main": ["plate"], "secondary": ["projectile"]}],
        "output": {"plot": False, "history_interval": 1},
    }


class Intrusion:
    """Recorder: at every step, the deepest a projectile node is inside a live plate cell
    (m; negative: outside all), from the cells' 6 face planes (behind every plane)."""

    def __init__(self, sim):
        self.comm, self.deepest = sim.comm, -np.inf
        names = [p.name for p in sim.internal.parts]
        s, held = sim.state, sim.internal.held[: len(sim.state.mass)]
        self.projectile = np.flatnonzero(held[:, names.index("projectile")] > 0)
        self.plate = sim.internal.elements[names.index("plate")]
        sim.recorders.append(self)

    def due(self, s):
        return True

    def record(self, sim, s):
        x = self._positions(sim)  # owned and ghost nodes
        points = np.concatenate(self.comm.allgather(x[self.projectile]))
        e = self.plate.erosion
        cells = self.plate.cells[e.alive] if e is not None else self.plate.cells
        corners = x[cells]  # (cells, 8, 3)
        near = np.all((corners.min(axis=1) <= points.max(axis=0))
                      & (corners.max(axis=1) >= points.min(axis=0)), axis=1)  # fmt: skip
        corners = corners[near]
        depth = np.full((len(points), len(corners)), np.inf)
        centre = corners.mean(axis=1)
        for face in ((0, 1, 3, 2), (4, 5, 7, 6), (0, 1, 5, 4), (2, 3, 7, 6), (0, 2, 6, 4),
                     (1, 3, 7, 5)):  # fmt: skip
            p = corners[:, face]
            n = np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 1])
            mid = p.mean(axis=1)
            n *= np.sign(np.einsum("ij,ij->i", n, mid - centre))[:, None]
            n /= np.linalg.norm(n, axis=1)[:, None]
            behind = np.einsum("cj,pcj->pc", n, mid[None] - points[:, None])
            depth = np.minimum(depth, behind)
        here = float(depth.max(initial=-np.inf))
        self.deepest = max(self.deepest, self.comm.allreduce(here, op=MPI.MAX))

    def _positions(self, sim):
        u = sim.internal.u
        u.scatter_forward()
        return sim.internal.X + u.array.reshape(-1, 3)

    def close(self, sim):
        pass


def test_a_projectile_perforates_a_plate_through_the_faces_erosion_bares(shared_dir):
    raw = perforation(shared_dir)
    sim = build_simulation(parse_scene(raw, source="test"), MPI.COMM_WORLD, shared_dir)
    intrusion = Intrusion(sim)
    assert sim.run() == "done"
    comm = sim.comm
    contact = sim.contacts[0]
    plate = contact.surfaces[0]
    eroded = comm.allreduce(int((~plate.alive).sum()))
    assert eroded > 0 and contact.updates > 0
    # The surface followed the erosion: it is the live cells' boundary built from scratch.
    live = np.repeat(plate.alive, plate.per)
    scratch = boundary_faces(plate.ids[live], plate.key[live], plate.values[live], comm)
    assert np.array_equal(plate.surface.segments, scratch.segments)
    assert np.array_equal(plate.surface.stiffness, scratch.stiffness)
    assert np.array_equal(plate.surface.depth, scratch.depth)
    # No face of an eroded cell is left unless a live cell holds it, and bared faces joined.
    dead = ~np.repeat(plate.alive, plate.per)
    keys = [np.concatenate(comm.allgather(plate.key[m])) for m in (dead, live)]
    rows = [{tuple(k) for k in ks} for ks in keys]
    surface = {tuple(k) for k in np.sort(plate.surface.segments, axis=1)}
    assert not (surface & rows[0]) - rows[1]
    start = boundary_faces(plate.ids, plate.key, plate.values, comm).segments
    assert surface - {tuple(k) for k in np.sort(start, axis=1)}
    # The projectile went through, never inside an intact cell by more than the gap.
    names = [p.name for p in sim.internal.parts]
    s = sim.state
    held = sim.internal.held[: len(s.mass), names.index("projectile")] > 0
    lowest = comm.allreduce(float((s.X + s.u)[: len(s.mass)][held, 2].min(initial=np.inf)),
                            op=MPI.MIN)  # fmt: skip
    assert lowest < 0.0, lowest
    assert intrusion.deepest <= contact.gap, (intrusion.deepest, contact.gap)
    summary = sim.history.summary
    assert summary["energy"]["max_balance_error"] <= 1e-12
    momentum = comm.allreduce((s.mass[:, None] * s.v[: len(s.mass)]).sum(axis=0))
    mass = STEEL["density"] * np.prod(PROJECTILE[1])
    assert np.abs(momentum - [0, 0, -mass * SPEED]).max() <= 1e-9 * mass * SPEED


@pytest.mark.skipif(MPI.COMM_WORLD.size == 1, reason="compares a partitioned run with a serial one")
def test_contact_with_erosion_does_not_depend_on_the_ranks(shared_dir, tmp_path):
    """The perforation's start (cells eroding) on N ranks against one: every column of
    energy.csv and contacts.csv to 1e-10 of its scale (the initial energy for energies,
    the vector's for force and impulse), the same cells eroded and nodes in contact at the
    same steps, the same surface after the run."""
    raw = perforation(shared_dir, end_time=3e-6)
    parallel = run(raw, shared_dir / "parallel")
    serial = run(raw, tmp_path, comm=MPI.COMM_SELF)
    e_par, e_ser = parallel.history.energy, serial.history.energy
    energy = serial.history.summary["energy"]["initial"]
    assert e_par.shape == e_ser.shape
    assert np.abs(e_par[:, 1:15] - e_ser[:, 1:15]).max() <= 1e-10 * energy
    assert np.array_equal(e_par[:, 16], e_ser[:, 16])  # eroded cells
    assert e_ser[-1, 16] > 0
    c_par, c_ser = parallel.history.contact(0), serial.history.contact(0)
    assert np.array_equal(c_par[:, 9], c_ser[:, 9])  # the same nodes in contact
    for span in (slice(2, 5), slice(5, 8), slice(8, 9)):
        assert np.abs(c_par[:, span] - c_ser[:, span]).max() <= 1e-10 * np.abs(c_ser[:, span]).max()
    assert parallel.contacts[0].updates == serial.contacts[0].updates > 0


def test_a_resumed_run_with_erosion_and_contact_equals_the_uninterrupted_one(shared_dir):
    """Stopped after cells eroded, and resumed from its checkpoint: the surface is built
    again from the live cells, and every output is the same to the bit."""
    raw = perforation(shared_dir, end_time=3e-6)
    raw["output"]["checkpoint_steps"] = 10
    whole = run(raw, shared_dir / "whole")
    out = shared_dir / "stopped"
    sim = build_simulation(parse_scene(copy.deepcopy(raw), source="test"), MPI.COMM_WORLD, out)
    sim.recorders.append(StopAt(100))
    assert sim.run().startswith("stopped: step 100,")
    assert sim.contacts[0].updates > 0  # stopped after the surface changed
    resumed = build_simulation(parse_scene(copy.deepcopy(raw), source="test"), MPI.COMM_WORLD, out)
    resumed.checkpoints.resume(resumed)
    assert resumed.run() == "done"
    assert np.array_equal(resumed.state.u, whole.state.u)
    np.testing.assert_array_equal(resumed.contacts[0].surfaces[0].surface.segments,
                                  whole.contacts[0].surfaces[0].surface.segments)  # fmt: skip
    MPI.COMM_WORLD.Barrier()
    if MPI.COMM_WORLD.rank == 0:
        for name in ("energy.csv", "contacts.csv"):
            assert (out / name).read_text() == (shared_dir / "whole" / name).read_text()
