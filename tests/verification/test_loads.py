"""Loads, added masses and Rayleigh damping ([[load]], [[added_mass]], [damping]) against
closed forms.

- A nu = 0 bar clamped at one end and pulled at the other by a force ramped over ten of
  its periods, then held, with mass damping at half the critical of its first mode: it
  ends at rest at the static extension F L / (E A) (exact for trilinear elements in a
  uniform bar), having stored F^2 L / (2 E A); the load's work is the integral of F du.
- A pressure on the end face equals the force p A (nu = 0: the face keeps its area); on a
  closed set of faces it sums to zero; it follows the faces when they turn.
- A bar clamped at one end carrying an end mass M = 25 m is a one-degree-of-freedom
  oscillator, omega^2 = (E A / L) / (M + m / 3); with Rayleigh damping its free vibration
  decays with the logarithmic decrement 2 pi xi / sqrt(1 - xi^2), xi = alpha / (2 omega) +
  beta omega / 2.
"""

import copy
import math

import numpy as np
import pytest
from conftest import STEEL_NU0, bar_scene, run
from mpi4py import MPI

from rwall_fem import SceneError, build_simulation, parse_scene
from rwall_fem.loads import damped_step_factor

N, H = 10, 1e-3  # layers, m
E, RHO = STEEL_NU0["young"], STEEL_NU0["density"]
C = math.sqrt(E / RHO)
LENGTH, AREA = N * H, H * H
PERIOD = 4 * LENGTH / C  # first mode of the clamped-free bar, s
F = 1000.0  # N
MASS_RATIO = 25  # the oscillator's end mass over the bar's


class EndTrace:
    """Recorder of the mean axial displacement of the free end face (m) at every step,
    over all ranks."""

    def __init__(self, sim):
        self.nodes = np.flatnonzero(np.abs(sim.state.X[:, 2] - LENGTH) < 1e-9 * LENGTH)
        self.comm = sim.comm
        self.count = self.comm.allreduce(len(self.nodes))
        self.t, self.u = [], []

    def due(self, state):
        return True

    def record(self, sim, state):
        self.t.append(state.t)
        self.u.append(self.comm.allreduce(float(state.u[self.nodes, 2].sum())) / self.count)

    def close(self, sim):
        pass


def traced(raw, directory):
    sim = build_simulation(parse_scene(copy.deepcopy(raw), source="test"), MPI.COMM_WORLD,
                           directory)  # fmt: skip
    trace = EndTrace(sim)
    sim.recorders.append(trace)
    sim.run()
    return sim, np.array(trace.t), np.array(trace.u)


def pulled_bar(load):
    raw = bar_scene(elements=N, h=H, speed=0.0, wall=False, end_time=15 * PERIOD)
    raw["boundary"] = [{"group": "bottom"}]
    raw["load"] = [{"group": "top", "history": [[0.0, 0.0], [10 * PERIOD, 1.0]], **load}]
    raw["damping"] = {"alpha": 2 * math.pi / PERIOD}  # xi = 1/2 on the first mode
    return raw


def test_slow_ramp_reaches_the_static_extension(shared_dir):
    sim, t, u = traced(pulled_bar({"kind": "force", "force": [0, 0, F], "per": "set"}),
                       shared_dir)  # fmt: skip
    static = F * LENGTH / (E * AREA)
    assert u[-1] == pytest.approx(static, rel=1e-6)  # 7e-10 seen
    energy = sim.history.summary["energy"]
    assert energy["internal"] == pytest.approx(F * static / 2, rel=1e-6)
    assert energy["kinetic"] < 1e-12 * energy["internal"]
    # The work booked is the integral of F du: trapezoids over the steps of F(t^n) and u^n,
    # the same sum as the mid-step booking once summed by parts.
    force = F * np.clip(t / (10 * PERIOD), 0.0, 1.0)
    integral = float(np.sum(0.5 * (force[1:] + force[:-1]) * np.diff(u)))
    assert energy["external_work"] == pytest.approx(integral, rel=1e-9)  # 7e-16 seen
    # What the damping took is the rest, and the balance closes.
    assert energy["external_work"] + energy["damping_work"] == pytest.approx(
        energy["internal"], rel=1e-9
    )
    assert energy["max_balance_error"] < 1e-12
    assert sim.history.summary["effects"] == ["linear_elastic", "load[0]", "damping",
                                              "boundary[0]"]  # fmt: skip


