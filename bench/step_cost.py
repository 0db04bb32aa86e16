"""What the adaptive step costs per cycle on the 80k-hexahedron bar (run by bench/bench.py).

The scene of the 80k section (demos/bar_impact.toml at 0.5 mm: 10 x 10 x 100 mm steel,
one-point hexahedra with physical hourglass control, 10 m/s onto a fixed plane), built
once; in rounds, alternating so that all see the same machine (medians of the rounds):

- ``fixed`` and ``adaptive``: whole steps of the time loop, ``run.time_step`` "fixed" at
  dt_scale 0.9 (the step of the start for the whole run) against "adaptive" at 0.9. A
  linear elastic body's stable step does not change, so its adaptive step estimates the
  cells once; what it adds each cycle is the choice of the step;
- what a body whose step varies (any other material, or mass scaling) adds to each
  cycle: the cells' estimates in the kernel pass (``kernel, estimating`` against
  ``kernel``, the compiled kernel alone on the final state) and the booking of the
  energy correction of a varying step in the update pass (``update, booking`` against
  ``update``), plus ``choose``, the step size's choice (the reduction of the estimates
  over the ranks, the rounding, the records).

Writes one JSON record of seconds per step (the slowest rank's).
"""

import argparse
import functools
import json
import statistics
import time
from pathlib import Path

from mpi4py import MPI

from rwall_fem import build_simulation, parse_scene
from rwall_fem.meshing import body_mesh
from rwall_fem.scene.read import read_toml
from rwall_fem.solver import CentralDifference

comm = MPI.COMM_WORLD
SCENE = Path(__file__).resolve().parent.parent / "demos" / "bar_impact.toml"


def scene(time_step: str, steps: int, dt: float, element_size: float):
    raw = read_toml(SCENE)
    raw["run"] |= {"time_step": time_step, "dt_scale": 0.9, "end_time": steps * dt}
    raw["mesh"]["element_size"] = element_size
    raw["output"] |= {"frames": 0, "plot": False, "history_interval": 1}
    return parse_scene(raw, source="bench:step_cost")


def block(call, repeats):
    """Seconds per call of ``repeats`` calls, the slowest rank's."""
    comm.Barrier()
    t0 = time.perf_counter()
    for _ in range(repeats):
        call()
    return comm.allreduce((time.perf_counter() - t0) / repeats, op=MPI.MAX)


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--element-size", type=float, default=5e-4)
    p.add_argument("--steps", type=int, default=300)
    p.add_argument("--rounds", type=int, default=5)
    p.add_argument("--repeats", type=int, default=30)
    p.add_argument("--json", required=True)
    a = p.parse_args()
    out = f"/tmp/rwall-bench-step-cost-{comm.size}"
    first = scene("fixed", 1, 1e-7, a.element_size)
    body = body_mesh(comm, first.mesh)
    dt = build_simulation(first, comm, out, body=body).state.dt  # the fixed step, s
    times: dict[str, list[float]] = {}
    summary = {}
    for _ in range(a.rounds):
        for mode in ("fixed", "adaptive"):
            raw = scene(mode, a.steps, dt, a.element_size)
            sim = build_simulation(raw, comm, out, body=body)
            sim.run()
            s = sim.history.summary
            times.setdefault(mode, []).append(s["wall_seconds"] / (s["steps"] + 1))
            summary[mode] = {"steps": s["steps"] + 1, "status": s["status"], "dt": s["dt"]}
        # On the adaptive run's final state: the parts of a cycle of a varying step.
        element, state = sim.internal.elements[0], sim.state
        params = element.params
        for estimate in (False, True):
            params.estimate = estimate
            name = "kernel, estimating" if estimate else "kernel"
            times.setdefault(name, []).append(block(element._kernel, a.repeats))
        internal = sim.internal
        plain = CentralDifference(state)
        internal.books_work = True  # as for a varying step: f . v summed, then Body.book
        booking = CentralDifference(state, internal)
        internal.books_work = False
        times.setdefault("update", []).append(block(functools.partial(plain, state), a.repeats))
        times.setdefault("update, booking", []).append(
            block(functools.partial(booking, state), a.repeats)
        )
        choose = functools.partial(sim.step_size.choose, sim, state)
        times.setdefault("choose", []).append(block(choose, a.repeats))
    record = {
        "ranks": comm.size,
        "cells": sim.info.get("cells"),
        "runs": summary,
        "seconds": {k: statistics.median(v) for k, v in times.items()},
        "all_seconds": times,
    }
    if comm.rank == 0:
        Path(a.json).write_text(json.dumps(record, indent=1))


if __name__ == "__main__":
    main()
