"""Only the effects a scene calls for are in the step: the rest never runs."""

import pytest
from conftest import bar_scene, block_scene, run

import rwall_fem.effects
import rwall_fem.loads
import rwall_fem.output.frames
import rwall_fem.walls.motion


def forbidden(name):
    def call(*args, **kwargs):
        raise AssertionError(f"{name} ran although the scene did not ask for it")

    return call


@pytest.fixture
def nothing_optional(monkeypatch):
    """Make every optional effect fail loudly if it runs."""
    for owner, name in [
        (rwall_fem.effects.Gravity, "accelerate"),
        (rwall_fem.loads.NodalForce, "accelerate"),
        (rwall_fem.loads.Pressure, "accelerate"),
        (rwall_fem.loads.RayleighDamping, "accelerate"),
        (rwall_fem.output.frames.Frames, "record"),
        (rwall_fem.walls.motion.MainNodeMotion, "advance"),
        (rwall_fem.walls.motion.PrescribedMotion, "predict"),
    ]:
        monkeypatch.setattr(owner, name, forbidden(f"{owner.__name__}.{name}"))


def test_plain_impact_runs_only_elasticity_and_its_wall(nothing_optional, shared_dir):
    sim = run(bar_scene(elements=10), shared_dir)
    assert sim.effects == ["linear_elastic", "wall[0]"]
    assert sim.forces == [] and [type(r).__name__ for r in sim.recorders] == ["RunLog"]
    wall = sim.walls[0]
    # A fixed wall with free sliding: no tangential impulse was ever booked.
    assert type(wall.motion) is rwall_fem.walls.motion.FixedMotion and wall.slide == "free"
    assert not wall.tangential_impulse.any() and wall.friction_work == 0.0


def test_free_flight_runs_only_elasticity(nothing_optional, shared_dir):
    sim = run(bar_scene(elements=10, wall=False), shared_dir)
    assert sim.effects == ["linear_elastic"] and sim.constraints == []


def test_gravity_is_an_effect_when_asked(shared_dir):
    sim = run(block_scene(gravity=[0.0, 0.0, -9.81], end_time=1e-3), shared_dir)
    assert sim.effects == ["linear_elastic", "gravity"]
