"""Failure and erosion against independent references (docs/theory.md, "Failure and erosion").

- A bar pulled apart by prescribed end velocities is in uniaxial stress (triaxiality 1/3):
  Johnson-Cook's criterion without its rate and temperature terms fails it at the closed
  form eps_f = D1 + D2 exp(D3 / 3), whatever the element technology. The end velocities
  rise smoothly (a smoothstep over 60 % of the pull), so that the bar yields without
  ringing: the strain at which the damage of the first cell to fail reaches 1 (within the
  step in which it does, the step that cell is eroded in) is eps_f to within the plastic
  strain of that step (seen: 0.01-0.15 of it).
- Path independence: in the rate-free case, pulling twice as fast fails the bar at the same
  strain, to within the strain of one step.
- The energy books: the cells take their internal energy with them (eroded_internal), and
  the balance closes to round-off; what they took is the plastic work of uniaxial
  tension with linear hardening, sigma_y eps_f + H eps_f^2 / 2 per volume, with the
  elastic energy sigma^2 / (2 E), and what is left to the live cells is nil once they
  have all eroded (the cells' books against the nodes', to 1e-3).
- Detached nodes: once every cell is eroded, every node flies at constant velocity
  (exactly) until a wall meets it; the wall then stops its normal velocity and nothing
  else.
- The same answers on 1 and 2 ranks (the eroded cells, the energies to 1e-10), and a run
  resumed after cells eroded equals the run that never stopped, to the last bit.
- run.dt_min_action = "erode": the step never goes below dt_min; the cells that would
  take it there are eroded, and the books close.
"""

import copy
import math

import numpy as np
import pytest
from conftest import StopAt, run
from mpi4py import MPI

from rwall_fem import build_simulation, parse_scene

D = {"d1": 0.05, "d2": 0.5, "d3": -1.5}  # rate- and temperature-free Johnson-Cook
EPS_F = D["d1"] + D["d2"] * math.exp(D["d3"] / 3.0)  # at triaxiality 1/3: 0.3533
STEEL = {
    "model": "elastic_plastic", "density": 7850.0, "young": 200e9, "poisson": 0.3,
    "hardening": "linear", "yield_stress": 400e6, "hardening_modulus": 1e9,
}  # fmt: skip
TECHNOLOGIES = {
    "tet": ("tetrahedron", {}),
    "full": ("hexahedron", {"integration": "full"}),
    "physical": ("hexahedron", {"hourglass": "physical"}),
    "stiffness": ("hexahedron", {"hourglass": "stiffness"}),
    "viscous": ("hexahedron", {"hourglass": "viscous"}),
    "none": ("hexahedron", {"hourglass": "none"}),
}


def pull_scene(technology="physical", speed=1.2, cells=4, h=1e-3, failure=None, drift=0.0):
    """A steel bar of ``cells`` cells of side h (m) along z, its end faces pulled apart in z at
    ``speed`` (m/s each) after a smoothstep ramp over 60 % of the pull, run a little past
    the strain eps_f; lateral faces free, so that it is in uniaxial stress. ``drift``
    (m/s): a uniform initial velocity along x."""
    length = cells * h
    rate = 2.0 * speed / length
    pull = 1.1 * math.expm1(EPS_F + 0.01) / rate
    ramp = 0.6 * pull
    table = [[ramp * x, 0.0, 0.0, speed * (3 * x**2 - 2 * x**3)] for x in np.linspace(0, 1, 9)]
    cell, element = TECHNOLOGIES[technology]
    raw = {
        "run": {"end_time": pull + 0.5 * ramp},
        "mesh": {"shape": "bar", "size": [h, h, length], "element_size": h, "cell": cell},
        "material": STEEL | {"failure": failure or {"criterion": "johnson_cook", **D}},
        "initial": {"velocity": [drift, 0.0, 0.0]},
        "boundary": [
            {
                "group": "bottom",
                "velocity": [[t, 0.0, 0.0, -v] for t, _, _, v in table],
                "components": "z",
            },
            {"group": "top", "velocity": table, "components": "z"},
        ],  # fmt: skip
        "output": {"plot": False, "history_interval": 50},
    }
    if element:
        raw["element"] = element
    return raw


