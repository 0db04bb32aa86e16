"""Running the study: every case x element technology x dt_scale x element size.

Each case is run for every element size (halving), element technology (:data:`TECHNOLOGIES`:
P1 tetrahedra; hexahedra with one point and physical hourglass control, the default; with
2 x 2 x 2 points; with one point and the Flanagan-Belytschko stiffness form) and
``dt_scale`` (0.5, 0.9); the quick study keeps the two defaults (:data:`QUICK`). Every run
records its cells, steps, dt, the wall time of the
time loop (median of repeats for short runs), the ns per cell-step, the signed relative error
of each quantity, the share of the energy the wall dissipated and the energy balance error.
The runs use the communicator given (every rank takes part in every run and takes the same
decisions: run times come from the summary, already reduced over ranks).
"""

from __future__ import annotations

import math
import os
import statistics
import time
from pathlib import Path

from mpi4py import MPI

from rwall_fem.build import build_simulation
from rwall_fem.output import OutputError
from rwall_fem.scene import parse_scene
from rwall_fem.study.cases import CASES, Case
from rwall_fem.study.report import write_outputs

__all__ = ["DT_SCALES", "QUICK", "TECHNOLOGIES", "run_case", "run_study"]

# Element technologies: name -> (cell type, the scene's [element] table).
TECHNOLOGIES = {
    "tet": ("tetrahedron", {}),
    "hex": ("hexahedron", {}),  # one point, physical hourglass control: the default
    "hex_full": ("hexahedron", {"integration": "full"}),
    "hex_fb": ("hexahedron", {"integration": "reduced", "hourglass": "stiffness"}),
}
QUICK = ("tet", "hex")  # the technologies of the quick study
DT_SCALES = (0.5, 0.9)


def run_case(case: Case, h: float, element: str, dt_scale: float, comm, directory: Path, *,
             repeat_below: float, max_repeats: int) -> dict:  # fmt: skip
    """One run (repeated while short) of the technology ``element`` (a key of
    :data:`TECHNOLOGIES`) -> a row of ``study.csv``."""
    cell, table = TECHNOLOGIES[element]
    raw = case.scene(h, cell, dt_scale)
    if table:
        raw["element"] = dict(table)
    scene = parse_scene(raw, source=f"study:{case.name}")
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
        "element": element,
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


def run_study(out="results/study", *, quick: bool = False, comm=MPI.COMM_WORLD,
              cases=None, echo=print) -> list[dict]:  # fmt: skip
    """Run every case x technology x dt_scale x element size; write the outputs into ``out``.

    Returns the rows (the same on every rank).
    """
    out = Path(out)
    cases = [CASES[name] for name in (cases or CASES)]
    repeat_below, max_repeats = (0.3, 2) if quick else (1.0, 3)
    started = time.perf_counter()
    load = [os.getloadavg()[0]]
    rows = []
    for case in cases:
        for element in QUICK if quick else TECHNOLOGIES:
            for dt_scale in DT_SCALES:
                for h in case.quick_levels if quick else case.levels:
                    run_dir = out / "runs" / f"{case.name}-{element}-dt{dt_scale:g}-h{h * 1e3:g}mm"
                    row = run_case(case, h, element, dt_scale, comm, run_dir,
                                   repeat_below=repeat_below, max_repeats=max_repeats)  # fmt: skip
                    rows.append(row)
                    if comm.rank == 0 and echo:
                        errors = " ".join(
                            f"{k}={100 * row[f'error_{k}']:+.3f}%" for k in case.quantities
                        )
                        echo(
                            f"study: {case.name} {element} dt_scale={dt_scale:g} "
                            f"h={h * 1e3:g}mm cells={row['cells']} steps={row['steps']} "
                            f"loop={row['wall_seconds']:.3g}s "
                            f"({row['ns_per_cell_step']:.0f} ns/cell-step) {errors}",
                            flush=True,
                        )
    seconds = comm.allreduce(time.perf_counter() - started, op=MPI.MAX)
    load.append(os.getloadavg()[0])
    error = None
    if comm.rank == 0:
        try:
            write_outputs(rows, cases, out, seconds, load)
        except OSError as err:
            error = f"{err.filename or out}: cannot be written ({err.strerror})"
    error = comm.bcast(error, root=0)  # every rank ends alike
    if error:
        raise OutputError(error)
    return rows
