"""Throughput of one mesh in a fresh process (run by bench/bench.py, maybe under mpirun).

A linear elastic steel bar of n x n x 10 n bricks of 1 mm (hexahedra, or 6 tetrahedra per
brick) moving at 10 m/s onto a fixed plane it touches at t = 0, so the wall acts from the
first step. The mesh is made once; then, in rounds, the variants alternate so that all of
them see the same machine:

- ``baij``: the old code's internal force, the PETSc BAIJ (3 x 3 blocks) product K u of the
  small-strain stiffness (``mechanics.stiffness_form``), kept here as the baseline;
- for each element technology asked for: a fresh simulation on the same mesh runs
  ``--steps`` whole steps (``step``; each history interval asked for), then on its final
  state the compiled element kernel alone (``kernel``: the C call, no Python around it)
  and the internal-force effect (``accelerate``: kernel, ghost scatters and -f/m).

Each figure is the median over rounds of the slowest rank's time. Writes one JSON record
(rank 0).
"""

import argparse
import functools
import json
import resource
import statistics
import time

from mpi4py import MPI

import rwall_fem.build as build
from rwall_fem import _compat, build_simulation, parse_scene
from rwall_fem.mechanics import stiffness_form
from rwall_fem.meshing import body_mesh

comm = MPI.COMM_WORLD
H = 1e-3  # brick edge, m
# Throughput only: a fixed step safely below the stable one of either cell type (the
# eigenvalue solve is measured with the start-up), 0.3 h / c_p. The stable step is said
# to be twice that, so that the stable-step monitors of the nonlinear materials let it be.
DT = 5.0e-8
TECHNOLOGIES = {
    "tet": {},
    "full": {"integration": "full"},
    "physical": {"integration": "reduced", "hourglass": "physical"},
    "stiffness": {"integration": "reduced", "hourglass": "stiffness"},
    "viscous": {"integration": "reduced", "hourglass": "viscous"},
    "none": {"integration": "reduced", "hourglass": "none"},
}


def scene(cell, n, steps, history_interval, technology="physical", material=None):
    raw = {
        "run": {"end_time": steps * DT, "dt_scale": 0.5},
        "mesh": {
            "shape": "bar",
            "size": [n * H, n * H, 10 * n * H],
            "element_size": H,
            "cell": cell,
        },
        "material": material
        or {"model": "linear_elastic", "density": 7850.0, "young": 210e9, "poisson": 0.3},
        "initial": {"velocity": [0.0, 0.0, -10.0]},
        "wall": [{"kind": "plane", "point": [0, 0, 0], "normal_point": [0, 0, 1]}],
        "output": {"frames": 0, "plot": False, "history_interval": history_interval},
    }
    if cell == "hexahedron":
        raw["element"] = TECHNOLOGIES[technology]
    return parse_scene(raw, source="bench")


def fixed_step():
    """Replace the stable-step eigenvalue solve (minutes at a million hexahedra): 2 DT."""
    build.critical_time_step = lambda *args, **kwargs: 2 * DT


def slowest(seconds):
    return comm.allreduce(seconds, op=MPI.MAX)


def block(call, repeats):
    """Time per call (s) of ``repeats`` calls, all ranks in step, the slowest rank's."""
    comm.Barrier()
    t0 = time.perf_counter()
    for _ in range(repeats):
        call()
    return slowest((time.perf_counter() - t0) / repeats)


def peak_rss():
    """Sum over ranks of the peak resident set (bytes)."""
    return comm.allreduce(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024)


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--cell", default="hexahedron")
    p.add_argument("--n", type=int, default=10)
    p.add_argument("--technologies", default="physical,full")
    p.add_argument("--steps", type=int, default=100)
    p.add_argument("--intervals", default="1", help="history intervals of the whole steps")
    p.add_argument("--rounds", type=int, default=5)
    p.add_argument("--no-baseline", action="store_true")
    p.add_argument("--json", required=True)
    a = p.parse_args()
    fixed_step()
    technologies = ["tet"] if a.cell == "tetrahedron" else a.technologies.split(",")
    intervals = [int(i) for i in a.intervals.split(",")]

    t0 = time.perf_counter()
    first = scene(a.cell, a.n, a.steps, intervals[0], technologies[0])
    body = body_mesh(comm, first.mesh)
    mesh_seconds = slowest(time.perf_counter() - t0)
    out = f"/tmp/rwall-bench-{a.cell}-{a.n}-{comm.size}"
    cells = body.num_cells

    K = x = y = None
    if not a.no_baseline:
        sim = build_simulation(first, comm, out, body=body)
        t0 = time.perf_counter()
        K = _compat.assemble_matrix(stiffness_form(sim.internal.V, first.material), "baij")
        assembly_seconds = slowest(time.perf_counter() - t0)
        x, y = K.createVecRight(), K.createVecLeft()
        x.setRandom()
        info = K.getInfo(K.InfoType.GLOBAL_SUM)
        del sim
    # Calls per timed block: about 0.3 s of the slowest variant.
    repeats = max(3, int(3e6 / cells))

    times = {"baij": []}
    for tech in technologies:
        times |= {f"{tech}:kernel": [], f"{tech}:accelerate": []}
        times |= {f"{tech}:step/{every}": [] for every in intervals}
    summary = {}
    for _ in range(a.rounds):
        if K is not None:
            times["baij"].append(block(lambda: K.mult(x, y), repeats))
        for tech in technologies:
            for every in intervals:
                sim = build_simulation(
                    scene(a.cell, a.n, a.steps, every, tech), comm, out, body=body
                )
                sim.run()
                s = sim.history.summary
                times[f"{tech}:step/{every}"].append(s["wall_seconds"] / (s["steps"] + 1))
            force, state = sim.internal, sim.state
            times[f"{tech}:kernel"].append(block(force.elements[0]._kernel, repeats))
            accelerate = functools.partial(force.accelerate, state)
            times[f"{tech}:accelerate"].append(block(accelerate, repeats))
            summary[tech] = {
                "element": s["element"],
                "steps": s["steps"] + 1,
                "status": s["status"],
                "balance_error": s["energy"]["max_balance_error"],
            }
    record = {
        "cell": a.cell,
        "n": a.n,
        "ranks": comm.size,
        "cells": cells,
        "rounds": a.rounds,
        "repeats": repeats,
        "mesh_seconds": mesh_seconds,
        "technologies": summary,
        "seconds": {k: statistics.median(v) for k, v in times.items() if v},
        "all_seconds": {k: v for k, v in times.items() if v},
        "peak_rss_bytes": peak_rss(),
    }
    if K is not None:
        record |= {
            "nnz": info["nz_used"],
            "rows": K.getSize()[0],
            "assembly_seconds": assembly_seconds,
        }
    if comm.rank == 0:
        with open(a.json, "w") as f:
            json.dump(record, f, indent=1)


if __name__ == "__main__":
    main()
