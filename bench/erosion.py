"""Cost of failure and erosion: ``python bench/erosion.py`` -> bench/erosion.md and .json.

One process on one rank, one mesh per cell type (the bar of bench/case.py: 20 x 20 x 200
hexahedra, or 14 x 14 x 140 bricks of 6 tetrahedra), a Johnson-Cook material; every figure
is the median over rounds in which the variants alternate, so that they see the same
machine. Times are the process's CPU time, not wall time: on the 2 cores that two people
share, another job's share of a core does not count.

1. **No failed cell.** The element kernel alone, per cell-step, of the material without a
   failure criterion, with Johnson-Cook's damage (no cell reaches D = 1), and with
   ``run.dt_min_action = "erode"`` (no cell below the floor): in the *elastic* state (a
   strain of 1e-3, tiny increments: no point flows) and in *plastic* flow at every point
   and every call (a uniaxial strain rate of 2e4 /s: the damage grows at every point,
   the upper bound of its cost). With ``--main-tree``, the same kernels compiled from that
   checkout (the code before failure and erosion) beside them. Then whole steps of a scene
   (the bar onto a plane at 100 m/s: plastic flow at the impact face, no cell fails),
   without and with the damage.
2. **As cells erode.** The kernel per live cell-step when 0 to 90 % of the cells have
   eroded: a random choice of cells (the worst case for the batches, whose consecutive
   cells load as vectors) and a block of consecutive cells (a hole, as in a perforation).
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import os
import shutil
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from mpi4py import MPI

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent))
import case  # noqa: E402

from rwall_fem import _compat, build_simulation, parse_scene  # noqa: E402
from rwall_fem.elements import ElementForce, GhostedField, Technology  # noqa: E402
from rwall_fem.meshing import body_mesh  # noqa: E402

comm = MPI.COMM_WORLD
JOHNSON_COOK = {
    "model": "johnson_cook", "density": 7850.0, "young": 200e9, "poisson": 0.33,
    "yield_stress": 490e6, "hardening_coefficient": 807e6, "hardening_exponent": 0.73,
    "strain_rate_coefficient": 0.0114, "reference_strain_rate": 5e-4,
}  # fmt: skip
DAMAGE = {"criterion": "johnson_cook", "d1": 0.0705, "d2": 1.732, "d3": -0.54, "d4": -0.015}
RATES = {"elastic": 1.0, "plastic": 2e4}  # uniaxial strain rates, 1/s
CELLS = {"hexahedron": (20, ["physical", "full"]), "tetrahedron": (14, ["tet"])}
FRACTIONS = (0.0, 0.25, 0.5, 0.75, 0.9)


def material(failure):
    raw = {
        "run": {"end_time": 1e-6},
        "mesh": {"shape": "bar", "size": [0.01] * 3, "element_size": 0.01},
        "material": JOHNSON_COOK | ({"failure": failure} if failure else {}),
    }
    return parse_scene(raw, source="bench").material


def technology(cell, tech):
    options = case.TECHNOLOGIES[tech]
    hourglass = options.get("hourglass", "physical") if cell == "hexahedron" else None
    return Technology.choose(cell, options.get("integration"), hourglass, plastic=True)


def main_kernels(tree: Path):
    """The kernels of the checkout ``tree`` as a module of their own (``main_kernels``),
    compiled into a private cache: ``(ffi, lib)``."""
    folder = Path(tempfile.mkdtemp(prefix="rwall-main-kernels-"))
    shutil.copytree(tree / "rwall_fem" / "kernels", folder / "main_kernels")
    spec = importlib.util.spec_from_file_location(
        "main_kernels", folder / "main_kernels" / "__init__.py"
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    cache = os.environ.get("RWALL_FEM_CACHE")
    os.environ["RWALL_FEM_CACHE"] = str(folder / "cache")
    try:
        return module.load()
    finally:
        if cache is None:
            del os.environ["RWALL_FEM_CACHE"]
        else:
            os.environ["RWALL_FEM_CACHE"] = cache


def main_kernel(force: ElementForce, ffi, lib):
    """``force``'s kernel call as the checkout of :func:`main_kernels` makes it: its own
    parameter struct with the same values, the same arrays."""
    p = ffi.new("element_params *")
    for name, _ in ffi.typeof("element_params").fields:
        value = getattr(force.params, name)
        if name in ("table_strain", "table_stress"):
            getattr(p, name)[0 : len(value)] = list(value)
        elif not name.startswith(("length0", "volume0", "step_factor", "below")):
            setattr(p, name, value)
    lengths, volumes = force.length0, force.volume0
    p.length0 = ffi.cast("double *", lengths.ctypes.data)
    p.volume0 = ffi.cast("double *", volumes.ctypes.data)
    state = np.zeros((force.history.shape[0] - force.points * (force.failure is not None),
                      force.num_cells))  # fmt: skip
    energy, step = np.zeros(4), np.zeros(16)

    def ptr(a, kind="double *"):
        return ffi.cast(kind, a.ctypes.data)

    t = force.technology
    name = f"hex8r_plastic_{t.hourglass}" if t.integration == "reduced" else (
        "tet4_plastic" if t.cell == "tetrahedron" else "hex8_plastic")  # fmt: skip
    kernel = getattr(lib, name)
    arrays = (ptr(force.cells, "int32_t *"), ptr(force.X), ptr(force.u.array), ptr(force.v.array))

    def call():
        p.dt, p.estimate = force.params.dt, 1
        kernel(force.num_cells, *arrays, p, ptr(state), force.num_cells,
               ptr(force.f.array), ptr(energy), ptr(step))  # fmt: skip

    call.state = state
    return call


def no_failed_cell(cell, rounds, main):
    """Kernel ns per cell-step of each variant, in the elastic state and in plastic flow."""
    n, techs = CELLS[cell]
    body = body_mesh(comm, case.scene(cell, n, 1, 1, techs[0]).mesh)
    V = _compat.vector_space(body.msh)
    u, v = GhostedField(V), GhostedField(V)
    X = V.tabulate_dof_coordinates()
    u.array[:, 2] = -1e-3 * X[:, 2]
    forces = {}
    for tech in techs:
        for name, failure in (("no failure", None), ("damage", DAMAGE), ("erode below", None)):
            force = ElementForce(V, material(failure), technology(cell, tech), u, v)
            if name == "erode below":
                force.erode_below(1e-30)  # the erosion machinery on, no cell below it
            force.params.dt, force.params.estimate = case.DT, 1
            forces[(tech, name)] = force
        if main is not None:
            forces[(tech, "before (main)")] = main_kernel(forces[(tech, "no failure")], *main)
    cells = body.num_cells
    repeats = max(3, int(1e6 / cells))
    times = {}
    for _ in range(rounds):
        for regime, rate in RATES.items():
            v.array[:] = 0.0
            v.array[:, 2] = -rate * X[:, 2]
            for key, force in forces.items():
                if isinstance(force, ElementForce):
                    force.history[...] = 0.0
                    kernel = force._kernel
                else:
                    force.state[...] = 0.0
                    kernel = force
                for _ in range(3):
                    kernel()
                seconds = cpu_seconds(kernel, repeats)
                times.setdefault(f"{key[0]}:{key[1]}:{regime}", []).append(seconds / cells * 1e9)
    damage = {
        tech: float(forces[(tech, "damage")].damage.max())
        for tech in techs
        if forces[(tech, "damage")].failure is not None
    }
    return {"cells": cells, "kernel_ns": _medians(times), "damage_reached": damage}


def whole_steps(rounds, steps=300):
    """ms per whole step of the bar onto a plane at 100 m/s (plastic flow at the face, no
    cell fails), without and with Johnson-Cook's damage."""
    case.fixed_step()
    times = {}
    for _ in range(rounds):
        for name, failure in (("no failure", None), ("damage", DAMAGE)):
            raw = {
                "run": {"end_time": steps * case.DT, "dt_scale": 0.5},
                "mesh": {"shape": "bar", "size": [0.01, 0.01, 0.1], "element_size": 1e-3},
                "material": JOHNSON_COOK | ({"failure": failure} if failure else {}),
                "initial": {"velocity": [0.0, 0.0, -100.0]},
                "wall": [{"kind": "plane", "point": [0, 0, 0], "normal_point": [0, 0, 1]}],
                "output": {"frames": 0, "plot": False, "history_interval": 10},
            }
            sim = build_simulation(parse_scene(raw, source="bench"), comm,
                                   f"/tmp/rwall-bench-erosion-{comm.size}")  # fmt: skip
            t0 = time.process_time()
            sim.run()
            seconds = time.process_time() - t0
            s = sim.history.summary
            eroded = s.get("erosion", {}).get("eroded_cells", 0)
            if s["status"] != "done" or eroded:
                raise RuntimeError(f"{name}: {s['status']} {s['reason']}, {eroded} eroded")
            times.setdefault(name, []).append(seconds / (s["steps"] + 1) * 1e3)
    return {"cells": s["cells"], "steps": s["steps"] + 1, "step_ms": _medians(times)}


