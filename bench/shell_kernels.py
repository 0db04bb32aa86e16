"""ns per element-step of the shell kernels against the one-point J2 hexahedron kernel.

    python bench/shell_kernels.py [--out bench/shell_kernels.md] [cells ...]
    mpirun -n 2 python bench/shell_kernels.py [--out ...] [cells ...]

Each kernel runs over a structured grid of the given number of cells (default 10,000 and
100,000; on N ranks each rank runs its own grid of 1/N of them, all ranks at once, as a
partitioned mesh would) with small random velocities, as in a step of a run. The J2 cases
(power-law hardening) flow plastically at every point once the first steps have brought
the stresses to the yield surface (a steady plastic flow, increments of about 4e-5 per
step), hexahedra alike; "below yield" is the same law with its yield stress out of reach
(the elastic checks only); "elastic" the linear elastic law (resultants, no points).
The QEPH rows are the quadrilateral as a deck's Ishell 24 reads it (formulation "qeph": its
physical hourglass stiffness with yield and viscosity, its step length), same laws.

Times are each rank's processor time (not wall time: the machine is shared), per element-
step of that rank's cells; every figure is the median over rounds in which the kernels
alternate, so that they see the same machine, and the ratio of the 5-point J2
quadrilateral to the one-point J2 hexahedron is taken in each round (median given). The
load average is printed before and after; with --out the table is written as Markdown
(bench/shell_kernels.md, included in docs/performance.md), for 1 rank and, appended by a
run on 2 ranks, for 2.
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import time
from pathlib import Path
from types import SimpleNamespace

import numpy as np

from rwall_fem.kernels import STEP_SLOTS, load
from rwall_fem.shells.elements import ShellKernel, ShellTechnology

E, NU, RHO = 210e9, 0.3, 7850.0
J2 = dict(model="elastic_plastic", plastic=True, young=E, poisson=NU, density=RHO,
          hardening="power", yield_stress=300e6, hardening_coefficient=500e6,
          hardening_exponent=0.3, strain_rate_coefficient=0.0, reference_strain_rate=1.0,
          failure=None, heating=None)  # fmt: skip


WARM_UP = 80  # steps of the same increments: the stresses reach the yield surface and flow
ROUNDS = 7  # of the alternating kernels
CALLS = 3  # kernel calls per kernel and round


def timed(call):
    """Processor time (s) of CALLS calls, per call."""
    start = time.process_time()
    for _ in range(CALLS):
        call()
    return (time.process_time() - start) / CALLS


# QEPH (Radioss's Ishell 24, as a deck's /PROP/SHELL reads it): its physical hourglass
# stiffness with yield and viscosity, its step length
QEPH = dict(formulation="qeph", hourglass=(0.0, 0.0, 0.0), step_length="qeph",
            hourglass_yield=True)


def shell_case(cells_wanted: int, plastic: bool, points: int = 5, yield_stress=300e6,
               cell="quadrilateral", technology=None):
    n = int(round(math.sqrt(cells_wanted / (2 if cell == "triangle" else 1))))
    h = 2.5e-3
    s = np.arange(n + 1) * h
    X = np.array([[x, y, 0.0] for y in s for x in s])
    row = n + 1
    cells = np.array([[j * row + i, j * row + i + 1, (j + 1) * row + i + 1, (j + 1) * row + i]
                      for j in range(n) for i in range(n)], np.int32)  # fmt: skip
    if cell == "triangle":  # each square halved
        cells = np.ascontiguousarray(np.concatenate([cells[:, [0, 1, 2]], cells[:, [0, 2, 3]]]))
    rng = np.random.default_rng(0)
    if plastic:
        material = SimpleNamespace(**(J2 | {"yield_stress": yield_stress}))
    else:
        material = SimpleNamespace(model="linear_elastic", plastic=False, young=E, poisson=NU,
                                   density=RHO)  # fmt: skip
    k = ShellKernel(material, ShellTechnology.choose(cell, points=points, **(technology or {})),
                    cells, 1e-3)
    u = rng.normal(size=X.shape) * 1e-6
    v, w = rng.normal(size=X.shape), rng.normal(size=X.shape) * 100
    f, m = np.zeros_like(X), np.zeros_like(X)
    energy, step = np.zeros(4), np.zeros(STEP_SLOTS)
    k.params.dt, k.params.estimate = 1e-7, 1
    call = k.bind(len(cells), X, u, v, w, f, m, energy, step)
    for _ in range(WARM_UP):
        call()
    flowing = np.mean(k.plastic_strains() > 0) if plastic and yield_stress < 1e9 else None
    return len(cells), call, flowing


def hex_case(cells_wanted: int):
    ffi, lib = load()
    n = int(round(cells_wanted ** (1 / 3)))
    h = 2.5e-3
    s = np.arange(n + 1) * h
    X = np.array([[x, y, z] for z in s for y in s for x in s])
    N = n + 1
    cells = []
    for k in range(n):
        for j in range(n):
            for i in range(n):
                base = [(k + c) * N * N + (j + b) * N + (i + a)
                        for c in (0, 1) for b in (0, 1) for a in (0, 1)]  # fmt: skip
                cells.append(base)
    cells = np.array(cells, np.int32)
    rng = np.random.default_rng(0)
    u, v = rng.normal(size=X.shape) * 1e-6, rng.normal(size=X.shape)
    f, energy, step = np.zeros_like(X), np.zeros(4), np.zeros(STEP_SLOTS)
    p = ffi.new("element_params *")
    p.lmbda, p.mu = E * NU / ((1 + NU) * (1 - 2 * NU)), E / (2 * (1 + NU))
    p.density, p.wave_speed = RHO, math.sqrt((p.lmbda + 2 * p.mu) / RHO)
    p.hourglass_coefficient, p.calibration, p.dt, p.estimate = 0.1, 1.0, 1e-7, 1
    p.hardening, p.yield_stress = 1, 300e6
    p.hardening_coefficient, p.hardening_exponent = 500e6, 0.3
    volume0 = np.full(len(cells), h**3)
    p.volume0 = ffi.cast("double *", volume0.ctypes.data)
    state = np.zeros((8 + 12, len(cells)))

    def ptr(a, kind="double *"):
        return ffi.cast(kind, a.ctypes.data)

    def call():
        lib.hex8r_plastic_viscous(len(cells), ptr(cells, "int32_t *"), ptr(X), ptr(u), ptr(v),
                                  p, ptr(state), len(cells), ptr(f), ptr(energy),
                                  ptr(step))  # fmt: skip

    for _ in range(WARM_UP):
        call()
    call.keep = volume0, state  # the kernel reads them through pointers
    return len(cells), call, np.mean(state[6] > 0)


CASES = (
    ("quadrilateral, elastic", lambda n: shell_case(n, False)),
    ("quadrilateral, J2, 5 points", lambda n: shell_case(n, True)),
    ("quadrilateral, J2, 3 points", lambda n: shell_case(n, True, 3)),
    ("quadrilateral, J2, 5 points, below yield", lambda n: shell_case(n, True, 5, 1e12)),
    ("triangle, elastic", lambda n: shell_case(n, False, cell="triangle")),
    ("triangle, J2, 5 points", lambda n: shell_case(n, True, cell="triangle")),
    ("quadrilateral QEPH (Ishell 24), J2, 5 points",
     lambda n: shell_case(n, True, technology=QEPH)),
    ("quadrilateral QEPH (Ishell 24), J2, 5 points, below yield",
     lambda n: shell_case(n, True, 5, 1e12, technology=QEPH)),
    ("hexahedron, one point, J2 (viscous)", hex_case),
)
QUAD_J2, HEX_J2 = 1, len(CASES) - 1


def load_average() -> str:
    return " ".join(f"{x:.1f}" for x in os.getloadavg())


def measure(size: int, comm) -> tuple[list, list, list]:
    """Per case: cells (all ranks), median ns per element-step over rounds (the largest of
    the ranks' in each round), share of points flowing; and the ratio's median."""
    ranks = comm.size
    built = [case(size // ranks) for _, case in CASES]
    per_round = [[] for _ in CASES]
    ratios = []
    for _ in range(ROUNDS):
        row = []
        for i, (cells, call, _flowing) in enumerate(built):
            comm.Barrier()
            ns = comm.allreduce(timed(call) / cells * 1e9, op=max_op())
            per_round[i].append(ns)
            row.append(ns)
        ratios.append(row[QUAD_J2] / row[HEX_J2])
    cells = [comm.allreduce(c) for c, _, _ in built]
    flowing = [f for _, _, f in built]
    return cells, [statistics.median(t) for t in per_round], flowing, statistics.median(ratios)


def max_op():
    from mpi4py import MPI

    return MPI.MAX


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("cells", nargs="*", type=int, default=[10_000, 100_000])
    parser.add_argument("--out", type=Path, help="write (1 rank) or append (N ranks) Markdown")
    args = parser.parse_args()
    from mpi4py import MPI

    comm = MPI.COMM_WORLD
    before = load_average()
    results = {size: measure(size, comm) for size in args.cells}
    after = load_average()
    if comm.rank:
        return
    sizes = list(args.cells)
    lines = [f"### {comm.size} rank{'s' if comm.size > 1 else ''}", "",
             f"Load average (1, 5, 15 min) before {before}, after {after}; medians of "
             f"{ROUNDS} alternating rounds of {CALLS} calls, processor time"
             + (", each rank its share of the cells at once" if comm.size > 1 else "") + ".",
             "", "| kernel | " + " | ".join(f"ns/element-step, {n:,} cells" for n in sizes)
             + " |", "|---|" + "---:|" * len(sizes)]  # fmt: skip
    for i, (name, _) in enumerate(CASES):
        cells = [f"{results[n][1][i]:.0f}" for n in sizes]
        lines.append(f"| {name} | " + " | ".join(cells) + " |")
    lines.append("| **J2 5-point quadrilateral / J2 hexahedron** | "
                 + " | ".join(f"**{results[n][3]:.2f}**" for n in sizes) + " |")  # fmt: skip
    flowing = ", ".join(f"{results[n][2][QUAD_J2]:.0%} of the quadrilaterals' points and "
                        f"{results[n][2][HEX_J2]:.0%} of the hexahedra flowing at {n:,}"
                        for n in sizes)  # fmt: skip
    lines += ["", f"({flowing}; cells: " + ", ".join(
        f"{results[n][0][QUAD_J2]:,} quadrilaterals, {results[n][0][4]:,} triangles, "
        f"{results[n][0][HEX_J2]:,} hexahedra" for n in sizes) + ".)", ""]  # fmt: skip
    text = "\n".join(lines)
    print(text)
    if args.out:
        if comm.size == 1:
            title = ("## Shell kernels\n\n`python bench/shell_kernels.py --out "
                     "bench/shell_kernels.md` then `mpirun -n 2 python bench/shell_kernels.py "
                     "--out bench/shell_kernels.md`: ns per element-step of each kernel "
                     "(the docstring says how).\n\n")  # fmt: skip
            args.out.write_text(title + text)
        else:
            with args.out.open("a") as out:
                out.write("\n" + text)


if __name__ == "__main__":
    main()
