"""The time step that follows the body (``run.time_step = "adaptive"``), the variable-step
central differences, and the controls for when the step falls.

References: the same scene with a fixed step (an elastic body's stable step does not
change); exact conservation of momentum (a free bar and a wall carried by a main node:
no external force) and of the energy books (central differences with mid-step booking
close exactly, and a linear force's stored energy with the step correction too, whatever
the steps); the published-scale Taylor rod run with a fixed small step.
"""

import copy
import math

import numpy as np
import pytest
from conftest import STEEL_NU0, StopAt, bar_scene, block_scene, run
from mpi4py import MPI

from rwall_fem import build_simulation, parse_scene
from rwall_fem.scene import SceneError
from rwall_fem.time_step import FixedStep

COPPER = {"model": "elastic_plastic", "density": 8930.0, "young": 117e9, "poisson": 0.35,
          "hardening": "linear", "yield_stress": 400e6, "hardening_modulus": 100e6}  # fmt: skip


def contact(sim) -> tuple[float, float, float]:
    """Contact duration (s), wall impulse (N s) and rebound velocity (m/s) of a bar."""
    s = sim.history.summary
    wall = s["walls"][0]
    return (
        wall["last_contact"] - wall["first_contact"],
        -wall["impulse"][2],
        s["final_momentum"][2] / s["mass"],
    )


def test_elastic_bar_adaptive_equals_fixed(shared_dir, tmp_path):
    """A small-strain body's stiffness does not change, so neither does its stable step:
    the adaptive step is the fixed one, and contact duration, impulse and rebound agree
    (to 0.1 %, here to the last bit); the balance closes to round-off."""
    raw = bar_scene(elements=40)
    adaptive = run(raw, shared_dir)
    raw["run"]["time_step"] = "fixed"
    fixed = run(raw, tmp_path if MPI.COMM_WORLD.size == 1 else shared_dir / "fixed")
    steps = adaptive.history.summary["time_step"]
    assert steps["mode"] == "adaptive" and steps["smallest"] == steps["largest"]
    assert adaptive.state.dt == fixed.state.dt
    for a, f in zip(contact(adaptive), contact(fixed), strict=True):
        assert a == pytest.approx(f, rel=1e-3)
    for sim in (adaptive, fixed):
        assert sim.history.summary["energy"]["max_balance_error"] <= 1e-10


def swing(s, dt):
    """A step that swings between 0.6 and 1 times ``dt`` (s) every 16 steps: each up to
    10 % from the one before, far more than an adaptive step changes."""
    return dt * (0.6 + 0.4 * math.sin(s.step / 5.0) ** 2)


@pytest.fixture
def swinging(monkeypatch):
    """Runs a scene (a dict) in a directory with fixed steps made to swing (:func:`swing`)
    of up to its stable step at rest x 0.9."""
    monkeypatch.setattr(FixedStep, "varies", True)

    def choose(self, sim, s):
        s.dt = swing(s, self.dt)

    def advance(self, s):
        s.dt_previous, s.step, s.t = s.dt, s.step + 1, s.t + s.dt

    monkeypatch.setattr(FixedStep, "choose", choose)
    monkeypatch.setattr(FixedStep, "advance", advance)

    def run_swinging(raw, directory):
        raw = copy.deepcopy(raw)
        raw["run"]["time_step"] = "fixed"
        sim = build_simulation(parse_scene(raw, source="test"), MPI.COMM_WORLD, directory)
        assert sim.run() == "done"
        return sim

    return run_swinging


PLANE = {"kind": "plane", "point": [0.0, 0.0, 0.0], "normal_point": [0.0, 0.0, 1.0]}