def as_cells_erode(rounds):
    """Kernel ns per live cell-step (one-point hexahedra, plastic flow) with a fraction of
    the cells eroded, at random or as one block of consecutive cells."""
    n, _ = CELLS["hexahedron"]
    body = body_mesh(comm, case.scene("hexahedron", n, 1, 1, "physical").mesh)
    V = _compat.vector_space(body.msh)
    u, v = GhostedField(V), GhostedField(V)
    X = V.tabulate_dof_coordinates()
    u.array[:, 2] = -1e-3 * X[:, 2]
    v.array[:, 2] = -RATES["plastic"] * X[:, 2]
    force = ElementForce(V, material(DAMAGE), technology("hexahedron", "physical"), u, v)
    force.params.dt, force.params.estimate = case.DT, 1
    cells = force.num_cells
    generator = np.random.default_rng(1)
    patterns = {}
    for fraction in FRACTIONS:
        count = int(fraction * cells)
        patterns[("random", fraction)] = generator.choice(cells, count, replace=False)
        patterns[("block", fraction)] = np.arange(count) + (cells - count) // 2
    times = {}
    for _ in range(rounds):
        for (how, fraction), eroded in patterns.items():
            # What ErodedCells.remove does after a kernel pass, for a chosen set of cells.
            e = force.erosion
            e.alive[:] = True
            e.alive[eroded] = False
            e.live = np.flatnonzero(e.alive).astype(np.int32)
            force.params.live = force.ffi.cast("int32_t *", e.live.ctypes.data)
            force._kernel = force._bind(u.array, v.array, force.f.array, force._energy, force.step)
            force.history[...] = 0.0
            live = len(e.live)
            repeats = max(3, int(1e6 / live))
            seconds = cpu_seconds(force._kernel, repeats)
            times.setdefault(f"{how}:{fraction}", []).append(seconds / live * 1e9)
    return {"cells": cells, "kernel_ns_per_live_cell": _medians(times)}


