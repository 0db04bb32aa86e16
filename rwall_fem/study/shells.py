"""Shells against solids: a clamped 2 mm steel plate struck by a sphere wall.

The plate of the peer decks (``../shared/peer-decks/gen_shell.py plate``): 200 x 200 mm,
2 mm steel (rho 7850 kg/m^3, E 210 GPa, nu 0.3), its rim clamped, struck at its centre by
a rigid sphere of 40 mm on a 1 kg main node; elastic at 5 m/s (4 ms), and elasto-plastic
(J2, sigma_y = 300 MPa + 300 MPa eps_p) at 20 m/s (2 ms). The sphere starts 0.1 mm above
the skin it strikes: the solids' top face, the shells' mid-surface (walls act on the
shells' nodes, with no thickness offset). The shells are the whole plate; the solids a
quarter of it (the planes x = 0 and y = 0 are planes of symmetry, the sphere's mass is a
quarter), one-point hexahedra with the Flanagan-Belytschko stiffness hourglass control,
refined in the plane and through the thickness together (the cells' aspect stays 5); the
reference is the finest solid. The sphere's main node of the quarter lies on both planes:
its x and y velocity are held (``motion.held = "xy"``). Free, it drifted sideways as soon
as the plastic plate wrapped round it (nodes off the axis touching it all push it away from
the quarter), about 4 m/s by 2 ms, and rebounded late or not at all; held, a quarter of the
shells gives the whole plate's answers to 1e-12, elastic and elasto-plastic
(``tests/shells/test_shell_symmetry.py``).

Figures per run: the peak force on the sphere (N, its largest 50-us mean), the contact
time (s, of the first contact: gaps under 50 us bridged, later touches of the receding
sphere by the vibrating plate left out) and the largest deflection under the sphere (m:
its largest travel less the 0.1 mm gap), with the cells, steps and the wall and CPU times
of the time loop.
"""

from __future__ import annotations

import csv
import math
import time
from pathlib import Path

import numpy as np

from rwall_fem.build import build_simulation
from rwall_fem.output import OutputError
from rwall_fem.scene import parse_scene

__all__ = ["LOADS", "SHELL_LEVELS", "SOLID_LEVELS", "measure", "plate_scene", "run_plate",
           "run_shell_study"]  # fmt: skip

HALF = 0.1  # m, the quarter's side (the plate is 200 mm)
THICKNESS = 0.002  # m
RADIUS = 0.02  # m, the sphere's
GAP = 1.0e-4  # m, from the sphere to the skin it strikes
STEEL = {"density": 7850.0, "young": 210.0e9, "poisson": 0.3}
# name -> (material table, impact speed m/s, end time s). The elastic solids take the
# large-deformation Saint Venant-Kirchhoff law: "linear_elastic" is geometrically linear
# on solids (no membrane stiffening: 34 % more deflection here), while the shells'
# co-rotational frame makes it exact for large rotations (the strains stay small).
LOADS = {
    "elastic": ({"model": "linear_elastic", **STEEL}, 5.0, 4.0e-3),
    "plastic": ({"model": "elastic_plastic", **STEEL, "hardening": "linear",
                 "yield_stress": 300.0e6, "hardening_modulus": 300.0e6}, 20.0, 2.0e-3),
}  # fmt: skip
SOLID_MODEL = {"linear_elastic": "saint_venant_kirchhoff"}
# (in-plane size m, layers through the thickness): the aspect of the hexahedra stays 5.
SOLID_LEVELS = ((5.0e-3, 2), (2.5e-3, 4), (1.6667e-3, 6))
SHELL_LEVELS = (5.0e-3, 2.5e-3)  # m, quadrilaterals
QUICK_SOLID, QUICK_SHELL = ((5.0e-3, 2),), (5.0e-3,)
SOLID_ELEMENT = {"integration": "reduced", "hourglass": "stiffness"}
MASS = 1.0  # kg, the whole sphere's
PEAK_WINDOW = 50e-6  # s, the peak force is the largest mean over this long
SHARE = {"solid": 4, "shell": 1}  # the whole plate over the part that is run

# The quarter plate in hexahedra: a structured box with its symmetry planes and its rim
# as named face groups (the built-in plate names its sides only together).
_QUARTER_GEO = """// quarter of a plate, {lx} x {lx} x {t} m, {n} x {n} x {layers} hexahedra
SetFactory("Built-in");
Point(1) = {{0, 0, {z0}}};
ex[] = Extrude {{{lx}, 0, 0}} {{ Point{{1}}; Layers{{{n}}}; Recombine; }};
ey[] = Extrude {{0, {lx}, 0}} {{ Line{{ex[1]}}; Layers{{{n}}}; Recombine; }};
ez[] = Extrude {{0, 0, {t}}} {{ Surface{{ey[1]}}; Layers{{{layers}}}; Recombine; }};
e = {eps};
lo = {z0} - e; hi = {z1} + e; L = {lx};
Physical Volume("body") = {{ez[1]}};
Physical Surface("sym_x") = Surface In BoundingBox{{-e, -e, lo, e, L + e, hi}};
Physical Surface("sym_y") = Surface In BoundingBox{{-e, -e, lo, L + e, e, hi}};
Physical Surface("rim_x") = Surface In BoundingBox{{L - e, -e, lo, L + e, L + e, hi}};
Physical Surface("rim_y") = Surface In BoundingBox{{-e, L - e, lo, L + e, L + e, hi}};
"""