class Failures:
    """Recorder of the cells as they erode: for each, the step, and at its point of largest
    damage the plastic strain and damage of the step before and of the step it was eroded
    in. ``events`` (every rank's cells, by step) is complete once the run has closed."""

    def __init__(self, sim):
        self.force, self.comm = sim.internal.elements[0], sim.comm  # the body's one part
        self.before = None
        self.events = []
        sim.recorders.append(self)

    def due(self, s):
        return True

    def record(self, sim, s):
        f = self.force
        damage, strain = f.damage, f.plastic_strains()
        if self.before is not None:
            for c in np.flatnonzero(self.before[2] & ~f.erosion.alive):
                q = int(np.argmax(damage[:, c]))
                old_strain, old_damage = self.before[0][q, c], self.before[1][q, c]
                self.events.append((s.step, old_strain, old_damage, strain[q, c], damage[q, c]))
        self.before = (strain.copy(), damage.copy(), f.erosion.alive.copy())

    def close(self, sim):
        self.events = sorted(e for rank in self.comm.allgather(self.events) for e in rank)

    def first(self):
        """The events of the first step in which cells eroded."""
        return [e for e in self.events if e[0] == self.events[0][0]]


def pulled(raw, directory, comm=MPI.COMM_WORLD):
    sim = build_simulation(parse_scene(copy.deepcopy(raw), source="test"), comm, directory)
    failures = Failures(sim)
    assert sim.run() == "done"
    return sim, failures


def crossing(event) -> tuple[float, float]:
    """The plastic strain at which the damage of an eroded cell's point reached 1,
    interpolated within the step it did, and that step's plastic strain increment."""
    _, old_strain, old_damage, strain, damage = event
    assert old_damage < 1.0 <= damage  # the cell is eroded in the step D reaches 1
    share = (1.0 - old_damage) / (damage - old_damage)
    return old_strain + share * (strain - old_strain), strain - old_strain


@pytest.mark.parametrize("technology", TECHNOLOGIES)
def test_a_pulled_bar_fails_at_the_closed_form_strain(technology, shared_dir):
    sim, failures = pulled(pull_scene(technology), shared_dir)
    for event in failures.first():
        strain, step = crossing(event)
        assert abs(strain - EPS_F) <= step, (strain - EPS_F) / step
    assert sim.history.summary["energy"]["max_balance_error"] <= 1e-12


def test_damage_is_path_independent(shared_dir):
    """Rate-free: twice as fast, the same failure strain to within a step's strain."""
    fast = pulled(pull_scene(speed=1.2), shared_dir / "fast")[1].first()[0]
    slow = pulled(pull_scene(speed=0.6), shared_dir / "slow")[1].first()[0]
    (strain_fast, step), (strain_slow, _) = crossing(fast), crossing(slow)
    assert abs(strain_fast - strain_slow) <= step
    assert abs(strain_slow - EPS_F) <= step / 2  # half the rate, half the step


def test_eroded_cells_take_their_internal_energy(shared_dir):
    """Fully integrated hexahedra stay uniform: every cell fails in the same step. They take
    the plastic work of linear hardening to eps_f and their elastic energy with them; the
    live cells are left nothing, and the balance closes to round-off."""
    sim, failures = pulled(pull_scene("full"), shared_dir)
    summary = sim.history.summary
    energy = summary["energy"]
    assert summary["erosion"]["eroded_cells"] == sim.info["cells"]
    strain = np.mean([e[3] for e in failures.events])
    A, H, E = STEEL["yield_stress"], STEEL["hardening_modulus"], STEEL["young"]
    stress = A + H * strain
    volume = 4e-9
    expected = volume * (A * strain + H * strain**2 / 2 + stress**2 / (2 * E))
    assert energy["eroded_internal"] == pytest.approx(expected, rel=2e-3)
    assert abs(energy["internal"]) <= 1e-3 * energy["eroded_internal"]
    for part in ("plastic_work", "elastic"):  # of the live cells: none
        assert abs(energy[part]) <= 1e-12 * energy["eroded_internal"]
    assert energy["max_balance_error"] <= 1e-12
    table = sim.history.energy  # the count column of energy.csv: 0, then all
    assert set(table[:, -1]) == {0.0, sim.info["cells"]}


