"""One benchmark measurement in a fresh process (run by bench/bench.py, maybe under mpirun).

A linear elastic steel bar of n x n x 10 n bricks of 1 mm (hexahedra, or 6 tetrahedra per
brick) moving at 10 m/s onto a fixed plane it touches at t = 0, so the wall acts from the
first step. Writes one JSON record (rank 0) with sizes, start-up, loop and K u timings,
peak memory, and optionally a cProfile of the time loop and side experiments.
"""

import time

STARTED = time.perf_counter()

import argparse  # noqa: E402
import cProfile  # noqa: E402
import json  # noqa: E402
import pstats  # noqa: E402
import resource  # noqa: E402
import statistics  # noqa: E402

import numpy as np  # noqa: E402
from mpi4py import MPI  # noqa: E402
from petsc4py import PETSc  # noqa: E402

import rwall_fem.build as build  # noqa: E402
from rwall_fem import build_simulation, parse_scene  # noqa: E402

comm = MPI.COMM_WORLD


def scene(cell, n, steps_hint, history_interval, secondary=None, wall=True):
    h = 1e-3
    raw = {
        "run": {"end_time": 1.0, "dt_scale": 1.0},
        "mesh": {
            "shape": "bar",
            "size": [n * h, n * h, 10 * n * h],
            "element_size": h,
            "cell": cell,
        },
        "material": {"model": "linear_elastic", "density": 7850.0, "young": 210e9, "poisson": 0.3},
        "initial": {"velocity": [0.0, 0.0, -10.0]},
        "wall": [{"kind": "plane", "point": [0, 0, 0], "normal_point": [0, 0, 1]}],
        "output": {"frames": 0, "plot": False, "history_interval": history_interval},
    }
    if secondary:
        raw["wall"][0]["secondary"] = secondary
    if not wall:
        del raw["wall"]
    return raw


class StopProfile:
    """Recorder that stops the profiler at the last step, before the recorders close."""

    def __init__(self, profiler, last):
        self.profiler, self.last = profiler, last

    def due(self, step):
        return step == self.last

    def record(self, sim, s):
        self.profiler.disable()

    def close(self, sim):
        pass


class FirstStep:
    """Recorder that notes the time when step 1 starts (the first step is done)."""

    def __init__(self):
        self.at = None

    def due(self, step):
        return step == 1

    def record(self, sim, s):
        self.at = time.perf_counter()

    def close(self, sim):
        pass


def timed(name, table):
    """Wrap build.<name> to add its duration to table[name] (start-up breakdown)."""
    inner = getattr(build, name)

    def wrapper(*args, **kwargs):
        t0 = time.perf_counter()
        try:
            return inner(*args, **kwargs)
        finally:
            table[name] = table.get(name, 0.0) + time.perf_counter() - t0

    setattr(build, name, wrapper)