def cpu_seconds(call, repeats) -> float:
    """CPU time of this process (s) per call of ``repeats`` calls."""
    t0 = time.process_time()
    for _ in range(repeats):
        call()
    return (time.process_time() - t0) / repeats


def _medians(times):
    return {k: statistics.median(v) for k, v in times.items()}


def report(record) -> str:
    load = record["load"]
    lines = [
        "# Cost of failure and erosion",
        "",
        f"`python bench/erosion.py` on {comm.size} rank, commit {record['commit']}; medians "
        f"of {record['rounds']} alternating rounds of the process's CPU time. 1-minute load "
        f"average before / after: {load[0]:.2f} / {load[1]:.2f} (this measurement counts "
        "about 1 itself; the rest is another job on the 2 shared cores, which the CPU times "
        "leave out but whose share of the caches they do not).",
        "",
        "## With no failed cell",
        "",
        "Element kernel alone, ns per cell-step, Johnson-Cook steel: *elastic*, no point flows;"
        " *plastic*, every point flows at every call (the damage grows everywhere: the upper"
        " bound of its cost). *damage*: Johnson-Cook's D1-D5, no cell reaching D = 1; "
        '*erode below*: `run.dt_min_action = "erode"`, no cell below the floor'
        + (
            "; *before (main)*: the same kernel compiled from the code before failure and erosion."
            if record["main"]
            else "."
        ),  # fmt: skip
        "",
        "| cells | technology | state | no failure | damage | x | erode below | x |"
        + (" before (main) | x |" if record["main"] else ""),
        "|---|---|---|---|---|---|---|---|" + ("---|---|" if record["main"] else ""),
    ]
    for cell, part in record["no_failed_cell"].items():
        k = part["kernel_ns"]
        for tech in CELLS[cell][1]:
            for regime in RATES:
                base = k[f"{tech}:no failure:{regime}"]
                row = f"| {part['cells']:,} | {tech} | {regime} | {base:.1f} |"
                for name in ("damage", "erode below"):
                    value = k[f"{tech}:{name}:{regime}"]
                    row += f" {value:.1f} | {value / base:.3f} |"
                if record["main"]:
                    value = k[f"{tech}:before (main):{regime}"]
                    row += f" {value:.1f} | {base / value:.3f} |"
                lines.append(row)
    steps = record["whole_steps"]
    ms = steps["step_ms"]
    lines += [
        "",
        f"Whole steps of the bar onto a plane at 100 m/s ({steps['cells']:,} hexahedra, one "
        f"point, {steps['steps']} steps, plastic flow at the impact face, no cell fails): "
        f"{ms['no failure']:.3f} ms without a failure criterion, {ms['damage']:.3f} ms with "
        f"Johnson-Cook's damage ({ms['damage'] / ms['no failure']:.3f} x).",
        "",
        "## As cells erode",
        "",
        f"One-point hexahedra ({record['as_cells_erode']['cells']:,}), plastic flow, the "
        "kernel's ns per *live* cell-step with a share of the cells eroded: at random (the "
        "worst case: the live cells left share few nodes with the cells computed just "
        "before them, so their nodes' values come from memory rather than the caches) or "
        "as one block of consecutive cells (a hole, as erosion makes them). The kernel "
        "does the same work per live cell in both; eroded cells cost nothing.",
        "",
        "| eroded | random | x | block | x |",
        "|---|---|---|---|---|",
    ]
    k = record["as_cells_erode"]["kernel_ns_per_live_cell"]
    for fraction in FRACTIONS:
        random, block = k[f"random:{fraction}"], k[f"block:{fraction}"]
        first_random, first_block = k["random:0.0"], k["block:0.0"]
        lines.append(
            f"| {fraction:.0%} | {random:.1f} | {random / first_random:.3f} | {block:.1f} | "
            f"{block / first_block:.3f} |"
        )
    return "\n".join(lines) + "\n"


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--rounds", type=int, default=5)
    p.add_argument("--main-tree", type=Path, help="a checkout of the code before erosion")
    p.add_argument("--out", type=Path, default=HERE / "erosion.md")
    a = p.parse_args()
    load_before = os.getloadavg()[0]
    main = main_kernels(a.main_tree) if a.main_tree else None
    record = {
        "rounds": a.rounds,
        "main": bool(main),
        "no_failed_cell": {cell: no_failed_cell(cell, a.rounds, main) for cell in CELLS},
        "whole_steps": whole_steps(a.rounds),
        "as_cells_erode": as_cells_erode(a.rounds),
    }
    record["load"] = (load_before, os.getloadavg()[0])
    from rwall_fem.provenance import git_hash

    record["commit"] = git_hash()
    if comm.rank == 0:
        a.out.with_suffix(".json").write_text(json.dumps(record, indent=1) + "\n")
        a.out.write_text(report(record))
        print(report(record))


if __name__ == "__main__":
    t0 = time.perf_counter()
    main()
    if comm.rank == 0:
        print(f"{time.perf_counter() - t0:.0f} s")
