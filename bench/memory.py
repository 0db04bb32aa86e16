"""Peak memory per cell of a process that builds and runs a body (run by bench/bench.py).

The bar scene of bench/case.py with its real start-up (gmsh, the lumped mass, the element
kernels, the SLEPc stable step) and ``--steps`` steps, history every step. After each
stage the resident set (VmRSS) and its peak so far (VmHWM, the getrusage maximum) are
read from /proc/self/status, so that the stage that sets the peak can be named. With
``--trim``, freed memory is handed back to the system (``malloc_trim``) before each reading,
so that the resident set is the memory still in use. Writes one JSON record (rank 0;
figures summed over ranks).
"""

import argparse
import ctypes
import gc
import json
import resource
import time

import case
from mpi4py import MPI

import rwall_fem.body as body
import rwall_fem.build as build
import rwall_fem.mechanics as mechanics
from rwall_fem import _compat, build_simulation

comm = MPI.COMM_WORLD
stages = []
TRIM = False  # --trim: hand freed memory back to the system after each stage


def status():
    """(resident, peak resident) bytes of this process."""
    values = {}
    with open("/proc/self/status") as f:
        for line in f:
            key, _, rest = line.partition(":")
            if key in ("VmRSS", "VmHWM"):
                values[key] = int(rest.split()[0]) * 1024
    return values["VmRSS"], values["VmHWM"]


def note(stage, seconds=0.0):
    if TRIM:
        gc.collect()
        ctypes.CDLL("libc.so.6").malloc_trim(0)
    rss, peak = status()
    stages.append({"stage": stage, "rss": rss, "peak": peak, "seconds": seconds})


def watched(module, name, stage, before=None):
    inner = getattr(module, name)

    def wrapper(*args, **kwargs):
        if before:
            note(before)
        t0 = time.perf_counter()
        try:
            return inner(*args, **kwargs)
        finally:
            note(stage, time.perf_counter() - t0)

    setattr(module, name, wrapper)


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--cell", default="hexahedron")
    p.add_argument("--n", type=int, default=46)
    p.add_argument("--technology", default="physical")
    p.add_argument("--steps", type=int, default=10)
    p.add_argument("--fixed-step", action="store_true", help="no SLEPc stable step")
    p.add_argument(
        "--trim",
        action="store_true",
        help="malloc_trim after each stage: the resident set is then the live memory",
    )
    p.add_argument("--json", required=True)
    a = p.parse_args()
    global TRIM
    TRIM = a.trim
    note("imports")
    watched(_compat, "model_to_mesh", "meshing: distributed by DOLFINx", "meshing: gmsh model")
    watched(build, "body_mesh", "meshing: gmsh finalized")
    watched(mechanics, "lumped_mass", "space and mass")  # imported by body at its call
    watched(body, "ElementForce", "element force (kernels)")
    watched(build, "critical_time_step", "stable step: SLEPc")
    watched(build, "shortest_edge", "stable step: shortest edge")
    watched(build, "boundary_nodes", "wall: boundary nodes")
    watched(build, "History", "history")
    if a.fixed_step:
        case.fixed_step()
    sc = case.scene(a.cell, a.n, a.steps, 1, a.technology)
    t0 = time.perf_counter()
    sim = build_simulation(sc, comm, f"/tmp/rwall-bench-memory-{comm.size}")
    note("set-up done", time.perf_counter() - t0)
    if not a.fixed_step:
        # The scene's end time assumed dt = DT: run a.steps steps of the real dt.
        sim.end_time = a.steps * sim.state.dt
    t0 = time.perf_counter()
    sim.run()
    note("time loop", time.perf_counter() - t0)
    cells = sim.info["cells"]
    record = {
        "cell": a.cell,
        "n": a.n,
        "technology": sim.info["element"],
        "trim": a.trim,
        "ranks": comm.size,
        "cells": cells,
        "nodes": sim.info["nodes"],
        "steps": sim.history.summary["steps"] + 1,
        "stages": [
            {**s, "rss": comm.allreduce(s["rss"]), "peak": comm.allreduce(s["peak"])}
            for s in stages
        ],
        "peak_rss_bytes": comm.allreduce(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024),
        "dolfinx": _compat.DOLFINX_VERSION,
    }
    if comm.rank == 0:
        with open(a.json, "w") as f:
            json.dump(record, f, indent=1)


if __name__ == "__main__":
    main()