def mult_seconds(K, x, y, repeats):
    """Median over blocks of the time of one K x (all ranks in step, slowest rank)."""
    blocks = []
    per_block = max(1, repeats // 5)
    for _ in range(5):
        comm.Barrier()
        t0 = time.perf_counter()
        for _ in range(per_block):
            K.mult(x, y)
        blocks.append(comm.allreduce((time.perf_counter() - t0) / per_block, op=MPI.MAX))
    return statistics.median(blocks)


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--cell", default="tetrahedron")
    p.add_argument("--n", type=int, default=6)
    p.add_argument("--steps", type=int, default=200)
    p.add_argument("--history-interval", type=int, default=100)
    p.add_argument("--real-dt", action="store_true", help="SLEPc stable step (default: h/c)")
    p.add_argument("--no-wall", action="store_true", help="the bar in free flight")
    p.add_argument("--profile", action="store_true")
    p.add_argument("--extras", action="store_true", help="side experiments (10k cells)")
    p.add_argument("--json", required=True)
    a = p.parse_args()

    setup = {}
    for name in ("body_mesh", "lumped_mass", "stiffness_matrix", "critical_time_step"):
        timed(name, setup)
    if not a.real_dt:
        # Throughput only: a safe step from the element size instead of the eigenvalue
        # solve (which takes minutes on large hexahedral meshes; its cost is measured
        # with --real-dt at 10k cells).
        build.critical_time_step = lambda K, mass, X: 0.3e-3 / 6000.0
    raw = scene(a.cell, a.n, a.steps, a.history_interval, wall=not a.no_wall)
    sc = parse_scene(raw, source="bench")
    t_build = time.perf_counter()
    # A fixed number of steps is timed, whatever end_time: no size limits.
    sim = build_simulation(sc, comm, f"/tmp/rwall-bench-{a.cell}-{a.n}-{comm.size}", limits=False)
    build_seconds = time.perf_counter() - t_build
    # Exactly a.steps + 1 steps (the loop runs steps 0..num_steps).
    sim.end_time = a.steps * sim.state.dt
    first = FirstStep()
    sim.recorders.append(first)
    profiler = cProfile.Profile() if a.profile else None
    if profiler:
        sim.recorders.append(StopProfile(profiler, sim.num_steps))
        profiler.enable()
    sim.run()
    s = sim.history.summary
    K = sim.internal.K
    info = K.getInfo(K.InfoType.GLOBAL_SUM)
    x, y = K.createVecRight(), K.createVecLeft()
    x.setRandom()
    mult = mult_seconds(K, x, y, max(10, min(500, int(3e7 / max(info["nz_used"], 1)))))
    record = {
        "cell": a.cell,
        "n": a.n,
        "ranks": comm.size,
        "cells": s["cells"],
        "nodes": s["nodes"],
        "rows": K.getSize()[0],
        "nnz": info["nz_used"],
        "mat_type": K.getType(),
        "steps": s["steps"] + 1,
        "status": s["status"],
        "history_interval": a.history_interval,
        "wall": not a.no_wall,
        "loop_seconds": s["wall_seconds"],
        "step_seconds": s["wall_seconds"] / (s["steps"] + 1),
        "mult_seconds": mult,
        "build_seconds": comm.allreduce(build_seconds, op=MPI.MAX),
        "setup": {k: comm.allreduce(v, op=MPI.MAX) for k, v in setup.items()},
        "first_step_seconds": comm.allreduce(first.at - STARTED, op=MPI.MAX),
        "peak_rss_bytes": comm.allreduce(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss) * 1024,
        "peak_rss_rank0_bytes": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024,
        "real_dt": a.real_dt,
    }
    if a.profile and comm.rank == 0:
        stats = pstats.Stats(profiler)
        rows = []
        for (file, line, func), (_, nc, tt, ct, _) in stats.stats.items():
            rows.append(
                {
                    "function": f"{file.split('/')[-1]}:{line}({func})",
                    "calls": nc,
                    "tottime": tt,
                    "cumtime": ct,
                }
            )
        record["profile"] = sorted(rows, key=lambda r: -r["tottime"])[:18]
    if a.extras:
        record["extras"] = extras(sim, K, x, y, a)
    if comm.rank == 0:
        with open(a.json, "w") as f:
            json.dump(record, f, indent=1)


def extras(sim, K, x, y, a):
    """Side experiments for the optimisation proposals, on the same mesh."""
    out = {}
    # Matrix formats, alternating so that both see the same machine: the solver's BAIJ K
    # (one column index per 3 x 3 block) and an AIJ copy (one per entry, DOLFINx's own).
    A = K.convert("aij", PETSc.Mat())  # a copy: without `out`, convert works in place
    times = {"baij": [], "aij": []}
    for _ in range(5):
        times["baij"].append(mult_seconds(K, x, y, 40))
        times["aij"].append(mult_seconds(A, x, y, 40))
    out["mult_baij_seconds"] = statistics.median(times["baij"])
    out["mult_aij_seconds"] = statistics.median(times["aij"])
    A.destroy()
    # Acceleration from K u: two passes (multiply, negate) against one with -1/m.
    s, ku = sim.state, sim.internal.ku
    neg = -s.inv_mass

    def best(f, n=200):
        ts = []
        for _ in range(n):
            t0 = time.perf_counter()
            f()
            ts.append(time.perf_counter() - t0)
        return statistics.median(ts)

    def two_passes():
        np.multiply(ku, s.inv_mass, out=s.a)
        np.negative(s.a, out=s.a)

    out["accel_two_pass_seconds"] = best(two_passes)
    out["accel_one_pass_seconds"] = best(lambda: np.multiply(ku, neg, out=s.a))
    scratch = np.empty_like(s.u)

    def update_now():
        np.multiply(s.a, s.dt, out=scratch)
        s.v += scratch
        np.multiply(s.v, s.dt, out=scratch)
        s.u += scratch

    out["update_seconds"] = best(update_now)
    # The wall alone: all boundary nodes (the default) against the bottom face only.
    wall = sim.walls[0]
    out["wall_nodes_default"] = comm.allreduce(len(wall.nodes))
    out["wall_seconds_default"] = best(lambda: wall.constrain(s), 100)
    out["wall_contacts"] = comm.allreduce(wall.contacts)
    # Whole loop with the wall on the bottom face only, and with history every step: the
    # median of 3 runs of each, the variants alternating so that all see the same machine.
    variants = {
        "every_100": (None, 100),
        "bottom_only": ({"add": ["bottom"]}, 100),
        "history_every_step": (None, 1),
    }
    steps = {label: [] for label in variants}
    for _ in range(3):
        for label, (secondary, every) in variants.items():
            sc = parse_scene(scene(a.cell, a.n, a.steps, every, secondary), source="bench")
            other = build_simulation(
                sc, comm, f"/tmp/rwall-bench-x-{a.cell}-{comm.size}", limits=False
            )
            other.end_time = a.steps * other.state.dt
            other.run()
            steps[label].append(other.history.summary["wall_seconds"] / (a.steps + 1))
            if label == "bottom_only":
                out["wall_nodes_bottom"] = comm.allreduce(len(other.walls[0].nodes))
    for label, times in steps.items():
        out[f"step_seconds_{label}"] = statistics.median(times)
    # Stable step: SLEPc as the solver does it (tol 1e-8), against a looser tolerance.
    from rwall_fem.mechanics import critical_time_step as exact_step

    t0 = time.perf_counter()
    dt8 = exact_step(K, s.mass, s.X)
    out["eigen_seconds_tol_1e-8"] = comm.allreduce(time.perf_counter() - t0, op=MPI.MAX)
    out["dt_stable"] = dt8
    return out


if __name__ == "__main__":
    main()