def test_a_part_that_fails_erodes_alone_and_the_books_close(shared_dir):
    """The pulled bar of fully integrated hexahedra made of two parts of the same steel,
    only the first cell's ("weak", the bar's front region) with the failure criterion: that
    cell erodes at eps_f and takes the energy of uniaxial tension with it (as the bar of one
    part does), the other part none; of the nodes, only the four that no other cell holds
    are detached (those it shares with the other part stay held). The balance closes to
    round-off and the parts' internal energies add up to the body's."""
    raw = pull_scene("full")
    h = raw["mesh"]["element_size"]
    raw["mesh"]["front_length"] = h
    raw["part"] = [
        {"name": "weak", "volumes": ["front"], "material": raw.pop("material")},
        {"name": "strong", "volumes": ["body"], "material": STEEL},
    ]
    sim, failures = pulled(raw, shared_dir)
    summary = sim.history.summary
    assert summary["erosion"]["eroded_cells"] == 1
    assert summary["erosion"]["detached_nodes"] == 4
    strain = np.mean([e[3] for e in failures.events])
    A, H, E = STEEL["yield_stress"], STEEL["hardening_modulus"], STEEL["young"]
    stress = A + H * strain
    expected = h**3 * (A * strain + H * strain**2 / 2 + stress**2 / (2 * E))
    energy = summary["energy"]
    assert energy["eroded_internal"] == pytest.approx(expected, rel=2e-3)
    assert energy["max_balance_error"] <= 1e-12
    parts = {part["name"]: part["energy"] for part in summary["parts"]}
    total = parts["weak"]["internal"] + parts["strong"]["internal"]
    assert total == pytest.approx(energy["internal"], rel=1e-12, abs=1e-12 * expected)


class Velocities:
    """Recorder of every owned node's velocity v^{n-1/2} (m/s) and position (m) from the step
    after ``start`` on; ``contacts``: the steps in which the wall treated a node."""

    def __init__(self, sim, start):
        self.start, self.v, self.x, self.steps = start, [], [], []
        sim.recorders.append(self)

    def due(self, s):
        return s.step > self.start

    def record(self, sim, s):
        self.steps.append(s.step)
        self.v.append(s.v.copy())
        self.x.append(s.X + s.u)

    def close(self, sim):
        self.v, self.x = np.array(self.v), np.array(self.x)


def test_detached_nodes_fly_freely_and_meet_a_wall(shared_dir):
    """A bar drifting sideways at 0.5 m/s is pulled apart (fully integrated hexahedra: every
    cell fails in one step); then every node flies at constant velocity, to the last bit,
    until the plane it drifts into stops its normal velocity (half of them by the end):
    its tangential velocity is left as it was, and no node ends behind the plane."""
    raw = pull_scene("full", drift=0.5)
    first = pulled(raw, shared_dir / "probe")[1].events[0][0]  # the step every cell fails in
    raw["run"]["end_time"] *= 1.3
    plane = 1.42e-3  # beyond the bar's side at the failure: the nodes reach it afterwards
    raw["wall"] = [{"kind": "plane", "point": [plane, 0, 0], "normal_point": [0, 0, 0]}]
    sim = build_simulation(parse_scene(copy.deepcopy(raw), source="test"), MPI.COMM_WORLD,
                           shared_dir / "wall")  # fmt: skip
    probe = Velocities(sim, first)
    assert sim.run() == "done"
    assert sim.history.summary["erosion"]["eroded_cells"] == sim.info["cells"]
    wall = sim.history.summary["walls"][0]
    assert wall["first_contact"] > sim.state.dt * (first + 10)  # well after the failure
    v, x = probe.v, probe.x
    free = v[:, :, 0] > 1e-9  # drifting toward the plane (0.1 to 0.9 m/s): not yet stopped
    changed = np.any(v[1:] != v[:-1], axis=2)
    assert not np.any(changed & free[1:])  # in flight, no velocity ever changes
    stopped = ~free[-1]  # the nodes of the side nearer the plane, by the end
    assert MPI.COMM_WORLD.allreduce(int(stopped.sum())) >= sim.info["nodes"] // 2
    assert np.abs(v[-1][stopped, 0]).max(initial=0.0) <= 1e-15  # the normal velocity is gone
    assert np.array_equal(v[-1][:, 1:], v[0][:, 1:])  # the tangential one is as it was
    assert x[-1][:, 0].max(initial=-np.inf) <= plane


def punch_scene(end_time=40e-6) -> dict:
    """A clamped steel plate (8 x 8 x 2 mm, 2 layers of 1 mm hexahedra: the bar shape, whose
    partition is the same in every build of a process) punched through by a 5 mm sphere of
    10 g at 300 m/s (a wall carried by a main node): cells fail at a plastic strain of 0.3
    from the 20th step on, 56 of 128 by the 100th."""
    return {
        "run": {"end_time": end_time},
        "mesh": {"shape": "bar", "size": [8e-3, 8e-3, 2e-3], "element_size": 1e-3},
        "material": STEEL | {"failure": {"criterion": "plastic_strain", "plastic_strain": 0.3}},
        "boundary": [{"group": "sides"}],
        "wall": [
            {
                "kind": "sphere",
                "point": [4e-3, 4e-3, 4.5e-3],
                "diameter": 5e-3,
                "motion": {"mass": 0.01, "velocity": [0.0, 0.0, -300.0]},
                "secondary": {"exclude": ["sides"]},
            }
        ],
        "output": {"plot": False},
    }


