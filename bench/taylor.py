"""The Taylor rod at the demo's resolution: time loop and answers (run by bench/bench.py).

A copper rod (radius 3.2 mm, length 32.4 mm; density 8930, E 117 GPa, nu 0.35, J2 with
linear hardening: yield 400 MPa, H 100 MPa) strikes a frictionless plane at 227 m/s, for
80 us, with 0.4 mm one-point hexahedra (the default technology): about 24k cells. With
``--time-step fixed --dt-scale 0.05`` (the step before the adaptive one: 0.05 of the
stable step at rest for the whole run) about 26k steps; ``--time-step adaptive
--dt-scale 0.9`` follows the crushed cells. Published: final length 21.42-21.66 mm,
mushroom radius 7.0-7.22 mm. Writes one JSON record (rank 0).
"""

import argparse
import json
import time

from mpi4py import MPI

from rwall_fem import build_simulation, parse_scene

COPPER = {
    "model": "elastic_plastic",
    "density": 8930.0,
    "young": 117e9,
    "poisson": 0.35,
    "hardening": "linear",
    "yield_stress": 400e6,
    "hardening_modulus": 100e6,
}


def scene(element_size, time_step, dt_scale, history_interval):
    return {
        "run": {"end_time": 80e-6, "time_step": time_step, "dt_scale": dt_scale},
        "mesh": {
            "shape": "round_bar",
            "radius": 3.2e-3,
            "length": 32.4e-3,
            "element_size": element_size,
            "cell": "hexahedron",
        },
        "material": COPPER,
        "initial": {"velocity": [0.0, 0.0, -227.0]},
        "wall": [{"kind": "plane", "point": [0.0, 0.0, 0.0], "normal_point": [0.0, 0.0, 1.0]}],
        "output": {"frames": 0, "plot": False, "history_interval": history_interval},
    }


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--element-size", type=float, default=0.4e-3)
    p.add_argument("--time-step", choices=("fixed", "adaptive"), default="fixed")
    p.add_argument("--dt-scale", type=float, default=0.05)
    p.add_argument("--history-interval", type=int, default=20)
    p.add_argument("--json", required=True)
    a = p.parse_args()
    comm = MPI.COMM_WORLD
    t0 = time.perf_counter()
    raw = scene(a.element_size, a.time_step, a.dt_scale, a.history_interval)
    sim = build_simulation(parse_scene(raw, source="bench:taylor"), comm, "/tmp/rwall-bench-taylor")
    setup = comm.allreduce(time.perf_counter() - t0, op=MPI.MAX)
    sim.run()
    s = sim.history.summary
    (low, high) = s["deformed_bounds"]
    record = {
        "element": s["element"],
        "element_size": a.element_size,
        "time_step": a.time_step,
        "dt_scale": a.dt_scale,
        "history_interval": a.history_interval,
        "ranks": comm.size,
        "cells": s["cells"],
        "steps": s["steps"] + 1,
        "dt": s["dt"],
        "time_steps": s["time_step"],
        "status": s["status"],
        "setup_seconds": setup,
        "loop_seconds": s["wall_seconds"],
        "final_length_mm": (high[2] - low[2]) * 1e3,
        "mushroom_radius_mm": max(high[0], -low[0], high[1], -low[1]) * 1e3,
        "max_plastic_strain": s.get("max_plastic_strain"),
        "balance_error": s["energy"]["max_balance_error"],
    }
    if comm.rank == 0:
        with open(a.json, "w") as f:
            json.dump(record, f, indent=1)


if __name__ == "__main__":
    main()
