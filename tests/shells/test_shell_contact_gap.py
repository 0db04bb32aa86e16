"""A flat sheet of shells finer than its thickness does not touch itself (the variable
gap of self-contact capped by the element size: Radioss TYPE7 Igap 3, LS-DYNA's
automatic contacts).

A steel sheet 1.5 mm thick meshed in 0.5 mm quadrilaterals with ``self = true``: half
the sum of the thicknesses (1.5 mm) is three elements, so without the cap every node is
within the gap of the coplanar segments of its own sheet beyond those that hold it.
With each shell's share of the gap at most 0.4 x its shortest side (0.2 mm), the pair gap
is 0.4 mm, less than the 0.5 mm from a node to the nearest segment it may meet.

References independent of the code:

- a sheet moving rigidly (uniform velocity, no load) stays rigid: no node in contact at
  any step, every velocity its initial one to round-off (1e-12 of it);
- a cantilever sheet (one edge clamped, the rest thrown at 2 m/s) bending gently: no node
  in contact at any step, and the run is the run without contact to round-off;
- no node starts within the gap of its sheet (where the old rule, the cap left out, has
  most of them: they are taken as initial penetrations, Radioss Inacti 6, and their gaps
  shrunk to 0.95 of their distances, which a fold coming later then meets).
"""

import numpy as np
import pytest
from mpi4py import MPI

import rwall_fem.contact as contact_module
from rwall_fem import build_simulation, parse_scene

comm = MPI.COMM_WORLD
STEEL = {"model": "linear_elastic", "density": 7850.0, "young": 210e9, "poisson": 0.3}
V0 = [3.0, -2.0, -5.0]  # m/s


def sheet(contact: bool, clamped: bool) -> dict:
    """A 12 x 8 mm steel sheet, 1.5 mm thick, in 0.5 mm quadrilaterals, for 20 us."""
    raw = {
        "run": {"end_time": 2e-5},
        "mesh": {"shape": "plate", "size": [0.012, 0.008, 1.5e-3], "element_size": 5e-4,
                 "cell": "quadrilateral"},
        "material": dict(STEEL),
        "element": {"thickness": 1.5e-3},
        "initial": {"velocity": [0.0, 0.0, -2.0] if clamped else V0},
        "output": {"plot": False, "frames": 0},
    }  # fmt: skip
    if clamped:
        raw["boundary"] = [{"group": "side_x0", "velocity": [0.0, 0.0, 0.0]}]
    if contact:
        raw["contact"] = [{"self": True}]
    return raw


def starting_inside(sim) -> int:
    """The nodes within the gap at the start (every rank sees the whole surface)."""
    return comm.allreduce(int(sim.contacts[0].starting_inside[0]), op=MPI.MAX)


class InContact:
    """Recorder: the most nodes in contact at any step (all ranks)."""

    def __init__(self, sim):
        self.contact, self.most = sim.contacts[0], 0
        sim.recorders.append(self)

    def due(self, s):
        return True

    def record(self, sim, s):
        self.most = max(self.most, int(self.contact.contacts))

    def close(self, sim):
        pass


def run_sheet(shared_dir, contact: bool, clamped: bool):
    sim = build_simulation(parse_scene(sheet(contact, clamped), source="test"), comm,
                           shared_dir)  # fmt: skip
    watch = InContact(sim) if contact else None
    assert sim.run() == "done"
    return sim, watch


def test_a_rigidly_moving_fine_sheet_does_not_touch_itself(shared_dir):
    sim, watch = run_sheet(shared_dir, contact=True, clamped=False)
    interface = sim.contacts[0]
    drift = comm.allreduce(float(np.abs(sim.state.v - V0).max(initial=0.0)), op=MPI.MAX)
    print(f"rigid sheet: most nodes in contact {watch.most}, pair gap {interface.gap_max:.3e} m,"
          f" velocity drift {drift:.2e} m/s")
    assert interface.gap_max == pytest.approx(0.8 * 5e-4, rel=1e-9)
    assert watch.most == 0 and starting_inside(sim) == 0
    assert interface.energy == 0.0
    assert drift <= 1e-12 * np.linalg.norm(V0)


