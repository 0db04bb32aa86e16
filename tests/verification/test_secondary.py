"""Secondary nodes (docs/theory.md, "Secondary nodes"): boundary default, search distance,
named sets, and nodes that start inside a wall.

The block is 10 mm with 2 hexahedra a side: 27 nodes in layers of 9, 26 on the
boundary, 9 on each face, 1 inside the lower face's edges.
"""

import pytest
from conftest import block_scene, run, run_probed

from rwall_fem import SceneError


def plane(z=0.0, **keys):
    return {"kind": "plane", "point": [0.0, 0.0, z], "normal_point": [0.0, 0.0, z + 1.0]} | keys


def secondary_count(raw, directory):
    return run(raw, directory).history.summary["walls"][0]["secondary_nodes"]


@pytest.mark.parametrize(
    "gap, wall_z, secondary, expected",
    [
        (0.001, 0.0, {}, 26),  # default: the boundary nodes
        (0.001, 0.0, {"search_distance": 0.0015}, 9),  # the lower layer (d = 1 mm)
        (0.001, 0.0, {"search_distance": 0.007}, 18),  # and the middle one (d = 6 mm)
        (0.001, 0.003, {"search_distance": 1.0}, 18),  # lower layer behind: never selected
        (-0.0005, 0.0, {"search_distance": 0.001}, 0),  # penetrated lower layer: not selected
        (0.001, 0.0, {"add": ["bottom"]}, 9),
        (0.001, 0.0, {"add": ["bottom"], "exclude": ["sides"]}, 1),  # exclusion wins
        (0.001, 0.0, {"search_distance": 0.0015, "add": ["top"]}, 18),
    ],
)
def test_selection(gap, wall_z, secondary, expected, shared_dir):
    raw = block_scene(
        origin=(0.0, 0.0, gap), wall=[plane(wall_z, secondary=secondary)], end_time=1e-3
    )
    assert secondary_count(raw, shared_dir) == expected


def test_unknown_node_set_is_named(shared_dir):
    raw = block_scene(wall=[plane(secondary={"exclude": ["clamp"]})], end_time=1e-3)
    with pytest.raises(
        SceneError,
        match=r"wall\[0\]\.secondary\.exclude: unknown node set "
        r"'clamp'; the mesh has: bottom, sides, top",
    ):
        run(raw, shared_dir)


DEPTH = 5e-4  # m, lower face inside the wall at the start


@pytest.mark.parametrize("speed", [1e-3, 10.0])
def test_explicit_node_inside_cannot_rebound_unless_one_step_takes_it_out(speed, shared_dir):
    wall = plane(secondary={"add": ["bottom"]})
    raw = block_scene(
        origin=(0.0, 0.0, -DEPTH), velocity=(0.0, 0.0, speed), wall=[wall], end_time=0.01
    )
    sim, probe = run_probed(raw, shared_dir)
    inside_at_end = probe.distances[-1, 0]
    if speed * sim.state.dt < DEPTH:  # slow: held where it is, at every step
        assert probe.distances[:, 0] == pytest.approx(-DEPTH, abs=1e-12)
        assert sim.history.summary["walls"][0]["first_contact"] == 0.0
        assert inside_at_end < 0
    else:  # one step takes it out: never treated
        assert sim.history.summary["walls"][0]["first_contact"] is None
        assert inside_at_end == pytest.approx(-DEPTH + speed * probe.t[-1], rel=1e-9)