def eroded_centroids(sim) -> np.ndarray:
    """The reference centroids (m) of the eroded cells of every rank, sorted, rounded to a
    nanometre (the mesher's round-off differs between partitions)."""
    f = sim.internal
    mine = f.X[f.cells[~f.erosion.alive]].mean(axis=1)
    every = np.round(np.concatenate(sim.comm.allgather(mine)), 9)
    return every[np.lexsort(every.T[::-1])]


def test_the_punched_plate_erodes_and_keeps_its_books(shared_dir):
    """The punched plate: about half its cells erode, some nodes are left detached, and the
    books close to round-off (on 2 ranks too; its answers are not compared with one rank's:
    a detached node riding the sphere sits on it to round-off, and whether the sphere
    catches it in a step is decided by the round-off of the sum over ranks)."""
    sim = run(punch_scene(), shared_dir)
    summary = sim.history.summary
    assert 30 <= summary["erosion"]["eroded_cells"] <= 100  # of 128
    assert summary["erosion"]["detached_nodes"] > 0
    assert summary["energy"]["max_balance_error"] <= 1e-12


def neck_scene() -> dict:
    """A steel bar (4 x 4 x 12 mm, 1 mm hexahedra) held at one end and pulled at the other
    to 10 m/s over 0.1 ms: it necks, and the neck's whole cross-section (16 cells) fails at a
    plastic strain of 0.25 at about 0.2 ms."""
    ramp = [[1e-4 * x, 0.0, 0.0, 10.0 * (3 * x**2 - 2 * x**3)] for x in np.linspace(0, 1, 5)]
    return {
        "run": {"end_time": 3e-4},
        "mesh": {"shape": "bar", "size": [4e-3, 4e-3, 12e-3], "element_size": 1e-3},
        "material": STEEL
        | {
            "hardening_modulus": 1e8,
            "failure": {"criterion": "plastic_strain", "plastic_strain": 0.25},
        },
        "boundary": [{"group": "bottom"}, {"group": "top", "velocity": ramp}],
        "output": {"plot": False, "history_interval": 20},
    }


def test_the_same_cells_erode_on_any_number_of_ranks(shared_dir, tmp_path):
    """The necking bar: the eroded cells, their count at every sample and the energies are
    those of one rank (to 1e-10), and the books close to round-off."""
    sim = run(neck_scene(), shared_dir)
    summary = sim.history.summary
    assert summary["erosion"]["eroded_cells"] == 16
    assert summary["energy"]["max_balance_error"] <= 1e-12
    if MPI.COMM_WORLD.size > 1:
        serial = run(neck_scene(), tmp_path, comm=MPI.COMM_SELF)
        mine, one = eroded_centroids(sim), eroded_centroids(serial)
        assert mine.shape == one.shape and np.abs(mine - one).max() <= 1e-12  # m: the same cells
        e, f = sim.history.energy, serial.history.energy
        assert e.shape == f.shape
        assert np.array_equal(e[:, -1], f[:, -1])  # the eroded cells, sample by sample
        assert np.abs(e[:, 1:-2] - f[:, 1:-2]).max() <= 1e-10 * np.abs(f[:, 1:-2]).max()


def test_a_run_resumed_after_erosion_equals_the_uninterrupted_one(shared_dir):
    """Stopped while the plate is being punched through (some cells eroded, more to come),
    resumed from its checkpoint: every output is that of the run that never stopped, to
    the last bit."""
    whole = run(punch_scene(), shared_dir / "whole")
    out = shared_dir / "stopped"
    sim = build_simulation(parse_scene(punch_scene(), source="test"), MPI.COMM_WORLD, out)
    sim.recorders.append(StopAt(60))
    assert sim.run().startswith("stopped: step 60,")
    eroded = sim.history.summary["erosion"]["eroded_cells"]
    assert 0 < eroded < whole.history.summary["erosion"]["eroded_cells"]
    resumed = build_simulation(parse_scene(punch_scene(), source="test"), MPI.COMM_WORLD, out)
    resumed.checkpoints.resume(resumed)
    assert resumed.run() == "done"
    assert np.array_equal(resumed.state.u, whole.state.u)
    assert np.array_equal(resumed.internal.erosion.alive, whole.internal.erosion.alive)
    assert np.array_equal(resumed.internal.elements[0].history, whole.internal.elements[0].history)
    MPI.COMM_WORLD.Barrier()
    if MPI.COMM_WORLD.rank == 0:
        for name in ("energy.csv", "walls.csv"):
            assert (out / name).read_text() == (shared_dir / "whole" / name).read_text()


