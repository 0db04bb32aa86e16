"""Contact with eroding shells: a heavy square shell punch perforates a shell plate whose
cells fail (rwall_fem/contact/erosion.py, ErodingShells; the solids' model:
tests/verification/test_contact_erosion.py).

A 20 x 20 mm steel plate of 1 mm shells (1 mm thick, its edges held; a cell fails when 3
of its 5 points reach the plastic strain 0.3) is struck flat at 300 m/s by a 6 x 6 mm
punch of 1 mm shells (3 mm thick, ten times steel's density, yield 5 GPa), the punch's
nodes off the plate's (a quarter cell). One [[contact]], the plate main and the punch
secondary, both passes. References independent of the code:

- the plate's segments after the run are its live shells, built from scratch
  (shell_surface of the live cells): an eroded shell's segment left, no other did;
- no pass holds a segment of an eroded shell, nor a secondary node that no live shell
  holds (the nodes the erosion detached);
- no contact force on a node that no live shell holds, from the step after its last
  shell eroded (the contact follows the erosion one step later, as Radioss's interfaces);
- the punch gets through (its lowest node below the plate);
- the books close as the erosion tests' do (max balance error <= 1e-12 of the initial
  energy): an eroded shell takes its internal energy, a spring on a segment that leaves
  keeps its work in contact_energy;
- 2 ranks equal 1 to 1e-10 (energy.csv and contacts.csv, the same eroded cells).
"""

import copy

import numpy as np
from conftest import StopAt, run
from mpi4py import MPI

from rwall_fem import build_simulation, parse_scene
from rwall_fem.contact.surface import once

comm = MPI.COMM_WORLD

GEO = """h = 0.001;
Point(1) = {0, 0, 0, h};
ex[] = Extrude {0.02, 0, 0} { Point{1}; Layers{20}; Recombine; };
ey[] = Extrude {0, 0.02, 0} { Line{ex[1]}; Layers{20}; Recombine; };
Physical Surface("plate") = {ey[1]};
Physical Curve("edge") = {ex[1], ey[0], ey[2], ey[3]};
Point(101) = {0.00725, 0.00725, 0.003, h};
px[] = Extrude {0.006, 0, 0} { Point{101}; Layers{6}; Recombine; };
py[] = Extrude {0, 0.006, 0} { Line{px[1]}; Layers{6}; Recombine; };
Physical Surface("punch") = {py[1]};
"""
STEEL = {"model": "elastic_plastic", "density": 7850.0, "young": 200e9, "poisson": 0.3,
         "hardening": "linear", "yield_stress": 400e6, "hardening_modulus": 1e9}  # fmt: skip


def punch_scene(directory):
    path = directory / "punch.geo"
    if comm.rank == 0:
        path.write_text(GEO)
    comm.Barrier()
    failing = STEEL | {"failure": {"criterion": "plastic_strain", "plastic_strain": 0.3}}
    return {
        "run": {"end_time": 6e-5},
        "mesh": {"file": str(path)},
        "material": STEEL,
        "part": [
            {"name": "plate", "material": failing,
             "element": {"thickness": 1e-3, "failed_share": 0.6}},
            {"name": "punch", "material": STEEL | {"density": 78500.0, "yield_stress": 5e9},
             "element": {"thickness": 3e-3}, "initial": {"velocity": [0.0, 0.0, -300.0]}},
        ],  # fmt: skip
        "boundary": [{"group": "edge", "velocity": [0.0, 0.0, 0.0]}],
        "contact": [{"main": ["plate"], "secondary": ["punch"]}],
        "output": {"plot": False, "history_interval": 1},
    }


class DetachedForces:
    """Recorder: the largest contact force (N) on a node that no live shell held at the
    previous step, over the run (this rank's owned nodes)."""

    def __init__(self, sim):
        self.erosion, self.contact = sim.internal.erosion, sim.contacts[0]
        self.before = np.zeros(0, dtype=np.int64)
        self.largest, self.checked = 0.0, 0
        sim.recorders.append(self)

    def due(self, s):
        return True

    def record(self, sim, s):
        rows, force, _ = self.contact.nodal_forces()
        on = np.isin(rows, self.before)
        self.checked += int(on.sum())
        self.largest = max(self.largest, float(np.abs(force[on]).max(initial=0.0)))
        self.before = np.asarray(self.erosion.detached, dtype=np.int64)

    def close(self, sim):
        pass


