"""Cylinder and sphere walls: a small block sliding off the top without friction.

A point mass starting at the top of a frictionless convex cylinder or sphere
of radius R with speed v0 leaves the surface at cos(theta) = 2/3 + v0^2/(3 g R)
(docs/theory.md, "Curved walls"). The block (2 mm, one soft hexahedron) is small against
R = 0.1 m; its centre runs at R + a/2. Its flat face touching a curved wall
and its elastic ringing shift the angle by well under 0.02 in cos(theta).
"""

import math

import numpy as np
import pytest
from conftest import COLUMN, block_scene, run_probed

G, R, A, V0 = 9.81, 0.1, 0.002, 0.2


@pytest.mark.parametrize("kind", ["cylinder", "sphere"])
def test_block_leaves_convex_wall_at_the_point_mass_angle(kind, shared_dir):
    wall = {"kind": kind, "point": [0.0, 0.0, 0.0], "diameter": 2 * R}
    if kind == "cylinder":
        wall["axis_point"] = [0.0, 1.0, 0.0]
    scene = block_scene(
        size=A,
        h=A,
        origin=(-A / 2, -A / 2, R),
        gravity=[0, 0, -G],
        wall=[wall],
        velocity=(V0, 0.0, 0.0),
        end_time=0.3,
    )
    scene["material"]["young"] = 2.5e5  # softer, a twice longer step: the block stays rigid
    sim, probe = run_probed(scene, shared_dir)
    contacts = sim.history.wall(0)[:, COLUMN["contacts"]]
    leave = np.flatnonzero(contacts > 0)[-1]
    x, _, z = probe.x[leave]
    expected = 2 / 3 + V0**2 / (3 * G * (R + A / 2))
    assert z / math.hypot(x, z) == pytest.approx(expected, abs=0.02)
    # It really flew: well past the leaving point at the end, and never inside the wall.
    assert probe.t[leave] < 0.8 * probe.t[-1]
    assert probe.distances.min() >= -1e-9 * R
    # Round-off of 1/2 u.Ku with a large rigid displacement (7 cm) sets this floor.
    assert sim.history.summary["energy"]["max_balance_error"] < 1e-8
