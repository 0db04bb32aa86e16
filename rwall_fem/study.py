"""What accuracy costs in time: a convergence and cost study against independent references.

Three cases whose exact answers do not come from the code (``../shared/notes/numerics.md``):

- ``bar``: a nu = 0 steel bar, 8 x 8 x 80 mm, hits a fixed plane at 10 m/s. 1-D wave theory:
  contact lasts 2L/c, the impulse is 2 m v0, the plateau force rho c A v0, the rebound v0.
- ``moving_wall``: a plane of twice the bar's mass, carried by a main node, hits the same bar
  (free) at 5 m/s. While in contact M_w dV/dt = -rho c A V: the wall leaves after 2L/c at
  V0 exp(-2 m_b / M_w).
- ``friction``: a soft 1 cm cube (nu = 0.3) on a belt whose speed is k t^2 / 2 (mu = 0.3).
  Rigid-body closed form: the block sticks until k t = mu g, then slips at mu g; its final
  velocity is k t_s^2 / 2 + mu g (t - t_s) and the friction work -mu m g k (t - t_s)^3 / 6.

Each case is run for every element size (halving), cell type (P1 tetrahedra, Q1 hexahedra)
and ``dt_scale`` (0.5, 0.9). Every run records its cells, steps, dt, the wall time of the
time loop (median of repeats for short runs), the ns per cell-step, the signed relative error
of each quantity, the share of the energy the wall dissipated and the energy balance error.
The runs use the communicator given (every rank takes part in every run and takes the same
decisions: run times come from the summary, already reduced over ranks); rank 0 writes
``study.csv``, ``study.md`` (summary and tables), ``summary.md`` and ``study_<case>.png``
(error against wall time, log-log, one line per cell type x dt_scale, slope guides).

The cost of an accuracy target is read from the data by linear interpolation of
log(error) against log(time) (and log(cells)) between the two runs that bracket it; beyond
the data the slope of the two nearest runs extrapolates, and the summary says so.
"""

from __future__ import annotations

import csv
import math
import os
import statistics
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from mpi4py import MPI

__all__ = ["CASES", "Case", "cost_at", "run_study"]

STEEL_NU0 = {"model": "linear_elastic", "density": 7850.0, "young": 210.0e9, "poisson": 0.0}
SOFT = {"model": "linear_elastic", "density": 1000.0, "young": 1.0e6, "poisson": 0.3}
CELLS = ("tetrahedron", "hexahedron")
DT_SCALES = (0.5, 0.9)
SAMPLES = 100  # history rows per run: enough for the plateau, cheap beside the loop

# The bar of the bar and moving-wall cases (m); nu = 0 makes it exactly 1-D.
BAR_SIDE, BAR_LENGTH = 0.008, 0.08
C_BAR = math.sqrt(STEEL_NU0["young"] / STEEL_NU0["density"])
BAR_AREA = BAR_SIDE**2
BAR_MASS = STEEL_NU0["density"] * BAR_AREA * BAR_LENGTH
BAR_SPEED, WALL_SPEED, WALL_RATIO = 10.0, 5.0, 2.0

# The belt of the friction case.
G, MU, BELT_K, BELT_END, BLOCK = 9.81, 0.3, 100.0, 0.05, 0.01  # m/s^2, -, m/s^3, s, m
BLOCK_MASS = SOFT["density"] * BLOCK**3
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
    from rwall_fem.history import WALL_COLUMNS

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


def _soft_c_p() -> float:
    E, nu, rho = SOFT["young"], SOFT["poisson"], SOFT["density"]
    return math.sqrt(E * (1 - nu) / ((1 + nu) * (1 - 2 * nu)) / rho)


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
            "history_interval": _history_interval(BELT_END, h, dt_scale, _soft_c_p()),
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
        c_p=_soft_c_p(),
        note=(
            "Why this error grows with refinement: the reference is a rigid block, but steady "
            "sliding of an elastic body on a rigid surface under Coulomb friction is dynamically "
            "unstable, with growth rates that rise with the wavenumber (Adams, J. Appl. Mech. "
            "62, 1995; Renardy, J. Elasticity 27, 1992), so finer meshes resolve faster "
            "modes. Seen with 0.625 mm hexahedra: the block starts unstressed, so its sole "
            "already bounces under gravity while it sticks (178-289 of 289 nodes in contact), "
            "which costs nothing then; once it slips the chatter grows (down to 35 nodes in "
            "contact), the friction force drops to 0.80 mu N in 35-45 ms (nodes in contact "
            "that stick) and the block ends 5.9 % slow. A 2 kHz friction filter leaves "
            "-4.3 %. The coarse levels and the tests (test_friction.py) agree with the rigid "
            "closed form to 0.2-0.7 %."
        ),
    ),
}