def wall_scenes():
    """Soft cubes and a steel bar on every wall kind, fixed, carried, driven; friction with
    a filter at a cut-off frequency (alpha follows the step), tied nodes, gravity and a
    driven face."""
    friction = PLANE | {"slide": "friction", "friction": 0.3,
                        "friction_filter": {"frequency": 200.0}}  # fmt: skip
    on_plane = block_scene(h=0.0025, origin=(0.0, 0.0, 1e-4), wall=[friction], end_time=0.02,
                           velocity=(2.0, 0.0, -1.0), gravity=(0.0, 0.0, -9.81))  # fmt: skip
    on_plane["boundary"] = [{"group": "top", "velocity": [[0, 0, 0, 0], [0.02, 0.5, 0, 0]],
                             "components": "x"}]  # fmt: skip
    curved = block_scene(h=0.0025, origin=(-0.005, -0.005, 0.0011), end_time=0.02,
                         velocity=(0.0, 0.0, -1.0), wall=[  # fmt: skip
        {"kind": "sphere", "point": [0.0, 0.0, -0.01], "diameter": 0.022},
        {"kind": "cylinder", "point": [0.0, 0.0, 0.03], "axis_point": [1.0, 0.0, 0.03],
         "diameter": 0.02, "slide": "tied", "motion": {"velocity": [0.0, 0.0, -0.5]}},
    ])  # fmt: skip
    patch = {"kind": "parallelogram", "point": [0.002, -0.02, 0.0],
             "corner1": [0.05, -0.02, 0.0], "corner2": [0.002, 0.02, 0.0]}  # fmt: skip
    edge = block_scene(h=0.0025, origin=(0.0, 0.0, 1e-4), wall=[patch], end_time=0.02,
                       velocity=(0.0, 0.0, -1.0))  # fmt: skip
    carried = bar_scene(elements=12, speed=0.0, wall=False, end_time=4e-5)
    hammer = {"mass": 0.002, "velocity": [0.1, 0.0, -5.0]}
    carried["wall"] = [{"kind": "plane", "point": [0.0, 0.0, 0.0121], "normal_point": [0, 0, 0],
                        "slide": "tied", "motion": hammer}]  # fmt: skip
    return {"friction": on_plane, "curved": curved, "parallelogram": edge, "main node": carried}


@pytest.mark.parametrize("name", ["friction", "curved", "parallelogram", "main node"])
def test_the_books_close_to_round_off_whatever_the_steps(name, shared_dir, swinging):
    """Steps that swing by 40 %: the energy balance of a linear elastic body on every wall
    kind still closes to round-off (<= 1e-12 of the largest energy), as walls, friction
    filters, prescribed motions, driven faces and gravity all take the step of their own
    update, and the work of the step's changes (on K + U: what the integrator puts in
    when the step varies) is booked; it stays a few % of the energy here."""
    sim = swinging(wall_scenes()[name], shared_dir)
    assert sim.internal.corrects
    summary = sim.history.summary
    dt = sim.history.energy[:, -1]
    assert dt.max() > 1.3 * dt.min()
    assert summary["energy"]["max_balance_error"] <= 1e-12
    assert summary["energy"]["step_change_work"] != 0.0
    assert abs(summary["energy"]["step_change_work"]) < 0.05 * sim.history.balance.reference
    assert any(w["peak_contacts"] for w in summary["walls"])


def crush_scene(**run_keys) -> dict:
    """A free copper bar (4 x 4 x 16 mm) struck at 250 m/s by a 20 g wall carried by a main
    node: the struck cells are crushed, the step falls over three times within 30 us."""
    return {
        "run": {"end_time": 30e-6, **run_keys},
        "mesh": {"shape": "bar", "size": [4e-3, 4e-3, 16e-3], "element_size": 1e-3},
        "material": COPPER,
        "wall": [
            {
                "kind": "plane",
                "point": [0.0, 0.0, 16e-3],
                "normal_point": [0.0, 0.0, 0.0],
                "motion": {"mass": 0.02, "velocity": [0.0, 0.0, -250.0]},
            }
        ],  # fmt: skip
        "output": {"plot": False, "history_interval": 10},
    }


