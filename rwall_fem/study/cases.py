"""The cases of the accuracy study: scenes whose exact answers do not come from the code.

The references (``docs/theory.md``, section "Reference solutions"):

- ``bar``: a nu = 0 steel bar, 8 x 8 x 80 mm, hits a fixed plane at 10 m/s. 1-D wave theory:
  contact lasts 2L/c, the impulse is 2 m v0, the plateau force rho c A v0, the rebound v0.
- ``moving_wall``: a plane of twice the bar's mass, carried by a main node, hits the same bar
  (free) at 5 m/s. While in contact M_w dV/dt = -rho c A V: the wall leaves after 2L/c at
  V0 exp(-2 m_b / M_w).
- ``friction``: a soft 1 cm cube (nu = 0.3) on a belt whose speed is k t^2 / 2 (mu = 0.3).
  Rigid-body closed form: the block sticks until k t = mu g, then slips at mu g; its final
  velocity is k t_s^2 / 2 + mu g (t - t_s) and the friction work -mu m g k (t - t_s)^3 / 6.

The materials are those of the tests too (``tests/conftest.py``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from rwall_fem.output.wall_table import WALL_COLUMNS
from rwall_fem.scene import Material

__all__ = [
    "CASES",
    "SOFT",
    "STEEL_NU0",
    "Case",
    "bar_measure",
    "bar_scene",
    "friction_measure",
    "friction_scene",
    "moving_wall_measure",
    "moving_wall_scene",
]

# Scene tables of the materials (kg/m^3, Pa): steel with nu = 0 (a bar then is exactly
# 1-D), and a soft solid whose stable step is long (c_p about 37 m/s).
STEEL_NU0 = {"model": "linear_elastic", "density": 7850.0, "young": 210.0e9, "poisson": 0.0}
SOFT = {"model": "linear_elastic", "density": 1000.0, "young": 1.0e6, "poisson": 0.3}
C_SOFT = Material(**SOFT).p_wave_speed  # m/s
SAMPLES = 100  # history rows per run: enough for the plateau, cheap beside the loop

# The bar of the bar and moving-wall cases (m).
BAR_SIDE, BAR_LENGTH = 0.008, 0.08
C_BAR = math.sqrt(STEEL_NU0["young"] / STEEL_NU0["density"])  # bar wave speed, m/s
BAR_AREA = BAR_SIDE**2
BAR_MASS = STEEL_NU0["density"] * BAR_AREA * BAR_LENGTH
BAR_SPEED, WALL_SPEED, WALL_RATIO = 10.0, 5.0, 2.0

# The belt of the friction case.
G, MU, BELT_K, BELT_END, BLOCK = 9.81, 0.3, 100.0, 0.05, 0.01  # m/s^2, -, m/s^3, s, m
SLIP_START = MU * G / BELT_K  # s


@dataclass(frozen=True)
class Case:
    """A scene family with exact answers.

    ``scene(h, cell, dt_scale)`` gives the scene as a dict; ``measure(sim)`` the signed
    relative error of each quantity of interest (``quantities``: key -> label).
    """

    name: str
    title: str
    scene: object
    measure: object
    quantities: dict
    headline: str  # the quantity the plain-words summary is about
    levels: tuple  # element sizes (m), coarse to fine, for the full study
    quick_levels: tuple
    c_p: float  # p-wave speed (m/s), only to size the history interval
    note: str = ""  # what limits the reference, printed under the case's summary


def _history_interval(end_time: float, h: float, dt_scale: float, c_p: float) -> int:
    """About SAMPLES rows per run, from an estimate of the number of steps."""
    steps = end_time / (dt_scale * 0.5 * h / c_p)
    return max(1, int(steps // SAMPLES))


def _bar(h, cell, material, end_time, dt_scale, c_p):
    return {
        "run": {"end_time": end_time, "dt_scale": dt_scale},
        "mesh": {
            "shape": "bar",
            "size": [BAR_SIDE, BAR_SIDE, BAR_LENGTH],
            "element_size": h,
            "cell": cell,
        },
        "material": dict(material),
        "output": {
            "frames": 0,
            "plot": False,  # no histories.png per run: the study draws its own plots
            "history_interval": _history_interval(end_time, h, dt_scale, c_p),
        },
    }


def bar_scene(h: float, cell: str, dt_scale: float) -> dict:
    """The bar on a fixed plane: touching it at t = 0, three wave transits long."""
    raw = _bar(h, cell, STEEL_NU0, 3 * BAR_LENGTH / C_BAR, dt_scale, C_BAR)
    raw["initial"] = {"velocity": [0.0, 0.0, -BAR_SPEED]}
    raw["wall"] = [{"kind": "plane", "point": [0.0, 0.0, 0.0], "normal_point": [0.0, 0.0, 1.0]}]
    return raw


def _contact(sim, wall: int = 0):
    """(first contact, duration) in s from the summary: the last contact step counts whole."""
    entry = sim.history.summary["walls"][wall]
    first, last = entry["first_contact"], entry["last_contact"]
    if first is None:
        return math.nan, math.nan
    return first, last - first + sim.state.dt


def bar_measure(sim) -> dict:
    summary = sim.history.summary
    mass = summary["mass"]
    start, duration = _contact(sim)
    exact_duration = 2 * BAR_LENGTH / C_BAR
    impulse = -summary["walls"][0]["normal_impulse"][2]  # the push on the wall is along -z
    rebound = summary["final_momentum"][2] / mass
    # Plateau: mean force over the middle half of the exact contact, from the cumulative
    # impulse history (rows every few steps), interpolated at the window's ends.
    rows = sim.history.wall(0)
    t = rows[:, WALL_COLUMNS.index("time")]
    cumulative = -rows[:, WALL_COLUMNS.index("normal_impulse_z")]
    t1, t3 = start + 0.25 * exact_duration, start + 0.75 * exact_duration
    plateau = (np.interp(t3, t, cumulative) - np.interp(t1, t, cumulative)) / (t3 - t1)
    exact_plateau = STEEL_NU0["density"] * C_BAR * BAR_AREA * BAR_SPEED
    return {
        "rebound": rebound / BAR_SPEED - 1.0,
        "impulse": impulse / (2 * mass * BAR_SPEED) - 1.0,
        "duration": duration / exact_duration - 1.0,
        "plateau": plateau / exact_plateau - 1.0,
    }


def moving_wall_scene(h: float, cell: str, dt_scale: float) -> dict:
    """A main-node plane of WALL_RATIO times the bar's mass hits the free bar at WALL_SPEED."""
    raw = _bar(h, cell, STEEL_NU0, 3 * BAR_LENGTH / C_BAR, dt_scale, C_BAR)
    raw["wall"] = [
        {
            "kind": "plane",
            "point": [0.0, 0.0, 0.0],
            "normal_point": [0.0, 0.0, 1.0],
            "motion": {"mass": WALL_RATIO * BAR_MASS, "velocity": [0.0, 0.0, WALL_SPEED]},
        }
    ]
    return raw


