"""Where a step goes: the phases of the time loop timed one by one (run by bench/bench.py).

The bar scene of bench/case.py at 10k cells, default technology, history every step:
each phase the loop calls (the internal force, with its compiled kernel timed apart;
each wall; the update pass; the history sample) is wrapped by a timer, and what is left
of the step is the loop itself (recorders' ``due``, the Python around the calls). The
timers add well under a microsecond per call. Then a run under cProfile names the Python
functions that take the time outside the kernel (its own overhead inflates them). Writes
one JSON record of seconds per step.
"""

import argparse
import cProfile
import functools
import json
import pstats
import time

import case
from mpi4py import MPI

from rwall_fem import build_simulation


def timer(table, name, call):
    @functools.wraps(call)
    def timed(*args, **kwargs):
        t0 = time.perf_counter()
        try:
            return call(*args, **kwargs)
        finally:
            table[name] = table.get(name, 0.0) + time.perf_counter() - t0

    return timed


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--cell", default="hexahedron")
    p.add_argument("--n", type=int, default=10)
    p.add_argument("--technology", default="physical")
    p.add_argument("--steps", type=int, default=1500)
    p.add_argument("--json", required=True)
    a = p.parse_args()
    case.fixed_step()
    comm = MPI.COMM_WORLD
    sc = case.scene(a.cell, a.n, a.steps, 1, a.technology)
    best = None
    for _ in range(3):
        sim = build_simulation(sc, comm, f"/tmp/rwall-bench-anatomy-{comm.size}")
        table = {}
        force = sim.internal
        for element in force.elements:  # the parts' element forces
            element._kernel = timer(table, "kernel", element._kernel)
        force.accelerate = timer(table, "internal force", force.accelerate)
        for wall in sim.walls:
            wall.constrain = timer(table, "wall", wall.constrain)
        sim.update = timer(table, "update pass", sim.update)
        sim.history.record = timer(table, "history", sim.history.record)
        sim.run()
        steps = sim.history.summary["steps"] + 1
        phases = {k: v / steps for k, v in table.items()}
        phases["step"] = sim.wall_seconds / steps
        if best is None or phases["step"] < best["step"]:
            best = phases
    best["internal force"] -= best["kernel"]
    best = {
        "kernel": best.pop("kernel"),
        "rest of the internal force (fill, -f/m)": best.pop("internal force"),
        **best,
    }
    best["loop and recorders"] = best["step"] - sum(v for k, v in best.items() if k != "step")
    sim = build_simulation(sc, comm, f"/tmp/rwall-bench-anatomy-{comm.size}")
    profiler = cProfile.Profile()
    profiler.enable()
    sim.run()
    profiler.disable()
    steps = sim.history.summary["steps"] + 1
    rows = [
        {
            "function": f"{file.split('/')[-1]}:{line}({name})",
            "calls": calls,
            "own_per_step": own / steps,
            "cumulative_per_step": cumulative / steps,
        }
        for (file, line, name), (_, calls, own, cumulative, _) in pstats.Stats(
            profiler
        ).stats.items()
    ]
    record = {"phases": best, "profile": sorted(rows, key=lambda r: -r["own_per_step"])[:15]}
    if comm.rank == 0:
        with open(a.json, "w") as f:
            json.dump(record, f, indent=1)


if __name__ == "__main__":
    main()