def crush(directory, comm=MPI.COMM_WORLD, **run_keys):
    """Run :func:`crush_scene` into ``directory``."""
    return run(crush_scene(**run_keys), directory, comm)


def momentum_error(summary) -> float:
    """|final - initial momentum| over the initial one (body and main-node wall)."""
    before, after = (np.array(summary[k]) for k in ("initial_momentum", "final_momentum"))
    return float(np.linalg.norm(after - before) / np.linalg.norm(before))


def test_a_step_that_falls_three_times(shared_dir, tmp_path):
    """The crushed bar: the step falls by over 3x; momentum (no external force) is
    conserved to round-off and the energy balance closes to round-off (the plastic
    body's internal energy is booked at mid-step, exact for any steps); on 2 ranks, the
    answers of one rank to 1e-10."""
    sim = crush(shared_dir)
    summary = sim.history.summary
    steps = summary["time_step"]
    assert steps["first"] > 3.0 * steps["smallest"]
    assert momentum_error(summary) <= 1e-13
    assert summary["energy"]["max_balance_error"] <= 1e-12
    assert summary["plastic_work"] > 0.05 * summary["energy"]["initial"]
    if MPI.COMM_WORLD.size > 1:
        serial = crush(tmp_path, MPI.COMM_SELF)
        e, f = sim.history.energy, serial.history.energy
        assert e.shape == f.shape and sim.state.step == serial.state.step
        assert np.abs(e[:, -1] - f[:, -1]).max() <= 1e-10 * f[:, -1].max()  # the steps
        assert np.abs(e[:, 1:6] - f[:, 1:6]).max() <= 1e-10 * summary["energy"]["initial"]
        bounds = np.array(summary["deformed_bounds"])
        assert np.abs(bounds - serial.history.summary["deformed_bounds"]).max() <= 1e-12


def test_mass_scaling_holds_the_step_and_keeps_the_books(shared_dir):
    """With dt_min above where the step would fall and mass scaling: the step holds at
    dt_min, the few crushed cells get the mass that holds it (reported, and below
    max_added_mass), momentum stays conserved to round-off (the added mass joins its node
    at rest) and the balance closes counting the kinetic energy that costs."""
    sim = crush(shared_dir, dt_min=5e-8, dt_min_action="mass_scaling")
    summary = sim.history.summary
    steps = summary["time_step"]
    assert steps["smallest"] == 5e-8 and 0 < steps["scaled_cells"] < sim.info["cells"] // 16
    assert 0.0 < steps["added_mass_percent"] < 5.0  # the default run.max_added_mass
    assert steps["added_mass"] == pytest.approx(summary["mass"] * steps["added_mass_percent"] / 100)
    assert momentum_error(summary) <= 1e-13
    assert summary["energy"]["max_balance_error"] <= 1e-12
    assert summary["energy"]["mass_scaling_work"] == pytest.approx(steps["mass_scaling_work"])
    assert steps["mass_scaling_work"] < 0.0
    energy = sim.history.energy
    assert energy[-1, -2] == pytest.approx(steps["added_mass"])  # energy.csv: kg, then %
    assert np.all(np.diff(energy[:, -2]) >= 0.0)


def test_too_much_added_mass_stops_the_run(shared_dir):
    sim = crush(shared_dir, dt_min=1e-7, dt_min_action="mass_scaling", max_added_mass=0.01)
    assert "mass scaling has added" in sim.status and "run.max_added_mass = 0.01" in sim.status
    assert sim.history.summary["time_step"]["added_mass_percent"] > 1.0