def test_pressure_on_the_end_equals_the_force(shared_dir):
    pressed = run(pulled_bar({"kind": "pressure", "pressure": -F / AREA}), shared_dir)
    pulled = run(pulled_bar({"kind": "force", "force": [0, 0, F], "per": "set"}), shared_dir)
    assert np.allclose(pressed.state.u, pulled.state.u, rtol=0, atol=1e-12 * LENGTH)
    work = [s.history.summary["energy"]["external_work"] for s in (pressed, pulled)]
    assert work[0] == pytest.approx(work[1], rel=1e-10)


def resultant(sim, load) -> np.ndarray:
    """The load's total force (N) at t = 0 over all ranks, the state left as it was."""
    state = sim.state
    kept = state.a.copy()
    state.a[:] = 0.0
    load.accelerate(state)
    total = sim.comm.allreduce(np.sum(state.mass[:, None] * state.a, axis=0))
    state.a[:] = kept
    return total


@pytest.mark.parametrize("cell", ["hexahedron", "tetrahedron"])
def test_pressure_sums_over_the_faces_and_follows_them(cell, shared_dir):
    p = 2e6
    raw = bar_scene(elements=4, h=H, speed=0.0, wall=False, cell=cell, end_time=1e-7)
    raw["load"] = [{"kind": "pressure", "group": g, "pressure": p} for g in ("top", "sides")]
    sim = build_simulation(parse_scene(raw, source="test"), MPI.COMM_WORLD, shared_dir)
    top, sides = sim.forces
    scale = p * AREA
    assert resultant(sim, top) == pytest.approx([0, 0, -scale], abs=1e-12 * scale)
    assert np.abs(resultant(sim, sides)).max() < 1e-12 * scale  # four opposite faces
    # Turn the body a quarter about x: the end's normal +z becomes -y, and its push too.
    X = sim.internal.X
    turned = np.column_stack([X[:, 0], -X[:, 2], X[:, 1]])
    sim.internal.u.array[:] = turned - X
    assert resultant(sim, top) == pytest.approx([0, scale, 0], abs=1e-12 * scale)


def oscillator(alpha, beta):
    """The clamped bar with an end mass of 25 times its own, moving at 1 m/s; its omega."""
    m = RHO * AREA * LENGTH
    omega = math.sqrt(E * AREA / LENGTH / (MASS_RATIO * m + m / 3))
    raw = bar_scene(elements=N, h=H, speed=-1.0, wall=False, end_time=2.3 * 2 * math.pi / omega)
    raw["boundary"] = [{"group": "bottom"}]
    raw["added_mass"] = [{"group": "top", "mass": MASS_RATIO * m, "per": "set"}]
    raw["damping"] = {"alpha": alpha, "beta": beta}
    return raw, omega, m