def run_case(case: Case, h: float, cell: str, dt_scale: float, comm, directory: Path, *,
             repeat_below: float, max_repeats: int) -> dict:  # fmt: skip
    """One run (repeated while short) -> a row of ``study.csv``."""
    from rwall_fem import build_simulation, parse_scene

    scene = parse_scene(case.scene(h, cell, dt_scale), source=f"study:{case.name}")
    loops, setups = [], []
    while True:
        started = time.perf_counter()
        sim = build_simulation(scene, comm, directory)
        setups.append(comm.allreduce(time.perf_counter() - started, op=MPI.MAX))
        sim.run()
        summary = sim.history.summary
        # Reduced over ranks (MAX) by the history: every rank sees the same value and so
        # takes the same decision to repeat.
        loops.append(summary["wall_seconds"])
        if len(loops) == 1:
            errors = case.measure(sim)
            energy = summary["energy"]
            supplied = energy["initial"] + max(energy["external_work"], 0.0)
            share = -energy["wall_work"] / supplied if supplied > 0 else math.nan
        if len(loops) >= max_repeats or sum(loops) >= repeat_below:
            break
    loop = statistics.median(loops)
    cells, steps = summary["cells"], summary["steps"]
    row = {
        "case": case.name,
        "cell": cell,
        "dt_scale": dt_scale,
        "element_size": h,
        "ranks": comm.size,
        "cells": cells,
        "nodes": summary["nodes"],
        "steps": steps,
        "dt": summary["dt"],
        "setup_seconds": statistics.median(setups),
        "wall_seconds": loop,
        "repeats": len(loops),
        "ns_per_cell_step": 1e9 * loop / (cells * steps),
        "wall_share": share,
        "balance_error": energy["max_balance_error"],
    }
    row |= {f"error_{key}": errors[key] for key in case.quantities}
    return row


def cost_at(errors, seconds, cells, target: float):
    """(seconds, cells, how) at which |error| reaches ``target``, by log-log interpolation
    between the two runs that bracket it (``how`` = "interpolated"), else along the slope
    of the two runs nearest to it ("extrapolated"); None if the errors do not fall."""
    e = np.abs(np.asarray(errors, float))
    t, n = np.asarray(seconds, float), np.asarray(cells, float)
    keep = np.isfinite(e) & (e > 0)
    e, t, n = e[keep], t[keep], n[keep]
    if len(e) < 2:
        return None
    order = np.argsort(t)
    e, t, n = np.log(e[order]), np.log(t[order]), np.log(n[order])
    goal = math.log(target)
    pair, how = None, "extrapolated"
    for i in range(len(e) - 1):
        if (e[i] - goal) * (e[i + 1] - goal) <= 0 and e[i] != e[i + 1]:
            pair, how = (i, i + 1), "interpolated"
            break
    if pair is None:
        pair = (len(e) - 2, len(e) - 1) if e[-1] > goal else (0, 1)
    i, j = pair
    if e[j] >= e[i]:
        return None  # no decrease to follow
    w = (goal - e[i]) / (e[j] - e[i])
    return (
        math.exp(t[i] + w * (t[j] - t[i])),
        math.exp(n[i] + w * (n[j] - n[i])),
        how,
    )


def _slope(errors, seconds) -> float:
    """Least-squares slope of log|error| against log(time) over the runs (nan if < 2)."""
    e, t = np.abs(np.asarray(errors, float)), np.asarray(seconds, float)
    keep = np.isfinite(e) & (e > 0)
    if keep.sum() < 2:
        return math.nan
    return float(np.polyfit(np.log(t[keep]), np.log(e[keep]), 1)[0])


def _technologies(rows):
    return sorted({(r["cell"], r["dt_scale"]) for r in rows})


def _series(rows, case, cell, dt_scale):
    chosen = [r for r in rows if (r["case"], r["cell"], r["dt_scale"]) == (case, cell, dt_scale)]
    return sorted(chosen, key=lambda r: -r["element_size"])