def _quarter_geo(folder: Path, h: float, layers: int) -> Path:
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"quarter_h{h * 1e3:g}mm_{layers}layers.geo"
    n = round(HALF / h)
    text = _QUARTER_GEO.format(lx=HALF, t=THICKNESS, n=n, layers=layers, z0=-THICKNESS / 2,
                               z1=THICKNESS / 2, eps=1e-3 * h)  # fmt: skip
    path.write_text(text)
    return path


def plate_scene(load: str, kind: str, h: float, layers: int = 0,
                folder: Path = Path(".")) -> dict:  # fmt: skip
    """The scene of ``kind`` "shell" (the whole plate in quadrilaterals of ``h`` m) or
    "solid" (its quarter in hexahedra, ``layers`` through the thickness, the mesh file in
    ``folder``) under ``load`` (a key of :data:`LOADS`)."""
    material, speed, end_time = LOADS[load]
    if kind == "shell":  # the whole plate
        mesh = {"shape": "plate", "origin": [-HALF, -HALF, -THICKNESS / 2],
                "size": [2 * HALF, 2 * HALF, THICKNESS], "element_size": h,
                "cell": "quadrilateral"}  # fmt: skip
        boundary = [{"group": side, "components": "xyz", "rotations": "xyz"}
                    for side in ("side_x0", "side_x1", "side_y0", "side_y1")]  # fmt: skip
        element, skin = {"points": 5}, 0.0  # the sphere acts on the mid-surface
    else:
        mesh = {"file": str(_quarter_geo(folder, h, layers))}
        boundary = [
            {"group": "sym_x", "components": "x"},
            {"group": "sym_y", "components": "y"},
            {"group": "rim_x", "components": "xyz"},
            {"group": "rim_y", "components": "xyz"},
        ]
        element, skin = dict(SOLID_ELEMENT), THICKNESS / 2
    material = dict(material)
    if kind == "solid":
        material["model"] = SOLID_MODEL.get(material["model"], material["model"])
    return {
        "run": {"end_time": end_time},
        "mesh": mesh,
        "element": element,
        "material": material,
        "boundary": boundary,
        "wall": [{
            "kind": "sphere", "point": [0.0, 0.0, skin + GAP + RADIUS], "diameter": 2 * RADIUS,
            "motion": {"mass": MASS / SHARE[kind], "velocity": [0.0, 0.0, -speed]}
            | ({"held": "xy"} if kind == "solid" else {}),  # the quarter's sphere: on x = y = 0
        }],
        "output": {"frames": 0, "plot": False, "history_interval": 1},
    }  # fmt: skip


def run_plate(load: str, kind: str, h: float, layers: int, comm, folder: Path) -> dict:
    """One run -> a row: its size, cost and the whole plate's figures (:func:`measure`)."""
    raw = plate_scene(load, kind, h, layers, folder)
    scene = parse_scene(raw, source=f"study:shells:{load}:{kind}")
    sim = build_simulation(scene, comm, folder)
    cpu = time.process_time()
    sim.run()
    cpu = comm.allreduce(time.process_time() - cpu)
    s = sim.history.summary
    row = {"load": load, "kind": kind, "status": s["status"], "element_size": h, "layers": layers,
           "cells": s["cells"], "steps": s["steps"], "dt": s["dt"],
           "wall_seconds": s["wall_seconds"], "cpu_seconds": cpu}  # fmt: skip
    return row | measure(s, sim.history.wall(0), SHARE[kind])


def measure(summary: dict, rows, share: int = 1) -> dict:
    """The whole plate's figures from the run's summary and its wall's rows (walls.csv):
    the peak force (N) is the largest mean over PEAK_WINDOW (the solids' contact chatters:
    from one step to the next their force doubles as a node strikes the sphere), the
    contact time (s) of the first contact (gaps shorter than PEAK_WINDOW bridged), the
    largest deflection (m) the sphere's largest travel less the gap, the rebound its final
    velocity (m/s); ``share`` is the whole plate over the part that ran."""
    from rwall_fem.output.wall_table import WALL_COLUMNS

    t = rows[:, WALL_COLUMNS.index("time")]
    impulse = share * rows[:, WALL_COLUMNS.index("impulse_z")]
    z = rows[:, WALL_COLUMNS.index("position_z")]
    centre = np.arange(PEAK_WINDOW / 2, t[-1] - PEAK_WINDOW / 2, PEAK_WINDOW / 10)
    mean = (np.interp(centre + PEAK_WINDOW / 2, t, impulse)
            - np.interp(centre - PEAK_WINDOW / 2, t, impulse)) / PEAK_WINDOW  # fmt: skip
    wall = summary["walls"][0]
    touching = t[rows[:, WALL_COLUMNS.index("contacts")] > 0]
    # the first contact: until the first gap longer than PEAK_WINDOW (the plate's
    # vibrations touch the receding sphere again later)
    gaps = np.flatnonzero(np.diff(touching) > PEAK_WINDOW)
    end = touching[gaps[0]] if len(gaps) else touching[-1] if len(touching) else math.nan
    return {
        "peak_force": mean.max(),
        "peak_time": centre[mean.argmax()],
        "contact_time": end - touching[0] + summary["dt"] if len(touching) else math.nan,
        "deflection": z[0] - z.min() - GAP,
        "rebound": wall["velocity"][2],
        "balance_error": summary["energy"]["max_balance_error"],
    }


