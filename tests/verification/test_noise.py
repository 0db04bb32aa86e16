"""Random noise on the initial coordinates (docs/theory.md, "Coordinate noise").

The noise of a node depends only on the seed and the node's input (gmsh)
index, so a seeded run is reproducible and independent of the partitioning.
"""

import math

import numpy as np
import pytest
from conftest import bar_scene, block_scene, run
from mpi4py import MPI

NOISE = {"amplitude": 1e-5, "seed": 7}


def noisy_bar(seed=7):
    raw = bar_scene(elements=10, h=2e-3, cell="tetrahedron", axis=(1.0, -2.0, 2.0))
    raw["mesh"]["size"] = [4e-3, 4e-3, 20e-3]
    raw["mesh"]["noise"] = NOISE | {"seed": seed}
    return raw


def test_same_seed_same_run_other_seed_other_run(shared_dir, tmp_path):
    # Each run's histories are read back from its files before the next run replaces them.
    history = run(noisy_bar(), shared_dir).history
    scale = history.summary["energy"]["initial"]
    first = history.energy[:, 1:5]
    again = run(noisy_bar(), shared_dir).history.energy[:, 1:5]
    other = run(noisy_bar(seed=8), shared_dir).history.energy[:, 1:5]
    # Bitwise in serial; in parallel the order of sums may change the last bits.
    assert np.abs(first - again).max() <= 1e-12 * scale
    assert np.abs(first - other).max() > 1e-8 * scale


@pytest.mark.skipif(MPI.COMM_WORLD.size == 1, reason="compares a partitioned run with a serial one")
def test_noise_does_not_depend_on_the_partition(shared_dir, tmp_path):
    parallel = run(noisy_bar(), shared_dir)
    serial = run(noisy_bar(), tmp_path, comm=MPI.COMM_SELF)
    e_par, e_ser = parallel.history.energy, serial.history.energy
    scale = serial.history.summary["energy"]["initial"]
    assert np.abs(e_par[:, 1:5] - e_ser[:, 1:5]).max() <= 1e-10 * scale


def test_nodes_at_zero_distance_selected_by_distance(shared_dir):
    """With noise, lower-face nodes at d = 0 land on both sides; those inside are not
    secondary when the selection is by distance."""
    wall = {
        "kind": "plane",
        "point": [0, 0, 0],
        "normal_point": [0, 0, 1],
        "secondary": {"search_distance": 1e-3},
    }
    exact = block_scene(wall=[wall], end_time=1e-3, h=2.5e-3)  # 5 x 5 = 25 lower-face nodes
    noisy = block_scene(wall=[wall], end_time=1e-3, h=2.5e-3)
    noisy["mesh"]["noise"] = NOISE
    count = run(exact, shared_dir).history.summary["walls"][0]["secondary_nodes"]
    noisy_count = run(noisy, shared_dir).history.summary["walls"][0]["secondary_nodes"]
    assert count == 25
    assert 0 < noisy_count < 25


@pytest.mark.parametrize("arm, tilted", [(1e-4, True), (1.0, False)])
def test_noise_moves_a_moving_walls_main_node(arm, tilted, shared_dir):
    """The main node moves with the noise; the normal from it to M1 turns, the more
    the closer M1 is."""
    wall = {
        "kind": "plane",
        "point": [0, 0, -0.01],
        "normal_point": [0, 0, -0.01 + arm],
        "motion": {"mass": 1.0, "velocity": [0, 0, 0]},
    }
    raw = block_scene(wall=[wall], end_time=1e-3)
    raw["mesh"]["noise"] = NOISE
    sim = run(raw, shared_dir)
    normal = sim.constraints[0].shape.normal
    angle = math.acos(min(1.0, normal[2]))
    bound = math.sqrt(2) * NOISE["amplitude"] / arm  # largest tilt a 1e-5 move can give
    assert angle <= bound
    assert (angle > 1e-2) == tilted
    fixed = dict(wall)
    del fixed["motion"]
    raw["wall"] = [fixed]
    assert np.array_equal(run(raw, shared_dir).constraints[0].shape.normal, [0.0, 0.0, 1.0])
