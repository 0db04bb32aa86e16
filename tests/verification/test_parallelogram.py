"""Finite plane (parallelogram): contact only inside it, bodies pass beside and behind it."""

import numpy as np
import pytest
from conftest import COLUMN, block_scene, run_probed

G = 9.81
PATCH = {
    "kind": "parallelogram",
    "point": [0.0, -0.02, 0.0],
    "corner1": [0.05, -0.02, 0.0],
    "corner2": [0.0, 0.02, 0.0],
}  # z = 0, normal +z


def contacts(sim):
    return sim.history.wall(0)[:, COLUMN["contacts"]]


def test_block_slides_off_the_edge_and_falls(shared_dir):
    scene = block_scene(
        origin=(0.02, -0.005, 0.0),
        velocity=(0.5, 0.0, 0.0),
        gravity=[0, 0, -G],
        wall=[PATCH],
        end_time=0.12,
    )
    sim, probe = run_probed(scene, shared_dir)
    c = contacts(sim)
    assert c[: len(c) // 4].min() > 0  # supported while on the wall
    assert c[-1] == 0 and probe.x[-1, 2] < -0.01  # gone over the edge (x = 0.05) and down
    assert probe.x[-1, 0] > 0.05
    assert sim.history.summary["energy"]["max_balance_error"] < 1e-8


@pytest.mark.parametrize(
    "origin", [(0.06, 0.0, 0.001), (0.02, 0.0, -0.02)], ids=["beside", "behind"]
)
def test_body_beside_or_behind_is_never_caught(origin, shared_dir):
    scene = block_scene(origin=origin, gravity=[0, 0, -G], wall=[PATCH], end_time=0.05)
    sim, probe = run_probed(scene, shared_dir)
    assert contacts(sim).max() == 0
    # Free fall through the plane's level: v = g t exactly (gravity acts from step 0).
    assert probe.v[-1] == pytest.approx([0.0, 0.0, -G * probe.t[-1]], abs=1e-9)


def test_corner_impact(shared_dir):
    # A block falls with one quarter of its lower face over the corner (0.05, 0.02).
    scene = block_scene(
        origin=(0.045, 0.015, 0.0), velocity=(0.0, 0.0, -1.0), wall=[PATCH], end_time=0.02
    )
    sim, probe = run_probed(scene, shared_dir)
    summary = sim.history.summary
    change = np.subtract(summary["final_momentum"], summary["initial_momentum"])
    impulse = np.asarray(summary["walls"][0]["impulse"])
    # Exact but for the round-off of sum(K u) (1e-12 relative seen with DOLFINx 0.11).
    assert np.allclose(change, -impulse, rtol=0, atol=1e-11 * np.abs(impulse).max())
    assert impulse[2] < 0 and summary["walls"][0]["peak_contacts"] <= 4  # 2 x 2 nodes inside
    assert summary["energy"]["max_balance_error"] < 1e-10
    assert np.all(np.isfinite(probe.v))


def test_slightly_penetrated_nodes_are_pushed_back_in_one_step(shared_dir):
    depth = 2e-5  # less than two steps of normal travel at 0.5 m/s (dt is about 1e-4 s)
    patch = PATCH | {"secondary": {"add": ["bottom"]}}
    scene = block_scene(
        origin=(0.02, -0.005, -depth), velocity=(0.5, 0.0, -0.5), wall=[patch], end_time=0.002
    )
    sim, probe = run_probed(scene, shared_dir)
    assert probe.distances[0, 0] == pytest.approx(-depth)
    assert abs(probe.distances[1, 0]) < 1e-12