def test_a_gently_bending_fine_sheet_does_not_touch_itself(shared_dir):
    sim, watch = run_sheet(shared_dir, contact=True, clamped=True)
    free, _ = run_sheet(shared_dir, contact=False, clamped=True)
    u, u_free = sim.state.u, free.state.u
    scale = comm.allreduce(float(np.abs(u_free).max(initial=0.0)), op=MPI.MAX)
    differ = comm.allreduce(float(np.abs(u - u_free).max(initial=0.0)), op=MPI.MAX)
    print(f"bending sheet: most nodes in contact {watch.most}, tip deflection {scale:.3e} m,"
          f" against no contact {differ:.2e} m")
    assert scale > 2e-5  # it bends: 40 um at the free edge
    assert watch.most == 0 and starting_inside(sim) == 0
    assert differ <= 1e-12 * scale


def test_without_the_cap_the_fine_sheet_touches_itself(shared_dir, monkeypatch):
    uncapped = classmethod(lambda cls, spec: cls(size=np.inf))  # the old rule
    monkeypatch.setattr(contact_module.GapShare, "of", uncapped)
    sim = build_simulation(parse_scene(sheet(True, False), source="test"), comm, shared_dir)
    nodes = comm.allreduce(len(sim.state.X))
    inside = starting_inside(sim)
    print(f"uncapped rigid sheet: {inside} of {nodes} nodes start inside the gap, pair gap "
          f"{sim.contacts[0].gap_max:.3e} m")
    assert sim.contacts[0].gap_max == pytest.approx(1.5e-3, rel=1e-9)
    assert inside >= nodes // 2


# A constant gap larger than the mesh: Radioss Irem_gap 2 (``exclude_within_gap``). With
# gap = 1.2 mm (2.4 cells) every node is within the gap of its sheet's coplanar shells one
# and two cells away (0.5 and 1 mm), beyond the shells that hold it. Worked by hand: each segment
# leaves out the nodes within sqrt 2 x 1.2 = 1.70 mm of it along the mesh; a coplanar shell
# within 1.2 mm of a node in the plane has its nearest node at most (2, 1) cells away, 1.21
# mm along the mesh (a diagonal and a side): left out, every one. So with the lists no node
# starts inside the gap or meets its sheet, and the cantilever's run is the run without
# contact, on any number of ranks (the lists travel with the segments).
LARGE_GAP = {"self": True, "gap": 1.2e-3}


@pytest.mark.parametrize("within", [False, True], ids=["neighbours_only", "exclude_within_gap"])
def test_a_gap_larger_than_the_mesh_with_the_lists(within, shared_dir):
    raw = sheet(True, False)
    raw["contact"] = [LARGE_GAP | ({"exclude_within_gap": True} if within else {})]
    sim = build_simulation(parse_scene(raw, source="test"), comm, shared_dir)
    nodes = comm.allreduce(len(sim.state.X))
    inside = starting_inside(sim)
    print(f"gap 1.2 mm, exclude_within_gap {within}: {inside} of {nodes} nodes start inside")
    if not within:
        assert inside >= nodes // 2
        return
    watch = InContact(sim)
    assert sim.run() == "done"
    drift = comm.allreduce(float(np.abs(sim.state.v - V0).max(initial=0.0)), op=MPI.MAX)
    assert inside == 0 and watch.most == 0
    assert drift <= 1e-12 * np.linalg.norm(V0)


def test_a_bending_sheet_with_the_lists_is_the_run_without_contact(shared_dir):
    raw = sheet(True, True)
    raw["contact"] = [LARGE_GAP | {"exclude_within_gap": True}]
    sim = build_simulation(parse_scene(raw, source="test"), comm, shared_dir / "lists")
    watch = InContact(sim)
    assert sim.run() == "done"
    free, _ = run_sheet(shared_dir / "free", contact=False, clamped=True)
    scale = comm.allreduce(float(np.abs(free.state.u).max(initial=0.0)), op=MPI.MAX)
    differ = comm.allreduce(float(np.abs(sim.state.u - free.state.u).max(initial=0.0)),
                            op=MPI.MAX)  # fmt: skip
    print(f"bending sheet, gap 1.2 mm with the lists: most in contact {watch.most}, "
          f"against no contact {differ:.2e} m of {scale:.2e} m")
    assert watch.most == 0 and starting_inside(sim) == 0
    assert differ <= 1e-12 * scale