def moving_wall_measure(sim) -> dict:
    summary = sim.history.summary
    final = summary["walls"][0]["velocity"][2]
    _, duration = _contact(sim)
    return {
        "wall_velocity": final / (WALL_SPEED * math.exp(-2.0 / WALL_RATIO)) - 1.0,
        "duration": duration / (2 * BAR_LENGTH / C_BAR) - 1.0,
    }


def friction_scene(h: float, cell: str, dt_scale: float) -> dict:
    """The soft cube resting on a belt that accelerates as k t (velocity table, fine enough
    that its linear interpolation is exact to 1e-6 of the belt speed)."""
    times = np.linspace(0.0, BELT_END, 501)
    table = [[t, 0.5 * BELT_K * t * t, 0.0, 0.0] for t in times]
    return {
        "run": {"end_time": BELT_END, "dt_scale": dt_scale},
        "mesh": {"shape": "bar", "size": [BLOCK] * 3, "element_size": h, "cell": cell},
        "material": dict(SOFT),
        "gravity": {"acceleration": [0.0, 0.0, -G]},
        "wall": [
            {
                "kind": "plane",
                "point": [0.0, 0.0, 0.0],
                "normal_point": [0.0, 0.0, 1.0],
                "slide": "friction",
                "friction": MU,
                "motion": {"velocity": table},
            }
        ],
        "output": {
            "frames": 0,
            "plot": False,
            "history_interval": _history_interval(BELT_END, h, dt_scale, C_SOFT),
        },
    }


def friction_measure(sim) -> dict:
    summary, dt = sim.history.summary, sim.state.dt
    # The final momentum holds v^{N+1/2}: the velocity half a step after the last step.
    t_end = (summary["steps"] + 0.5) * dt
    velocity = summary["final_momentum"][0] / summary["mass"]
    exact = 0.5 * BELT_K * SLIP_START**2 + MU * G * (t_end - SLIP_START)
    t_work = summary["steps"] * dt
    exact_work = -MU * summary["mass"] * G * BELT_K * (t_work - SLIP_START) ** 3 / 6.0
    return {
        "velocity": velocity / exact - 1.0,
        "friction_work": summary["walls"][0]["friction_work"] / exact_work - 1.0,
    }


CASES = {
    "bar": Case(
        name="bar",
        title="nu = 0 bar on a fixed plane (1-D wave theory)",
        scene=bar_scene,
        measure=bar_measure,
        quantities={
            "rebound": "rebound velocity",
            "impulse": "wall impulse",
            "duration": "contact duration",
            "plateau": "plateau force",
        },
        headline="rebound",
        levels=(4e-3, 2e-3, 1e-3, 5e-4),
        quick_levels=(4e-3, 2e-3, 1e-3),
        c_p=C_BAR,
    ),
    "moving_wall": Case(
        name="moving_wall",
        title="heavy main-node wall on a free bar (exponential decay)",
        scene=moving_wall_scene,
        measure=moving_wall_measure,
        quantities={"wall_velocity": "final wall velocity", "duration": "contact duration"},
        headline="wall_velocity",
        levels=(4e-3, 2e-3, 1e-3, 5e-4),
        quick_levels=(4e-3, 2e-3, 1e-3),
        c_p=C_BAR,
    ),
    "friction": Case(
        name="friction",
        title="Coulomb stick-slip on an accelerating belt (rigid-body closed form)",
        scene=friction_scene,
        measure=friction_measure,
        quantities={"velocity": "final block velocity", "friction_work": "friction work"},
        headline="velocity",
        levels=(5e-3, 2.5e-3, 1.25e-3, 6.25e-4),
        quick_levels=(5e-3, 2.5e-3),
        c_p=C_SOFT,
        note=(
            "Why this error grows with refinement: docs/study_notes.md (measured with "
            "0.625 mm hexahedra)."
        ),
    ),
}
