"""Cost of the corner test of one-point hexahedra (issue 28): ``python bench/corners.py
--before-tree DIR`` -> bench/corners.md and .json.

The one-point hexahedron's kernel tests the Jacobian at its eight corners every step
(``kernels/step.h``, ``hex8_corners_inverted``: about 200 flops per cell, vectorised over
the batch). This times the elasto-plastic kernel (Johnson-Cook steel, physical
hourglass control; the bar of bench/case.py, 20 x 20 x 200 cells) per cell-step with it
and compiled from a checkout before it (``--before-tree``: commit 864d876 or older), in
the elastic state and in plastic flow at every point, as bench/erosion.py does (medians
of alternating rounds of the process's CPU time, one rank).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent))
import case  # noqa: E402
from erosion import (  # noqa: E402
    RATES,
    _medians,
    comm,
    cpu_seconds,
    main_kernel,
    main_kernels,
    material,
    technology,
)

from rwall_fem import _compat  # noqa: E402
from rwall_fem.elements import ElementForce, GhostedField  # noqa: E402
from rwall_fem.meshing import body_mesh  # noqa: E402


def measure(before: Path, rounds: int) -> dict:
    body = body_mesh(comm, case.scene("hexahedron", 20, 1, 1, "physical").mesh)
    V = _compat.vector_space(body.msh)
    u, v = GhostedField(V), GhostedField(V)
    X = V.tabulate_dof_coordinates()
    u.array[:, 2] = -1e-3 * X[:, 2]
    force = ElementForce(V, material(None), technology("hexahedron", "physical"), u, v)
    force.params.dt, force.params.estimate = case.DT, 1
    old = main_kernel(force, *main_kernels(before))
    cells, repeats = force.num_cells, max(3, int(1e6 / force.num_cells))
    times: dict[str, list[float]] = {}
    for _ in range(rounds):
        for regime, rate in RATES.items():
            v.array[:] = 0.0
            v.array[:, 2] = -rate * X[:, 2]
            for name, kernel in (("corners", force._kernel), ("before", old)):
                if name == "corners":
                    force.history[...] = 0.0
                else:
                    old.state[...] = 0.0
                for _ in range(3):
                    kernel()
                ns = cpu_seconds(kernel, repeats) / cells * 1e9
                times.setdefault(f"{regime}:{name}", []).append(ns)
    return {"cells": cells, "kernel_ns": _medians(times)}


def report(record: dict) -> str:
    k = record["kernel_ns"]
    lines = [
        "# Cost of the corner test of one-point hexahedra",
        "",
        f"`python bench/corners.py --before-tree {record['before']}` on 1 rank, commit "
        f"{record['commit']}; medians of {record['rounds']} alternating rounds of the "
        f"process's CPU time; 1-minute load average before / after: {record['load'][0]:.2f}"
        f" / {record['load'][1]:.2f} (2 cores shared with other jobs).",
        "",
        f"Elasto-plastic kernel (Johnson-Cook, physical hourglass control), {record['cells']:,}"
        " cells, ns per cell-step:",
        "",
        "| state | with the corner test | before it | difference | x |",
        "|---|---|---|---|---|",
    ]
    for regime in RATES:
        new, old = k[f"{regime}:corners"], k[f"{regime}:before"]
        lines.append(f"| {regime} | {new:.1f} | {old:.1f} | {new - old:+.1f} | {new / old:.3f} |")
    return "\n".join(lines) + "\n"


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--before-tree", type=Path, required=True,
                   help="a checkout of rwall_fem before the corner test (864d876)")
    p.add_argument("--rounds", type=int, default=7)
    args = p.parse_args()
    load = [os.getloadavg()[0]]
    record = measure(args.before_tree, args.rounds)
    load.append(os.getloadavg()[0])
    commit = subprocess.run(["git", "-C", str(HERE), "rev-parse", "HEAD"], capture_output=True,
                            text=True).stdout.strip()  # fmt: skip
    record |= {"before": str(args.before_tree), "commit": commit, "rounds": args.rounds,
               "load": load}  # fmt: skip
    (HERE / "corners.json").write_text(json.dumps(record, indent=2) + "\n")
    (HERE / "corners.md").write_text(report(record))
    print(report(record))


if __name__ == "__main__":
    np.seterr(all="ignore")
    main()