FIGURES = {"peak_force": ("peak force", 1e-3, "kN"), "contact_time": ("contact time", 1e3, "ms"),
           "deflection": ("largest deflection", 1e3, "mm")}  # fmt: skip


def report(rows: list[dict], seconds: float) -> str:
    """The markdown section: every run, and each shell's error against the finest solid."""
    lines = ["## Shells against solids: a clamped 2 mm steel plate struck by a sphere", "",
             __doc__.split("\n\n", 1)[1].strip(), ""]  # fmt: skip
    for load in LOADS:
        runs = [r for r in rows if r["load"] == load]
        solids = [r for r in runs if r["kind"] == "solid"]
        if not solids:
            continue
        ref = solids[-1]
        material, speed, end = LOADS[load]
        lines += [f"**{load}** ({material['model']} shells, "
                  f"{SOLID_MODEL.get(material['model'], material['model'])} solids, "
                  f"{speed:g} m/s, {end * 1e3:g} ms); errors against the finest solid "
                  f"({ref['cells']:,} hexahedra in the quarter).", ""]  # fmt: skip
        if len(solids) > 1:
            before = solids[-2]
            change = ", ".join(f"{label} {100 * (ref[k] / before[k] - 1):+.2f} %"
                               for k, (label, _, _) in FIGURES.items())  # fmt: skip
            lines += [f"The finest solid against the level before it: {change}.", ""]
        lines += ["| model | h (mm) | layers | cells | steps | loop wall (s) | loop CPU (s) | "
                  + " | ".join(f"{label} ({unit})" for label, _, unit in FIGURES.values())
                  + " | balance |",
                  "|---" * (7 + len(FIGURES) + 1) + "|"]  # fmt: skip
        for r in runs:
            cells = [f"{r[k] * scale:.4g} ({100 * (r[k] / ref[k] - 1):+.2f} %)"
                     if r is not ref else f"{r[k] * scale:.4g}"
                     for k, (_, scale, _) in FIGURES.items()]  # fmt: skip
            layers = r["layers"] if r["kind"] == "solid" else "-"
            lines.append(f"| {r['kind']} | {r['element_size'] * 1e3:.3g} | {layers} | "
                         f"{r['cells']:,} | {r['steps']:,} | {r['wall_seconds']:.3g} | "
                         f"{r['cpu_seconds']:.3g} | " + " | ".join(cells)
                         + f" | {r['balance_error']:.1e} |")  # fmt: skip
        lines.append("")
    lines.append(f"The shell study took {seconds:.0f} s (set-up included) on 1 rank.")
    return "\n".join(lines) + "\n"


def run_shell_study(out="results/study-shells", *, quick: bool = False, comm=None,
                    loads=tuple(LOADS), echo=print) -> list[dict]:  # fmt: skip
    """Every load (of ``loads``) x (solid levels, shell levels); writes ``shells.csv`` and
    ``shells.md``."""
    from mpi4py import MPI

    comm = comm or MPI.COMM_WORLD
    out = Path(out)
    started = time.perf_counter()
    rows = []
    for load in loads:
        plan = [("solid", h, n) for h, n in (QUICK_SOLID if quick else SOLID_LEVELS)]
        plan += [("shell", h, 0) for h in (QUICK_SHELL if quick else SHELL_LEVELS)]
        for kind, h, layers in plan:
            folder = out / "runs" / f"{load}-{kind}-h{h * 1e3:.3g}mm"
            row = run_plate(load, kind, h, layers, comm, folder)
            if row["status"] != "done":  # stopped (a signal, a limit): so is the study
                raise OutputError(f"study shells: {folder}: the run {row['status']}")
            rows.append(row)
            if comm.rank == 0 and echo:
                echo(f"study shells: {load} {kind} h={h * 1e3:.3g}mm layers={layers} "
                     f"cells={row['cells']} steps={row['steps']} loop={row['wall_seconds']:.3g}s "
                     f"cpu={row['cpu_seconds']:.3g}s peak={row['peak_force']:.5g}N "
                     f"contact={row['contact_time']:.5g}s deflection={row['deflection']:.5g}m",
                     flush=True)  # fmt: skip
    seconds = comm.allreduce(time.perf_counter() - started, op=MPI.MAX)
    if comm.rank == 0:
        with open(out / "shells.csv", "w", newline="") as f:
            writer = csv.DictWriter(f, list(rows[0]))
            writer.writeheader()
            writer.writerows(rows)
        (out / "shells.md").write_text(report(rows, seconds))
    return rows