def _label(cell: str, dt_scale: float) -> str:
    return f"{'P1 tet' if cell == 'tetrahedron' else 'Q1 hex'}, dt_scale {dt_scale:g}"


def summarise(rows, cases, target: float = 0.01) -> str:
    """Plain-words markdown: what ``target`` relative error costs, for each headline quantity."""
    lines = ["# What accuracy costs in time", ""]
    ranks = rows[0]["ranks"] if rows else 1
    lines.append(
        f"Computed from {len(rows)} runs on {ranks} MPI rank(s); time is the wall time of the "
        "time loop (median of repeats for short runs), set-up (meshing, assembly, stable step) "
        "excluded. Costs are interpolated in log-log between the two runs that bracket the "
        "target (or extrapolated along the nearest two, as marked)."
    )
    lines.append("")
    for case in cases:
        label = case.quantities[case.headline]
        lines.append(f"**{case.title}**, {label}:")
        lines.append("")
        best = None
        for cell, dt_scale in _technologies([r for r in rows if r["case"] == case.name]):
            series = _series(rows, case.name, cell, dt_scale)
            errors = [r[f"error_{case.headline}"] for r in series]
            seconds = [r["wall_seconds"] for r in series]
            cells = [r["cells"] for r in series]
            one = cost_at(errors, seconds, cells, target)
            half = cost_at(errors, seconds, cells, target / 2)
            slope = _slope(errors, seconds)
            name = _label(cell, dt_scale)
            if one is None:
                lines.append(
                    f"- {name}: the error does not fall with refinement here "
                    f"({', '.join(f'{100 * e:+.2f} %' for e in errors)})."
                )
                continue
            text = (
                f"- {name}: {100 * target:g} % {label} error takes about {one[1]:,.0f} cells and "
                f"{one[0]:.3g} s ({one[2]})"
            )
            if half is not None:
                text += f"; halving it costs {half[0] / one[0]:.3g}x the time ({half[2]})"
            text += f" (error ~ time^{slope:.2f} over the runs)."
            lines.append(text)
            if best is None or one[0] < best[1]:
                best = (name, one[0], one[1])
        if best is not None:
            lines.append("")
            where = case.name.replace("_", " ")
            lines.append(
                f"In one line: {100 * target:g} % {label} error on the {where}"
                f" costs {best[2]:,.0f} cells and {best[1]:.3g} s with the cheapest technology "
                f"({best[0]})."
            )
        if case.note:
            lines += ["", case.note]
        lines.append("")
    lines.append(
        "Guides: an O(h) error at a cost growing like h^-4 (h^-3 cells times h^-1 steps) "
        "falls like time^-1/4, so halving it costs 16x; O(h^2) falls like time^-1/2 (4x)."
    )
    return "\n".join(lines) + "\n"


def _table(rows, case: Case) -> str:
    keys = list(case.quantities)
    head = (
        ["cell", "dt_scale", "h (mm)", "cells", "steps", "dt (s)", "loop (s)", "ns/cell-step"]
        + [f"{case.quantities[k]} err" for k in keys]
        + ["wall share", "balance err"]
    )
    out = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for cell, dt_scale in _technologies([r for r in rows if r["case"] == case.name]):
        for r in _series(rows, case.name, cell, dt_scale):
            cells = [
                cell[:3],
                f"{dt_scale:g}",
                f"{1e3 * r['element_size']:g}",
                f"{r['cells']:,}",
                f"{r['steps']}",
                f"{r['dt']:.3g}",
                f"{r['wall_seconds']:.3g}",
                f"{r['ns_per_cell_step']:.0f}",
                *(f"{100 * r[f'error_{k}']:+.3f} %" for k in keys),
                f"{100 * r['wall_share']:.3f} %",
                f"{r['balance_error']:.1e}",
            ]
            out.append("| " + " | ".join(cells) + " |")
    return "\n".join(out) + "\n"