def test_a_punch_perforates_a_shell_plate_whose_eroded_shells_leave_the_contact(
    shared_dir, tmp_path_factory
):
    raw = punch_scene(shared_dir)
    sim = build_simulation(parse_scene(copy.deepcopy(raw), source="test"), comm, shared_dir)
    watch = DetachedForces(sim)
    assert sim.run() == "done"
    contact = sim.contacts[0]
    plate = contact.surfaces[0]
    eroded = comm.allreduce(int((~plate.alive).sum()))
    assert eroded > 0 and contact.updates > 0
    # The segments are the live shells' built from scratch.
    scratch = once(plate.ids[plate.alive], plate.values[plate.alive], comm)
    for name in ("segments", "stiffness", "depth", "edge"):
        assert np.array_equal(getattr(plate.surface, name), getattr(scratch, name)), name
    # No pass holds an eroded shell's segment or a node no live shell holds.
    dead = {tuple(k) for k in np.concatenate(
        comm.allgather(np.sort(plate.ids[~plate.alive], axis=1)))}  # fmt: skip
    _, _, segments = contact.nodal_forces()
    assert not dead & {tuple(k) for k in np.sort(segments, axis=1)}
    owned = sim.internal.erosion.detached
    to_global = sim.internal.V.dofmap.index_map.local_to_global
    detached = np.concatenate(comm.allgather(to_global(np.asarray(owned, dtype=np.int32))))
    assert len(detached) > 0
    for share in contact.shares:  # each rank's secondary nodes (global numbers)
        assert not np.isin(share.secondary, detached).any()
    # No force on a detached node from the step after it detached.
    assert comm.allreduce(watch.checked) > 0
    assert comm.allreduce(watch.largest, op=MPI.MAX) == 0.0
    # The punch went through; the books close.
    names = [p.name for p in sim.internal.parts]
    s = sim.state
    held = sim.internal.held[: len(s.mass), names.index("punch")] > 0
    lowest = comm.allreduce(float((s.X + s.u)[held, 2].min(initial=np.inf)), op=MPI.MIN)
    assert lowest < -1e-3, lowest
    summary = sim.history.summary
    assert summary["energy"]["max_balance_error"] <= 1e-12
    # 2 ranks equal 1.
    if comm.size > 1:
        serial = None
        if comm.rank == 0:
            alone = run(raw, tmp_path_factory.mktemp("serial"), comm=MPI.COMM_SELF)
            serial = (alone.history.summary["erosion"]["eroded_cells"], alone.history.energy,
                      alone.history.contact(0))  # fmt: skip
        count, energy, table = comm.bcast(serial, root=0)
        assert count == summary["erosion"]["eroded_cells"]
        mine = sim.history.energy
        assert mine.shape == energy.shape
        scale = summary["energy"]["initial"]
        assert np.abs(mine[:, 1:-2] - energy[:, 1:-2]).max() <= 1e-10 * scale
        rows = sim.history.contact(0)
        assert np.array_equal(rows[:, 9], table[:, 9])  # the same nodes in contact
        for columns in (slice(2, 5), slice(5, 8), slice(8, 9)):
            size = np.abs(table[:, columns]).max()
            assert np.abs(rows[:, columns] - table[:, columns]).max() <= 1e-10 * size, columns


def test_a_resumed_punch_with_eroding_shells_equals_the_uninterrupted_run(shared_dir):
    """Stopped after shells eroded (the surface changed), resumed from its checkpoint: the
    segments are built again from the live shells, and the outputs are the same to the
    bit."""
    raw = punch_scene(shared_dir)
    raw["run"]["end_time"] = 3e-5
    raw["output"]["checkpoint_steps"] = 10
    whole = run(raw, shared_dir / "whole")
    out = shared_dir / "stopped"
    sim = build_simulation(parse_scene(copy.deepcopy(raw), source="test"), comm, out)
    sim.recorders.append(StopAt(80))  # shells erode from step 55 to 104
    assert sim.run().startswith("stopped: step 80,")
    assert sim.contacts[0].updates > 0  # stopped after the surface changed
    resumed = build_simulation(parse_scene(copy.deepcopy(raw), source="test"), comm, out)
    resumed.checkpoints.resume(resumed)
    assert resumed.run() == "done"
    assert resumed.contacts[0].updates > sim.contacts[0].updates  # more erosion after it
    assert np.array_equal(resumed.state.u, whole.state.u)
    np.testing.assert_array_equal(resumed.contacts[0].surfaces[0].surface.segments,
                                  whole.contacts[0].surfaces[0].surface.segments)  # fmt: skip
    comm.Barrier()
    if comm.rank == 0:
        for name in ("energy.csv", "contacts.csv"):
            assert (out / name).read_text() == (shared_dir / "whole" / name).read_text()


def _lists(share) -> dict[tuple, tuple]:
    """The nodes (global numbers) each segment this rank owns in ``share`` leaves out of
    its search, by the segment's sorted nodes."""
    offsets, ids = share.removed
    return {tuple(sorted(seg)): tuple(ids[offsets[j] : offsets[j + 1]])
            for seg, j in zip(share.segments.tolist(), share.places.tolist())}  # fmt: skip


def test_the_lists_of_exclude_within_gap_outlive_the_erosion(shared_dir):
    """The punch with the plate in contact with itself as well (single surface, a gap of
    1.5 mm over 1 mm shells, exclude_within_gap: Radioss Irem_gap 2): after shells eroded,
    each segment left has the list it had at the start (Radioss builds them once; a walk
    over the shells left would give the nodes across a crack to the segments before it:
    tests/unit/test_contact_removal.py), the punch gets through and the books close."""
    raw = punch_scene(shared_dir)
    raw["contact"] = [{"self": True, "gap": 1.5e-3, "exclude_within_gap": True}]
    sim = build_simulation(parse_scene(copy.deepcopy(raw), source="test"), comm, shared_dir)
    contact = sim.contacts[0]
    start = [_lists(share) for share in contact.shares]
    assert sum(len(v) for lists in start for v in lists.values()) > 0
    assert sim.run() == "done"
    eroded = comm.allreduce(int((~contact.surfaces[0].alive).sum()))
    assert eroded > 0 and contact.updates > 0
    for before, share in zip(start, contact.shares, strict=True):
        now = _lists(share)
        assert now.keys() <= before.keys()
        assert all(now[key] == before[key] for key in now)
    names = [p.name for p in sim.internal.parts]
    held = sim.internal.held[: len(sim.state.mass), names.index("punch")] > 0
    lowest = comm.allreduce(float((sim.state.X + sim.state.u)[held, 2].min(initial=np.inf)),
                            op=MPI.MIN)  # fmt: skip
    assert lowest < -1e-3, lowest
    assert sim.history.summary["energy"]["max_balance_error"] <= 1e-12