# A U-fold meeting itself under the lists, on N ranks as on one. A steel strip of 0.5 mm
# shells in 1 mm cells, 3 mm wide, folded into a U (a bottom leg of 10 mm at z = 0, a wall
# of 3 mm, a top leg of 10 mm back at z = 3 mm; the bottom leg's free edge held, the top
# leg's pushed down at 20 m/s), in
# self-contact with a constant gap of 2.5 mm and exclude_within_gap: the legs meet once
# they are within 2.5 mm (their nodes far apart along the mesh, round the wall), while each
# node is left out of its own leg's shells within the gap. The contacts.csv columns on N
# ranks against one, to 1e-10 of their scale (the normal force's for the forces), the same
# nodes in contact at the same steps.
U_GEO = """Point(1) = {0, 0, 0}; Point(2) = {0.01, 0, 0};
Point(3) = {0.01, 0, 0.003}; Point(4) = {0, 0, 0.003};
Line(1) = {1, 2}; Line(2) = {2, 3}; Line(3) = {3, 4};
Transfinite Curve{1, 3} = 11; Transfinite Curve{2} = 4;
a[] = Extrude {0, 0.003, 0} { Line{1}; Layers{3}; Recombine; };
b[] = Extrude {0, 0.003, 0} { Line{2}; Layers{3}; Recombine; };
c[] = Extrude {0, 0.003, 0} { Line{3}; Layers{3}; Recombine; };
Physical Surface("strip") = {a[1], b[1], c[1]};
Physical Curve("root") = {a[2]};
Physical Curve("tip") = {c[3]};
"""


@pytest.mark.skipif(comm.size == 1, reason="compares a partitioned run with a serial one")
def test_a_u_fold_meets_itself_under_the_lists_on_any_ranks(shared_dir, tmp_path):
    path = shared_dir / "u_fold.geo"
    if comm.rank == 0:
        shared_dir.mkdir(parents=True, exist_ok=True)
        path.write_text(U_GEO)
    comm.Barrier()
    raw = {
        "run": {"end_time": 6e-5},
        "mesh": {"file": str(path)},
        "material": dict(STEEL),
        "element": {"thickness": 5e-4},
        "boundary": [{"group": "root", "velocity": [0.0, 0.0, 0.0]},
                     {"group": "tip", "velocity": [0.0, 0.0, -20.0]}],
        "contact": [{"self": True, "gap": 2.5e-3, "exclude_within_gap": True}],
        "output": {"plot": False, "frames": 0},
    }  # fmt: skip
    parallel = build_simulation(parse_scene(raw, source="test"), comm, shared_dir / "u_fold")
    assert parallel.run() == "done"
    serial = build_simulation(parse_scene(raw, source="test"), MPI.COMM_SELF,
                              tmp_path / f"serial{comm.rank}")  # fmt: skip
    assert serial.run() == "done"
    mine, whole = parallel.history.contact(0), serial.history.contact(0)
    print(f"U-fold: nodes in contact at the end {int(whole[-1, 9])}, most {int(whole[:, 9].max())}"
          f", starting inside {starting_inside(parallel)}")
    assert starting_inside(parallel) == 0 and whole[:, 9].max() > 0  # the fold meets
    assert mine.shape == whole.shape and np.array_equal(mine[:, 9], whole[:, 9])
    # A self-contact's net force is a cancellation (both legs' nodes are secondary): its
    # scale is the normal force's (the sum of the pairs' sizes), the impulse's that times
    # the run's time
    normal = np.abs(whole[:, 8]).max()
    scales = {2: normal, 5: normal * raw["run"]["end_time"], 8: normal,
              10: np.abs(whole[:, 10:13]).max()}  # fmt: skip
    for columns in (slice(2, 5), slice(5, 8), slice(8, 9), slice(10, 13)):
        differ = np.abs(mine[:, columns] - whole[:, columns]).max()
        assert differ <= 1e-10 * scales[columns.start], columns