def test_dt_min_erodes_the_cells_below_it(shared_dir):
    """The crushed copper bar, whose step falls over three times without control: with
    dt_min_action = "erode" the step never goes below dt_min, a few crushed cells are
    eroded instead, their energy booked: momentum (no external force) and the balance are
    exact to round-off."""
    from test_time_step import crush_scene, momentum_error

    sim = run(crush_scene(dt_min=5e-8, dt_min_action="erode"), shared_dir)
    summary = sim.history.summary
    assert summary["status"] == "done"
    assert summary["time_step"]["smallest"] >= 5e-8
    assert 0 < summary["erosion"]["eroded_cells"] < sim.info["cells"] // 16
    assert summary["energy"]["eroded_internal"] > 0.0
    assert momentum_error(summary) <= 1e-13
    assert summary["energy"]["max_balance_error"] <= 1e-12


class ErodeFrom:
    """Recorder that, at ``step``, raises the step below which the force's cells erode to
    ``floor`` (s)."""

    def __init__(self, step, floor):
        self.step, self.floor = step, floor

    def due(self, s):
        return s.step == self.step

    def record(self, sim, s):
        for force in sim.internal.elements:
            force.params.erode_step = self.floor

    def close(self, sim):
        pass


def test_eroding_a_linear_elastic_body_keeps_its_books_exact(shared_dir):
    """Central differences conserve K + 1/2 u.Ku of a linear elastic body exactly; cells
    eroded in the middle of its motion take 1/2 u^{n-1}.K_c u^n with them (failure.h), and
    the books still close to round-off. The bar is meshed finer about a point, and from
    step 40 the cells whose step is below the middle of the range erode; a wall at the
    other end keeps the bar ringing."""
    raw = {
        "run": {"end_time": 30e-6, "dt_min": 1e-12, "dt_min_action": "erode"},
        "mesh": {
            "shape": "bar",
            "size": [4e-3, 4e-3, 16e-3],
            "element_size": 2e-3,
            "refine_point": [2e-3, 2e-3, 16e-3],
            "refine_size": 0.7e-3,
            "refine_radius": 4e-3,
        },
        "material": {
            "model": "linear_elastic",
            "density": 7850.0,
            "young": 200e9,
            "poisson": 0.3,
        },
        "initial": {"velocity": [0.0, 0.0, -50.0]},
        "wall": [{"kind": "plane", "point": [0, 0, 0], "normal_point": [0, 0, 1]}],
        "output": {"plot": False},
    }
    sim = build_simulation(parse_scene(raw, source="test"), MPI.COMM_WORLD, shared_dir)
    steps = sim.comm.allgather(sim.internal.steps_at_rest())
    floor = float(np.median(np.concatenate(steps)))
    sim.recorders.append(ErodeFrom(40, floor))
    assert sim.run() == "done"
    summary = sim.history.summary
    eroded = summary["erosion"]["eroded_cells"]
    assert 0 < eroded < sim.info["cells"]
    energy = summary["energy"]
    assert energy["eroded_internal"] > 1e-3 * energy["initial"]
    assert energy["max_balance_error"] <= 1e-12


def test_the_outputs_carry_damage_and_erosion(shared_dir):
    """The punched plate's fields hold each cell's damage and eroded flag; its frames leave
    the eroded cells out and draw the detached nodes (pictures: serial runs only, as the
    demos' test)."""
    pictures = MPI.COMM_WORLD.size == 1
    raw = punch_scene()
    raw["output"] |= {"fields": 2, "frames": 2 if pictures else 0, "color": "damage"}
    sim = run(raw, shared_dir)
    fields = sim.internal.cell_fields(sim.state)
    assert np.array_equal(fields["eroded"], (~sim.internal.erosion.alive).astype(float))
    assert np.all(fields["damage"][fields["eroded"] == 0.0] < 1.0)
    MPI.COMM_WORLD.Barrier()
    if MPI.COMM_WORLD.rank == 0:
        xdmf = (shared_dir / "fields.xdmf").read_text()
        assert 'Name="damage"' in xdmf and 'Name="eroded"' in xdmf
    if pictures:
        last = np.load(shared_dir / "frames" / "data" / "frame_0001.npz")
        assert last["cell_eroded"].sum() == sim.history.summary["erosion"]["eroded_cells"]
        assert last["detached"].sum() > 0
        assert len(list((shared_dir / "frames").glob("frame_*.png"))) == 2