@pytest.mark.parametrize("which", ["alpha", "beta"])
def test_free_vibration_decays_with_the_logarithmic_decrement(which, shared_dir):
    xi = 0.02
    _, omega, m = oscillator(0.0, 0.0)
    alpha, beta = (2 * xi * omega, 0.0) if which == "alpha" else (0.0, 2 * xi / omega)
    raw, _, _ = oscillator(alpha, beta)
    sim, t, u = traced(raw, shared_dir)
    peaks = np.flatnonzero((u[1:-1] > u[:-2]) & (u[1:-1] >= u[2:])) + 1
    assert len(peaks) == 3
    measured = np.log(u[peaks[:-1]] / u[peaks[1:]])
    closed = 2 * math.pi * xi / math.sqrt(1 - xi * xi)
    assert measured == pytest.approx([closed, closed], rel=0.01)  # 3e-3 (alpha), 1e-5 seen
    period = np.diff(t[peaks]).mean()  # the damped period; peaks at steps, 1/350 of it apart
    assert period == pytest.approx(2 * math.pi / (omega * math.sqrt(1 - xi * xi)), rel=5e-3)
    summary = sim.history.summary
    assert summary["mass"] == pytest.approx((MASS_RATIO + 1) * m, rel=1e-12)
    energy = summary["energy"]
    assert energy["damping_work"] < 0 and energy["max_balance_error"] < 1e-12
    if which == "beta":  # the step of the damped central difference
        factor = damped_step_factor(0.0, beta, sim.info["dt_stable"])
        assert sim.state.dt == pytest.approx(0.9 * factor * sim.info["dt_stable"], rel=1e-3)


@pytest.mark.parametrize("xi", [0.0, 0.3, 2.0])
def test_damped_step_factor_is_the_stability_limit(xi):
    """The amplification matrix of m a = -k u - c v^{n-1/2} has spectral radius 1 at
    omega dt = 2 (sqrt(1 + xi^2) - xi) and above 1 just past it."""
    omega = 1.0
    limit = 2.0 / omega * damped_step_factor(0.0, 2 * xi / omega, 2.0 / omega)

    def radius(dt):
        w, z = omega * dt, xi * omega * dt  # u+ = (2 - w^2 - 2 z) u + (2 z - 1) u-
        return max(abs(np.roots([1.0, w * w + 2 * z - 2.0, 1.0 - 2 * z])))

    assert radius(limit * (1 - 1e-6)) <= 1.0 + 1e-9
    assert radius(limit * (1 + 1e-3)) > 1.0


@pytest.mark.parametrize(
    "table, message",
    [
        ({"load": [{"kind": "force", "group": "nowhere", "force": [0, 0, 1]}]},
         "load[0].group: unknown node set 'nowhere'"),
        ({"added_mass": [{"group": "nowhere", "mass": 1.0}]},
         "added_mass[0].group: unknown node set 'nowhere'"),
        ({"damping": {"alpha": 1.0, "group": "nowhere"}},
         "damping.group: unknown node set 'nowhere'"),
    ],
)  # fmt: skip
def test_unknown_sets_are_refused_in_one_line(table, message, shared_dir):
    raw = bar_scene(elements=2, h=H, speed=0.0, wall=False, end_time=1e-7) | table
    with pytest.raises(SceneError, match=message.replace("[", r"\[").replace("]", r"\]")):
        build_simulation(parse_scene(raw, source="test"), MPI.COMM_WORLD, shared_dir)


def test_a_resumed_run_with_loads_equals_an_uninterrupted_one(shared_dir):
    """What the loads and the damping carry from step to step is in the checkpoints."""
    from pathlib import Path

    from conftest import StopAt

    raw = pulled_bar({"kind": "pressure", "pressure": -F / AREA})
    raw["damping"]["beta"] = 1e-9
    raw["load"].append({"kind": "force", "group": "top", "force": [1.0, 0.0, 0.0]})
    raw["run"]["end_time"] = 2 * PERIOD
    raw["output"] |= {"history_interval": 5, "checkpoint_steps": 50}
    root = Path(shared_dir)
    whole = run(raw, root / "whole")
    sim = build_simulation(parse_scene(copy.deepcopy(raw), source="test"), MPI.COMM_WORLD,
                           root / "stopped")  # fmt: skip
    sim.recorders.append(StopAt(72))
    assert sim.run().startswith("stopped")
    MPI.COMM_WORLD.Barrier()
    sim = build_simulation(parse_scene(copy.deepcopy(raw), source="test"), MPI.COMM_WORLD,
                           root / "stopped")  # fmt: skip
    sim.checkpoints.resume(sim)
    assert sim.run() == "done"
    assert np.array_equal(sim.state.u, whole.state.u)
    assert sim.history.summary["energy"] == whole.history.summary["energy"]
