"""A nu = 0 bar striking a fixed rigid plane, against 1-D wave theory.

With Poisson's ratio 0 and free sides the 3-D bar is exactly 1-D. For a bar
of length L, section A, density rho, wave speed c = sqrt(E / rho), hitting
the wall at v0: contact lasts 2L/c, the wall force is rho c A v0, the total
impulse 2 m v0 and the bar leaves at v0. The kinematic wall stops the first
layer of nodes plastically, which destroys 1/2 m_face v0^2 with m_face the
lumped mass of the contact face, M / (2N) for N layers; the discrete answers
converge at O(1/N) (docs/theory.md, "Bar on a fixed plane", gives the 1-D figures).
"""

import math

import numpy as np
import pytest
from conftest import COLUMN, STEEL_NU0, bar_scene, run

N, H, V0 = 40, 1e-3, 10.0
C = math.sqrt(STEEL_NU0["young"] / STEEL_NU0["density"])
L, A = N * H, H * H
MASS = STEEL_NU0["density"] * A * L
SKEWED = (1.0, -2.0, 2.0)


def contact_figures(sim, wall=0):
    """Contact start, duration (s), total impulse (N s) and mid-contact mean force (N)."""
    walls = sim.history.wall(wall)
    t, contacts = walls[:, COLUMN["time"]], walls[:, COLUMN["contacts"]]
    normal = sim.constraints[wall].shape.normal
    in_contact = np.flatnonzero(contacts > 0)
    start, end = t[in_contact[0]], t[in_contact[-1]] + sim.state.dt
    duration = end - start
    force = walls[:, COLUMN["force_x"] : COLUMN["force_z"] + 1] @ normal
    middle = (t >= start + 0.25 * duration) & (t <= start + 0.75 * duration)
    impulse = walls[-1, COLUMN["impulse_x"] : COLUMN["impulse_z"] + 1] @ normal
    return start, duration, impulse, force[middle].mean()


@pytest.mark.parametrize("cell", ["hexahedron", "tetrahedron"])
@pytest.mark.parametrize("axis", [(1, 0, 0), (0, 1, 0), (0, 0, 1), SKEWED])
def test_bar_on_fixed_plane_matches_wave_theory(cell, axis, shared_dir):
    sim = run(bar_scene(elements=N, h=H, axis=axis, cell=cell, speed=V0), shared_dir)
    dt, summary = sim.state.dt, sim.history.summary
    normal = np.asarray(axis, float) / np.linalg.norm(axis)
    start, duration, impulse, plateau = contact_figures(sim)

    assert start == 0.0  # the bar touches the wall at t = 0
    assert abs(duration - 2 * L / C) <= 2 * dt + 0.02 * 2 * L / C
    # The structure pushes the wall against its normal: force and impulse are negative.
    assert plateau == pytest.approx(-STEEL_NU0["density"] * C * A * V0, rel=0.01)
    assert abs(-impulse - 2 * MASS * V0) <= (1 / N + 0.01) * 2 * MASS * V0
    rebound = np.asarray(summary["final_momentum"]) @ normal / MASS
    assert abs(rebound - V0) <= (2 / N + 0.01) * V0
    assert summary["energy"]["max_balance_error"] <= 1e-10
    # Plastic stop of the contact face: 1/2 (M / 2N) v0^2, booked as (negative) wall work.
    face_loss = 0.5 * MASS / (2 * N) * V0**2
    assert -summary["energy"]["wall_work"] == pytest.approx(face_loss, rel=0.01)
    assert summary["effects"] == ["linear_elastic", "wall[0]"]


def test_momentum_change_equals_wall_impulse(shared_dir):
    """Newton: the bar's momentum change is minus the impulse it gave the wall, to round-off."""
    sim = run(bar_scene(elements=20, axis=SKEWED), shared_dir)
    summary = sim.history.summary
    change = np.subtract(summary["final_momentum"], summary["initial_momentum"])
    impulse = np.asarray(summary["walls"][0]["impulse"])
    assert np.allclose(change, -impulse, rtol=0, atol=1e-12 * MASS * V0)


def test_free_flight_conserves_momentum_and_energy(shared_dir):
    sim = run(bar_scene(elements=10, wall=False, axis=SKEWED), shared_dir)
    summary = sim.history.summary
    assert summary["effects"] == ["linear_elastic"]
    assert summary["walls"] == []
    p0, p1 = np.asarray(summary["initial_momentum"]), np.asarray(summary["final_momentum"])
    # K 1 = 0: a rigid translation has no internal force, up to the round-off of K u.
    assert np.allclose(p1, p0, rtol=0, atol=1e-11 * np.linalg.norm(p0))
    assert summary["energy"]["max_balance_error"] <= 1e-12
    assert summary["energy"]["kinetic"] == pytest.approx(summary["energy"]["initial"], rel=1e-12)


def test_gap_delays_contact_by_travel_time(shared_dir):
    """A bar released 10 steps of travel above the wall first touches it after gap / v0."""
    sim = run(bar_scene(elements=10, gap=2.5e-4), shared_dir)
    start, *_ = contact_figures(sim)
    dt = sim.state.dt
    # Contact is detected one step ahead, on the predicted position.
    assert 2.5e-4 / V0 - 2 * dt <= start <= 2.5e-4 / V0
