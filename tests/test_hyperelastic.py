"""Large deformation (total Lagrangian hyperelasticity) as an effect.

References: in the small-strain limit both models reduce to linear elasticity
(the bar's rebound must agree); central differences conserve a modified energy
within O(dt^2) for nonlinear forces, so the balance error of a hyperelastic
run, with the strain energy from the energy density, must fall like dt^2.
"""

import pytest
from conftest import bar_scene, run
from mpi4py import MPI

from rwall_fem import build_simulation, parse_scene
from rwall_fem.hyperelasticity import StableStepMonitor

MODELS = ["saint_venant_kirchhoff", "neo_hookean"]


def bar(model, speed=1.0, dt_scale=0.9):
    raw = bar_scene(elements=20, h=1e-3, speed=speed)
    raw["material"] |= {"model": model, "poisson": 0.3}
    raw["run"]["dt_scale"] = dt_scale
    return raw


def rebound(sim):
    s = sim.history.summary
    return s["final_momentum"][2] / s["mass"]


@pytest.mark.parametrize("model", MODELS)
def test_small_strain_limit_is_linear_elasticity(model, shared_dir):
    linear = run(bar("linear_elastic"), shared_dir)
    large = run(bar(model), shared_dir)
    assert large.effects == [model, "wall[0]"]
    # Strain 2e-4: the models differ from Hooke's law by that order.
    assert rebound(large) == pytest.approx(rebound(linear), abs=1e-3)


@pytest.mark.parametrize("model", MODELS)
def test_energy_balance_falls_as_dt_squared(model, shared_dir):
    errors = [
        run(bar(model, dt_scale=scale), shared_dir).history.summary["energy"]["max_balance_error"]
        for scale in (0.9, 0.45, 0.225)
    ]
    assert 3.0 < errors[0] / errors[1] < 5.0 and 3.0 < errors[1] / errors[2] < 5.0
    assert errors[2] <= 1e-6  # 4.4e-6 (SVK) and 2.2e-6 (neo-Hookean) at dt_scale 0.9


def test_stable_step_guard_stops_the_run(shared_dir):
    sim = build_simulation(
        parse_scene(bar("neo_hookean"), source="test"), MPI.COMM_WORLD, shared_dir
    )
    monitor = next(r for r in sim.recorders if isinstance(r, StableStepMonitor))
    monitor.dt_stable = 0.5 * sim.state.dt  # as if the deformation had halved the limit
    status = sim.run()
    assert status.startswith("stopped: step 0, t = 0 s: the deformation lowered the stable")
    assert "below dt = " in status and "lower run.dt_scale" in status