def test_dt_min_stops_the_run_naming_the_cell(shared_dir):
    """dt_min with the action "stop": the run stops after the step that falls below it,
    with its history sample and a checkpoint, naming the cell and its state."""
    sim = crush(shared_dir, dt_min=1e-7)
    status = sim.status
    assert "the stable step fell to" in status and "below run.dt_min = 1e-07 s" in status
    assert "it is set by the cell at (" in status and "plastic strain" in status
    assert "volume " in status and " of its initial" in status
    summary = sim.history.summary
    assert summary["status"] == "stopped" and summary["time"] == sim.history.energy[-1, 0]
    MPI.COMM_WORLD.Barrier()
    assert (shared_dir / "checkpoint" / f"step_{sim.state.step:010d}").is_dir()


def test_an_inverted_cell_stops_even_a_linear_elastic_run(shared_dir, tmp_path):
    """A coarse elastic bar at 8 km/s (a strain of over 1: the small-strain solution folds
    the mesh) stops with the inverted cell's place; the 1 km/s one runs on."""
    raw = bar_scene(elements=10, speed=8000.0)
    raw["mesh"] |= {"size": [2e-3, 2e-3, 10e-3], "element_size": 1e-3}
    sim = run(raw, shared_dir)
    assert sim.status.startswith("stopped: step ") and " inverted at t = " in sim.status
    assert "cell at (0.0005, 0.0005, " in sim.status or "cell at (0.0015," in sim.status
    assert sim.history.summary["time"] == sim.history.energy[-1, 0]
    raw = bar_scene(elements=10, speed=1000.0)
    assert run(raw, tmp_path if MPI.COMM_WORLD.size == 1 else shared_dir / "slow").status == "done"


def test_a_viscous_hourglass_far_above_its_range_stays_stable(shared_dir):
    """QM = 2 on the viscous hourglass form damps the hourglass modes at a rate eta of
    32 c / h: the explicit damper needs dt <= 2 / eta = h / (16 c), far below the limit at
    rest that a fixed step is taken from; the adaptive step counts it and the run stays
    stable, its energy booked (the balance closes to round-off)."""
    raw = bar_scene(elements=20, speed=10.0)
    raw["element"] = {"hourglass": "viscous", "hourglass_coefficient": 2.0}
    sim = run(raw, shared_dir)
    assert sim.status == "done"
    c = math.sqrt(STEEL_NU0["young"] / STEEL_NU0["density"])
    assert sim.state.dt <= 0.9 * 1e-3 / (16 * c)
    assert sim.history.summary["energy"]["max_balance_error"] <= 1e-12
    raw["run"]["time_step"] = "fixed"
    with pytest.raises(SceneError, match="element.hourglass_coefficient: the viscous hourglass"):
        run(raw, shared_dir / "fixed")


def test_a_resumed_mass_scaled_run_equals_the_uninterrupted_one(shared_dir):
    """Stopped in the middle of the crush (the cells being scaled), resumed from its
    checkpoint: the steps, the added mass and every output are those of the run that
    never stopped, to the last bit."""
    keys = {"dt_min": 5e-8, "dt_min_action": "mass_scaling"}
    whole = crush(shared_dir / "whole", **keys)
    raw = crush_scene(**keys)
    out = shared_dir / "stopped"
    sim = build_simulation(parse_scene(copy.deepcopy(raw), source="test"), MPI.COMM_WORLD, out)
    sim.recorders.append(StopAt(300))
    assert sim.run().startswith("stopped: step 300,")
    resumed = build_simulation(parse_scene(copy.deepcopy(raw), source="test"), MPI.COMM_WORLD, out)
    resumed.checkpoints.resume(resumed)
    assert resumed.run() == "done"
    assert np.array_equal(resumed.state.u, whole.state.u)
    assert np.array_equal(resumed.state.mass, whole.state.mass)
    assert resumed.state.step == whole.state.step and resumed.state.t == whole.state.t
    MPI.COMM_WORLD.Barrier()
    if MPI.COMM_WORLD.rank == 0:
        for name in ("energy.csv", "walls.csv"):
            assert (out / name).read_text() == (shared_dir / "whole" / name).read_text()
