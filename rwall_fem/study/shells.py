"""Shells against solids: a clamped 2 mm steel plate struck by a sphere wall.

The plate of the peer decks (``../shared/peer-decks/gen_shell.py plate``): 200 x 200 mm,
2 mm steel (rho 7850 kg/m^3, E 210 GPa, nu 0.3), its rim clamped, struck at its centre by
a rigid sphere of 40 mm on a 1 kg main node; elastic at 5 m/s (3 ms), and elasto-plastic
(J2, sigma_y = 300 MPa + 300 MPa eps_p) at 20 m/s (2 ms). The sphere starts 0.1 mm above
the skin it strikes: the solids' top face, the shells' mid-surface (walls act on the
shells' nodes, with no thickness offset). The shells are the whole plate in 5-point
Belytschko-Lin-Tsay quadrilaterals with the Belytschko-Wong-Chiang warping correction; the
solids a quarter of it (the planes x = 0 and y = 0 are planes of symmetry, held by u_x = 0
on x = 0 and u_y = 0 on y = 0; the sphere's mass is a quarter), one-point hexahedra,
refined in the plane and through the thickness together (the cells' aspect stays 5):
elastic, with the Flanagan-Belytschko stiffness hourglass control (coefficient 0.1), 5 mm x
2 layers, 2.5 mm x 4 and 1.25 mm x 8; elasto-plastic, with the physical (assumed-strain)
hourglass control (coefficient 0.1), 5 mm x 2, 2.5 mm x 4, 1.667 mm x 6 and 1.25 mm x 8
(its levels converge faster than the stiffness form's). The sphere's main node of
the quarter lies on both planes: its x and y velocity are held (``motion.held = "xy"``).
Free, it drifted sideways as soon as the plastic plate wrapped round it (nodes off the axis
touching it all push it away from the quarter); held, a quarter of the shells gives the
whole plate's answers to 1e-12 (``tests/shells/test_shell_symmetry.py``), and the coarsest
solid quarter the whole solid plate's to 3e-5 (the whole plate, meshed by the built-in
``plate`` shape, takes a step 1e-3 longer).

The reference of each figure is Richardson's extrapolation of the three finest solid levels
(`richardson` in `rwall_fem/study/shells.py`): the observed order, the extrapolated
value and its estimated error (Roache's grid convergence index, safety factor 1.25); the
reference is converged when
the finest solid lies within 1 % of it. The solid rows are computed by
``python -m rwall_fem.study.shells --solids`` (hours on one rank) and kept in
docs/study_shells_solids.csv, which ``rwall-fem study --shells`` reads, running its missing
levels and the coarsest level again to check the kept rows against the code.

Figures per run: the peak force on the sphere (N, its largest 50-us mean), the contact
time (s, of the first contact: gaps under 50 us bridged, later touches of the receding
sphere by the vibrating plate left out) and the largest deflection under the sphere (m:
its largest travel less the 0.1 mm gap), with the cells, steps and the wall and CPU times
of the time loop; each figure's error against the solid reference in brackets.
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
    "elastic": ({"model": "linear_elastic", **STEEL}, 5.0, 3.0e-3),
    "plastic": ({"model": "elastic_plastic", **STEEL, "hardening": "linear",
                 "yield_stress": 300.0e6, "hardening_modulus": 300.0e6}, 20.0, 2.0e-3),
}  # fmt: skip
SOLID_MODEL = {"linear_elastic": "saint_venant_kirchhoff"}
# load -> its levels (in-plane size m, layers through the thickness), refined together so
# that the aspect of the hexahedra stays 5; the three finest give Richardson's
# extrapolation (the elasto-plastic 2.5 mm x 4, 1.667 x 6 and 1.25 x 8: docs/study_notes.md).
SOLID_LEVELS = {"elastic": ((5.0e-3, 2), (2.5e-3, 4), (1.25e-3, 8)),
                "plastic": ((5.0e-3, 2), (2.5e-3, 4), (5.0e-3 / 3, 6), (1.25e-3, 8))}
CONVERGED = 0.01  # the finest solid within this of the extrapolation: converged
SAFETY = 1.25  # Roache's safety factor of the grid convergence index (three levels)
SHELL_LEVELS = (5.0e-3, 2.5e-3, 1.25e-3)  # m, quadrilaterals
QUICK_SOLID, QUICK_SHELL = ((5.0e-3, 2),), (5.0e-3,)
# load -> the solids' [element] (the rows of docs/study_shells_solids.csv name theirs: a
# kept row of another element is run again): one point, the Flanagan-Belytschko stiffness
# hourglass control for the elastic load (its levels converge to 0.13 %), the physical
# (assumed-strain) one for the elasto-plastic load, whose levels converge faster than the
# stiffness form's (docs/study_notes.md)
SOLID_ELEMENT = {"elastic": {"integration": "reduced", "hourglass": "stiffness"},
                 "plastic": {"integration": "reduced", "hourglass": "physical"}}
MASS = 1.0  # kg, the whole sphere's
PEAK_WINDOW = 50e-6  # s, the peak force is the largest mean over this long
SHARE = {"solid": 4, "shell": 1, "thinning_shell": 1}  # the whole plate over the part run
# kind -> its label; a "thinning_shell" is a shell whose thickness follows its membrane
# strain (element.thickness_change, Radioss's Ithick 1), run at these sizes (m) under these
# loads (the solids thin under the sphere: 18 mm of deflection on a 2 mm plate)
MODELS = {"solid": "solid", "shell": "shell", "thinning_shell": "shell, thickness change"}
THINNING = {"plastic": SHELL_LEVELS}

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
    """The scene of ``kind`` "shell" (the whole plate in quadrilaterals of ``h`` m),
    "thinning_shell" (the same, its thickness following its membrane strain) or "solid" (its
    quarter in hexahedra, ``layers`` through the thickness, the mesh file in ``folder``)
    under ``load`` (a key of :data:`LOADS`)."""
    material, speed, end_time = LOADS[load]
    if kind != "solid":  # the whole plate
        mesh = {"shape": "plate", "origin": [-HALF, -HALF, -THICKNESS / 2],
                "size": [2 * HALF, 2 * HALF, THICKNESS], "element_size": h,
                "cell": "quadrilateral"}  # fmt: skip
        boundary = [{"group": side, "components": "xyz", "rotations": "xyz"}
                    for side in ("side_x0", "side_x1", "side_y0", "side_y1")]  # fmt: skip
        element, skin = {"points": 5}, 0.0  # the sphere acts on the mid-surface
        if kind == "thinning_shell":
            element["thickness_change"] = True
    else:
        mesh = {"file": str(_quarter_geo(folder, h, layers))}
        boundary = [
            {"group": "sym_x", "components": "x"},
            {"group": "sym_y", "components": "y"},
            {"group": "rim_x", "components": "xyz"},
            {"group": "rim_y", "components": "xyz"},
        ]
        element, skin = dict(SOLID_ELEMENT[load]), THICKNESS / 2
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
    row = {"load": load, "kind": kind, "element": element_label(raw["element"]),
           "status": s["status"], "element_size": h, "layers": layers,
           "cells": s["cells"], "steps": s["steps"], "dt": s["dt"],
           "wall_seconds": s["wall_seconds"], "cpu_seconds": cpu}  # fmt: skip
    return row | measure(s, sim.history.wall(0), SHARE[kind])


def element_label(element: dict) -> str:
    """An ``[element]`` table as the rows name it: "hourglass=physical integration=reduced"."""
    return " ".join(f"{k}={v}" for k, v in sorted(element.items()))


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
# the committed reference: the solid levels' rows (the finest take an hour each on 1 rank)
REFERENCE = Path(__file__).resolve().parents[2] / "docs" / "study_shells_solids.csv"
_TEXT = ("load", "kind", "element", "status")
_WHOLE = ("layers", "cells", "steps")


def _order(d21: float, d32: float, r21: float, r32: float) -> float:
    """The order p of f(h) = f0 + C h^p whose changes over the size ratios r21 = h1 / h2 and
    r32 = h2 / h3 are d21 and d32: d21 / d32 = r32^p (r21^p - 1) / (r32^p - 1), which is
    r^p for equal ratios; nan when the changes differ in sign or p lies outside [-20, 20]."""
    if d21 * d32 <= 0:
        return math.nan
    if r21 == r32:
        return math.log(d21 / d32) / math.log(r21)

    def excess(p: float) -> float:  # increasing in p; at p = 0 its limit ln r21 / ln r32
        shrink = (r32**p * (r21**p - 1) / (r32**p - 1) if p != 0.0
                  else math.log(r21) / math.log(r32))  # fmt: skip
        return shrink - d21 / d32

    lo, hi = -20.0, 20.0
    if excess(lo) > 0 or excess(hi) < 0:
        return math.nan
    for _ in range(200):  # bisection to round-off
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if excess(mid) < 0 else (lo, mid)
    return 0.5 * (lo + hi)


def richardson(values, sizes=(4.0, 2.0, 1.0)) -> dict:
    """Richardson's extrapolation of a figure from three levels of cell sizes ``sizes``,
    coarse to fine (only their ratios matter; the study's levels halve it): the observed
    order p of f = f0 + C h^p (:func:`_order`; ln(d21 / d32) / ln(r) for a constant ratio r,
    d21 = f2 - f1, d32 = f3 - f2), the extrapolated value f3 + d32 / (r32^p - 1) (r32 =
    h2 / h3), its estimated error the grid convergence index of the finest level, SAFETY
    |d32| / (r32^p - 1), relative to it (Roache 1994), and the finest level's distance from
    it. Not converging monotonically at an order of 0.5 at least (the differences change
    sign, or do not shrink): no extrapolation, the finest level stands, with twice its last
    change as its error and the order nan."""
    f1, f2, f3 = (float(v) for v in values)
    h1, h2, h3 = (float(h) for h in sizes)
    d21, d32, r32 = f2 - f1, f3 - f2, h2 / h3
    order = _order(d21, d32, h1 / h2, r32)
    if not order >= 0.5:  # nan too
        return {"order": order, "value": f3, "error": 2 * abs(d32 / f3), "finest_error": 0.0,
                "extrapolated": False}  # fmt: skip
    value = f3 + d32 / (r32**order - 1)
    return {"order": order, "value": value, "error": SAFETY * abs(d32 / value) / (r32**order - 1),
            "finest_error": abs(f3 / value - 1), "extrapolated": True}  # fmt: skip


def reference(rows: list[dict], load: str) -> dict:
    """The solid reference of ``load``: per figure of :data:`FIGURES` Richardson's
    extrapolation of the three finest solid levels (:func:`richardson`), or the finest solid
    alone (``extrapolated`` False, error nan) with fewer levels."""
    solids = [r for r in rows if r["load"] == load and r["kind"] == "solid"]
    if len(solids) >= 3:
        sizes = [r["element_size"] for r in solids[-3:]]
        return {k: richardson([r[k] for r in solids[-3:]], sizes) for k in FIGURES}
    return {k: {"order": math.nan, "value": solids[-1][k], "error": math.nan,
                "finest_error": math.nan, "extrapolated": False} for k in FIGURES}  # fmt: skip


def _percent(x: float) -> str:
    return "-" if math.isnan(x) else f"{100 * x:.2f} %"


def report(rows: list[dict], seconds: float, cached: str = "") -> str:
    """The markdown section: every run, the solids' extrapolation, and each run's error
    against it; ``cached`` says where the solids' rows came from."""
    lines = ["## Shells against solids: a clamped 2 mm steel plate struck by a sphere", "",
             __doc__.split("\n\n", 1)[1].strip(), ""]  # fmt: skip
    if cached:
        lines += [cached, ""]
    for load in LOADS:
        runs = [r for r in rows if r["load"] == load]
        solids = [r for r in runs if r["kind"] == "solid"]
        if not solids:
            continue
        ref = reference(rows, load)
        material, speed, end = LOADS[load]
        lines += [f"**{load}** ({material['model']} shells, "
                  f"{SOLID_MODEL.get(material['model'], material['model'])} solids "
                  f"({element_label(SOLID_ELEMENT[load])}), "
                  f"{speed:g} m/s, {end * 1e3:g} ms).", ""]  # fmt: skip
        lines += ["| model | h (mm) | layers | cells | steps | loop wall (s) | loop CPU (s) | "
                  + " | ".join(f"{label} ({unit})" for label, _, unit in FIGURES.values())
                  + " | balance |",
                  "|---" * (7 + len(FIGURES) + 1) + "|"]  # fmt: skip
        for r in runs:
            cells = [f"{r[k] * scale:.4g} ({100 * (r[k] / ref[k]['value'] - 1):+.2f} %)"
                     for k, (_, scale, _) in FIGURES.items()]  # fmt: skip
            layers = r["layers"] if r["kind"] == "solid" else "-"
            lines.append(f"| {MODELS[r['kind']]} | {r['element_size'] * 1e3:.3g} | {layers} | "
                         f"{r['cells']:,} | {r['steps']:,} | {r['wall_seconds']:.3g} | "
                         f"{r['cpu_seconds']:.3g} | " + " | ".join(cells)
                         + f" | {r['balance_error']:.1e} |")  # fmt: skip
        lines.append("| **solid reference** | " + " | " * 6 + " | ".join(
            f"**{ref[k]['value'] * scale:.4g}**" for k, (_, scale, _) in FIGURES.items())
            + " | |")  # fmt: skip
        lines += ["", "| solid reference | " + " | ".join(label for label, _, _ in FIGURES.values())
                  + " |", "|---" * (1 + len(FIGURES)) + "|"]  # fmt: skip
        for name, key, fmt in (("observed order", "order", lambda x: "-" if math.isnan(x)
                                else f"{x:.2f}"),
                               ("estimated error (GCI)", "error", _percent),
                               ("finest solid from it", "finest_error", _percent)):  # fmt: skip
            lines.append(f"| {name} | " + " | ".join(fmt(ref[k][key]) for k in FIGURES) + " |")
        if len(solids) > 1:
            lines.append("| finest solid against the level before | " + " | ".join(
                f"{100 * (solids[-1][k] / solids[-2][k] - 1):+.2f} %" for k in FIGURES) + " |")
        lines.append("| converged (finest within 1 %) | " + " | ".join(
            ("yes" if ref[k]["finest_error"] <= CONVERGED else "no")
            if ref[k]["extrapolated"] else "not extrapolated" for k in FIGURES) + " |")
        lines += ["", _saving(runs, solids[-1]), ""]
    lines.append(f"The shell study took {seconds:.0f} s (set-up included) on 1 rank.")
    return "\n".join(lines) + "\n"


def _saving(runs: list[dict], solid: dict) -> str:
    """What each shell level saves: its loop CPU (the whole plate) against the finest
    solid's (a quarter, times SHARE for the whole plate: the cost goes with the cells)."""
    whole = SHARE["solid"] * solid["cpu_seconds"]
    shells = "; ".join(f"the {r['element_size'] * 1e3:.3g} mm shells {r['cpu_seconds']:.3g} s "
                       f"for the whole plate ({whole / r['cpu_seconds']:.0f} times less)"
                       for r in runs if r["kind"] == "shell")  # fmt: skip
    thinning = [r for r in runs if r["kind"] == "thinning_shell"]
    if thinning:
        shells += ("; with their thickness changing, " + ", ".join(
            f"{r['cpu_seconds']:.3g} s at {r['element_size'] * 1e3:.3g} mm" for r in thinning))
    return (f"What the shells save: the finest solid took {solid['cpu_seconds']:.3g} s of loop "
            f"CPU for its quarter, about {whole:.3g} s for the whole plate; {shells}.")


def read_rows(path: Path) -> list[dict]:
    """Rows written by :func:`write_rows` (shells.csv, solids.csv), numbers as numbers."""
    with open(path, newline="") as f:
        return [{k: v if k in _TEXT else int(v) if k in _WHOLE else float(v)
                 for k, v in r.items()} for r in csv.DictReader(f)]  # fmt: skip


def write_rows(path: Path, rows: list[dict]) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w", newline="") as f:
        writer = csv.DictWriter(f, list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)


def _run(plan, out: Path, comm, echo) -> list[dict]:
    """Each (load, kind, h, layers) of ``plan`` run in turn -> their rows."""
    rows = []
    for load, kind, h, layers in plan:
        folder = out / "runs" / f"{load}-{kind}-h{h * 1e3:.3g}mm-{layers}"
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
    return rows


def _solid_plan(loads, quick: bool = False) -> list[tuple]:
    return [(load, "solid", h, n) for load in loads
            for h, n in (QUICK_SOLID if quick else SOLID_LEVELS[load])]  # fmt: skip


def run_solid_reference(out="results/study-shells", *, comm=None, loads=tuple(LOADS),
                        echo=print, keep: Path | None = REFERENCE) -> list[dict]:  # fmt: skip
    """Every solid level of every load (hours on 1 rank: the finest elastic one alone about
    an hour of CPU): writes ``solids.csv`` in ``out`` and, with ``keep``, the committed
    reference the study reads (``python -m rwall_fem.study.shells --solids``)."""
    from mpi4py import MPI

    comm = comm or MPI.COMM_WORLD
    out = Path(out)
    rows = _run(_solid_plan(loads), out, comm, echo)
    if comm.rank == 0:
        write_rows(out / "solids.csv", rows)
        if keep:  # the other loads' rows stay
            others = [r for r in read_rows(keep) if r["load"] not in loads] if keep.exists() else []
            write_rows(keep, sorted(others + rows, key=lambda r: list(LOADS).index(r["load"])))
    return rows


def _cached_solids(loads, comm, out: Path, echo) -> tuple[list[dict], str]:
    """The solid levels from the committed reference (:data:`REFERENCE`), the missing ones
    run; the coarsest of each load run again, to check the reference against this code."""
    kept = read_rows(REFERENCE) if REFERENCE.exists() else []
    kept = comm.bcast(kept if comm.rank == 0 else None, root=0)
    rows, notes = [], []
    for load in loads:
        solid = element_label(SOLID_ELEMENT[load])  # kept rows of another element: run again
        for h, n in SOLID_LEVELS[load]:
            found = [r for r in kept if r["load"] == load and r["element_size"] == h
                     and r["layers"] == n and r["element"] == solid]  # fmt: skip
            rows += found[:1] or _run([(load, "solid", h, n)], out, comm, echo)
        h, n = SOLID_LEVELS[load][0]
        again = _run([(load, "solid", h, n)], out, comm, echo)[0]
        first = next(r for r in rows if r["load"] == load)
        change = max(abs(again[k] / first[k] - 1) for k in FIGURES)
        notes.append(f"{load} {change:.1e}")
    return rows, ("The solid rows are read from docs/study_shells_solids.csv (written by "
                  "`python -m rwall_fem.study.shells --solids`); the coarsest solid of each "
                  "load was run again with this code and its figures moved by at most "
                  + ", ".join(notes) + " from the kept ones.")  # fmt: skip


def run_shell_study(out="results/study-shells", *, quick: bool = False, comm=None,
                    loads=tuple(LOADS), echo=print) -> list[dict]:  # fmt: skip
    """Every load (of ``loads``): the solid levels (read from :data:`REFERENCE`, see
    :func:`_cached_solids`; with ``quick`` the coarsest solid only, run) and the shell
    levels (run); writes ``shells.csv`` and ``shells.md``."""
    from mpi4py import MPI

    comm = comm or MPI.COMM_WORLD
    out = Path(out)
    started = time.perf_counter()
    if quick:
        solids, cached = _run(_solid_plan(loads, quick=True), out, comm, echo), ""
    else:
        solids, cached = _cached_solids(loads, comm, out, echo)
    plan = [(load, "shell", h, 0) for load in loads
            for h in (QUICK_SHELL if quick else SHELL_LEVELS)]  # fmt: skip
    if not quick:
        plan += [(load, "thinning_shell", h, 0) for load in loads for h in THINNING.get(load, ())]
    shells = _run(plan, out, comm, echo)
    rows = [r for load in loads for r in solids + shells if r["load"] == load]
    seconds = comm.allreduce(time.perf_counter() - started, op=MPI.MAX)
    if comm.rank == 0:
        write_rows(out / "shells.csv", rows)
        (out / "shells.md").write_text(report(rows, seconds, cached))
    return rows


if __name__ == "__main__":
    import argparse

    parser = argparse.ArgumentParser(prog="python -m rwall_fem.study.shells", description=(
        "the solid reference of the shell study: every solid level, written to OUT/solids.csv "
        "and docs/study_shells_solids.csv"))  # fmt: skip
    parser.add_argument("--solids", action="store_true", required=True)
    parser.add_argument("--out", default="results/study-shells")
    parser.add_argument("--load", choices=tuple(LOADS), action="append")
    args = parser.parse_args()
    run_solid_reference(args.out, loads=tuple(args.load or LOADS))
