"""Velocity boundary conditions on named node sets, against wave theory.

A nu = 0 bar (N layers) whose end face is held or driven is a one-dimensional
wave problem: a clamp stops a bar moving at v0 with the force rho c A v0 until
the wave has run 2L/c, by then the impulse is 2 m v0; an end driven at V from
rest pulls with rho c A V and puts the driving work half into kinetic, half
into strain energy. Discretisation error of the plateau and the impulse: 1/N.
"""

import math

import numpy as np
import pytest
from conftest import STEEL_NU0, bar_scene, run
from mpi4py import MPI

from rwall_fem import SceneError, build_simulation, parse_scene

N, H = 20, 1e-3  # layers, m
C = math.sqrt(STEEL_NU0["young"] / STEEL_NU0["density"])  # bar wave speed, m/s
AREA, LENGTH = H * H, N * H


def held_bar(velocity, boundary, end_time):
    raw = bar_scene(elements=N, h=H, speed=0.0, wall=False, end_time=end_time)
    raw["initial"]["velocity"] = list(velocity)
    raw["boundary"] = [boundary]
    return raw


def test_clamp_stops_a_bar_like_a_fixed_wall(shared_dir):
    v0 = 2.0
    sim = run(held_bar((0.0, 0.0, -v0), {"group": "bottom"}, 2 * LENGTH / C), shared_dir)
    summary = sim.history.summary
    m = summary["mass"]
    reaction = summary["boundaries"][0]["reaction_impulse"]
    assert reaction[2] == pytest.approx(2 * m * v0, rel=1.0 / N)  # -1.7 % seen  # -1.3 % seen
    assert np.abs(reaction[:2]).max() < 1e-12 * m * v0  # round-off of K u only
    assert summary["effects"] == ["linear_elastic", "boundary[0]"]
    # The clamped face has not moved, and the balance closes like every other force's.
    bottom = np.abs(sim.state.X[:, 2]) < 1e-9 * LENGTH
    assert np.abs(sim.state.u[bottom]).max(initial=0.0) == 0.0
    assert summary["energy"]["max_balance_error"] < 1e-12
    # Momentum: what the body lost is what the clamp took.
    change = np.subtract(summary["final_momentum"], summary["initial_momentum"])
    assert change == pytest.approx(reaction, abs=1e-11 * m * v0)


def test_driven_end_pulls_with_the_wave_force(shared_dir):
    V = 1.5
    end = 0.75 * LENGTH / C  # the front has not reached the far end
    boundary = {"group": "bottom", "velocity": [0.0, 0.0, V], "components": "z"}
    sim = run(held_bar((0.0, 0.0, 0.0), boundary, end), shared_dir)
    summary = sim.history.summary
    t = summary["end_time"]
    rho_c_a = STEEL_NU0["density"] * C * AREA
    reaction = summary["boundaries"][0]["reaction_impulse"][2]
    assert reaction == pytest.approx(rho_c_a * V * t, rel=1.0 / N)  # +2.9 % seen
    energy = summary["energy"]
    work = energy["external_work"]
    assert work == pytest.approx(rho_c_a * V * V * t, rel=1.0 / N)
    # Half kinetic, half strain energy (equipartition in a travelling wave), to 1/N.
    assert energy["kinetic"] / work == pytest.approx(0.5, abs=1.0 / N)
    assert energy["max_balance_error"] < 1e-12


def test_free_components_stay_free(shared_dir):
    """Only z is held: the x velocity of the whole bar, clamped face included, is untouched
    (no reaction along x, x momentum exact)."""
    vx = 0.7
    boundary = {"group": "bottom", "components": "z"}
    sim = run(held_bar((vx, 0.0, -1.0), boundary, LENGTH / C), shared_dir)
    summary = sim.history.summary
    assert abs(summary["boundaries"][0]["reaction_impulse"][0]) < 1e-12 * summary["mass"]
    assert summary["final_momentum"][0] == pytest.approx(vx * summary["mass"], rel=1e-13)
    owned_vx = sim.state.v[:, 0]
    assert np.allclose(owned_vx, vx, rtol=0, atol=1e-12)


@pytest.mark.parametrize(
    "boundary, message",
    [
        ({"velocity": [0, 0, 0]}, r"boundary\[0\]\.group: missing"),
        ({"group": "bottom", "components": "xw"}, r"boundary\[0\]\.components: must be some"),
        ({"group": "bottom", "velocity": [0, 1]}, r"boundary\[0\]\.velocity: must be 3 finite"),
        ({"group": "bottom", "speed": 1.0}, r"boundary\[0\]\.speed: unknown key; allowed: group"),
    ],
)
def test_bad_boundaries_name_the_field(boundary, message):
    raw = held_bar((0, 0, 0), boundary, 1e-6)
    with pytest.raises(SceneError, match=message):
        parse_scene(raw, source="bad.toml")


def test_unknown_group_lists_the_mesh_groups(shared_dir):
    raw = held_bar((0, 0, 0), {"group": "left"}, 1e-6)
    with pytest.raises(SceneError, match=r"boundary\[0\]\.group: unknown node set 'left'; "):
        build_simulation(parse_scene(raw, source="bad.toml"), MPI.COMM_WORLD, shared_dir)


def test_clamp_wins_over_a_wall_and_the_balance_stays_exact(shared_dir):
    """A prescribed wall rises into a clamped face: the wall pushes the face's nodes, the
    clamp (acting last) holds them; each impulse's work is booked with the velocity the
    nodes really have after the step, so the balance closes to round-off (0.33 when the
    wall booked the velocity it had given them)."""
    raw = held_bar((0.0, 0.0, 0.0), {"group": "bottom"}, LENGTH / C)
    raw["mesh"]["origin"] = [0.0, 0.0, 0.0]
    wall = {"kind": "plane", "point": [0, 0, 0], "normal_point": [0, 0, 1]}
    raw["wall"] = [wall | {"motion": {"velocity": [0.0, 0.0, 5.0]}, "slide": "tied"}]
    sim = run(raw, shared_dir)
    bottom = np.abs(sim.state.X[:, 2]) < 1e-9 * LENGTH
    assert np.abs(sim.state.u[bottom]).max(initial=0.0) == 0.0
    assert sim.history.summary["walls"][0]["peak_contacts"] > 0
    assert sim.history.summary["energy"]["max_balance_error"] < 1e-12