def plot(rows, case: Case, path: Path) -> None:
    """Error against wall time, log-log, one panel per quantity, one line per technology."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    keys = list(case.quantities)
    fig, axes = plt.subplots(1, len(keys), figsize=(4.2 * len(keys), 3.8), squeeze=False)
    mine = [r for r in rows if r["case"] == case.name]
    for ax, key in zip(axes[0], keys, strict=True):
        every_t, every_e = [], []
        for (cell, dt_scale), marker in zip(_technologies(mine), "osD^v", strict=False):
            series = _series(rows, case.name, cell, dt_scale)
            t = np.array([r["wall_seconds"] for r in series])
            e = 100 * np.abs([r[f"error_{key}"] for r in series])
            good = e > 0
            ax.loglog(t[good], e[good], marker=marker, label=_label(cell, dt_scale))
            every_t += list(t[good])
            every_e += list(e[good])
        if every_t:
            # Slope guides through the middle of the data.
            t0 = math.exp(np.mean(np.log(every_t)))
            e0 = math.exp(np.mean(np.log(every_e)))
            span = np.array([min(every_t), max(every_t)])
            for power, style in ((-0.25, ":"), (-0.5, "--")):
                ax.loglog(span, e0 * (span / t0) ** power, "k" + style, lw=0.8,
                          label=f"slope {power:g}")  # fmt: skip
        ax.axhline(1.0, color="grey", lw=0.6)
        ax.set_xlabel("wall time of the time loop (s)")
        ax.set_ylabel("|relative error| (%)")
        ax.set_title(case.quantities[key], fontsize=10)
        ax.grid(True, which="both", lw=0.3)
    axes[0][0].legend(fontsize=7)
    fig.suptitle(case.title, fontsize=11)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def write_outputs(rows, cases, out: Path, seconds: float, load=None) -> None:
    """study.csv, study.md (summary + tables), summary.md, study_<case>.png (rank 0 only)."""
    out.mkdir(parents=True, exist_ok=True)
    columns = list(dict.fromkeys(k for r in rows for k in r))
    with open(out / "study.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, columns, restval="")
        writer.writeheader()
        writer.writerows(rows)
    summary = summarise(rows, cases)
    (out / "summary.md").write_text(summary)
    took = f"The whole study took {seconds:.0f} s (set-up included) on {os.cpu_count()} cores"
    if load is not None:
        # Timings are only as good as the machine was quiet: say how busy it was.
        took += f"; 1-minute load average {load[0]:.2f} before, {load[1]:.2f} after"
    parts = [summary, took + ".", ""]
    for case in cases:
        plot(rows, case, out / f"study_{case.name}.png")
        parts += [
            f"## {case.title}",
            "",
            f"![{case.name}](study_{case.name}.png)",
            "",
            _table(rows, case),
        ]
    parts += [
        "Columns: relative errors are signed (computed - exact) / exact; *wall share* is the "
        "energy the wall dissipated over the energy put in (initial plus external work); "
        "*balance err* the largest energy balance error of the run; *loop* the wall time "
        "of the time loop. Every run and its reference: `rwall_fem/study.py`.",
        "",
    ]
    (out / "study.md").write_text("\n".join(parts))


def run_study(out="results/study", *, quick: bool = False, comm=MPI.COMM_WORLD,
              cases=None, echo=print) -> list[dict]:  # fmt: skip
    """Run every case x cell type x dt_scale x element size; write the outputs into ``out``.

    Returns the rows (the same on every rank).
    """
    out = Path(out)
    cases = [CASES[name] for name in (cases or CASES)]
    repeat_below, max_repeats = (0.3, 2) if quick else (1.0, 3)
    started = time.perf_counter()
    load = [os.getloadavg()[0]]
    rows = []
    for case in cases:
        for cell in CELLS:
            for dt_scale in DT_SCALES:
                for h in case.quick_levels if quick else case.levels:
                    run_dir = out / "runs" / f"{case.name}-{cell[:3]}-dt{dt_scale:g}-h{h * 1e3:g}mm"
                    row = run_case(case, h, cell, dt_scale, comm, run_dir,
                                   repeat_below=repeat_below, max_repeats=max_repeats)  # fmt: skip
                    rows.append(row)
                    if comm.rank == 0 and echo:
                        errors = " ".join(
                            f"{k}={100 * row[f'error_{k}']:+.3f}%" for k in case.quantities
                        )
                        echo(
                            f"study: {case.name} {cell[:3]} dt_scale={dt_scale:g} "
                            f"h={h * 1e3:g}mm cells={row['cells']} steps={row['steps']} "
                            f"loop={row['wall_seconds']:.3g}s "
                            f"({row['ns_per_cell_step']:.0f} ns/cell-step) {errors}",
                            flush=True,
                        )
    seconds = comm.allreduce(time.perf_counter() - started, op=MPI.MAX)
    load.append(os.getloadavg()[0])
    if comm.rank == 0:
        write_outputs(rows, cases, out, seconds, load)
    comm.Barrier()
    return rows
