"""Cost of each material relative to linear elasticity, per element technology (one process).

On one mesh per cell type (about 100k cells, the bar of bench/case.py), the element
kernel of every technology x material is timed alone, the combinations alternating in
rounds (medians), in two states:

- ``elastic``: a uniform strain of 1e-3 plus a velocity whose strain increment per step is
  tiny: the elasto-plastic points stay elastic;
- ``plastic``: the same with a uniaxial strain rate of 2e4 /s (1e-3 per step of 5e-8 s):
  after the first calls every point of the elasto-plastic kernels is in plastic flow
  (radial return at every point, every call), the upper bound of their cost.

Hyperelastic and linear kernels do not depend on the velocity: one figure (``elastic``).
Then whole steps of the bar scene of bench/case.py (10 m/s onto a plane; the plastic
front yields) are timed for every combination, the stable-step monitors of the nonlinear
materials included. Writes one JSON record.
"""

import argparse
import json
import statistics
import time

import case
from mpi4py import MPI

from rwall_fem import _compat, build_simulation, parse_scene
from rwall_fem.elements import ElementForce, GhostedField, Technology
from rwall_fem.meshing import body_mesh

comm = MPI.COMM_WORLD
STEEL = {"density": 7850.0, "young": 210e9, "poisson": 0.3}
MATERIALS = {
    "linear_elastic": {"model": "linear_elastic"},
    "saint_venant_kirchhoff": {"model": "saint_venant_kirchhoff"},
    "neo_hookean": {"model": "neo_hookean"},
    "elastic_plastic": {
        "model": "elastic_plastic",
        "hardening": "linear",
        "yield_stress": 250e6,
        "hardening_modulus": 1e9,
    },
    "johnson_cook": {
        "model": "johnson_cook",
        "yield_stress": 250e6,
        "hardening_coefficient": 500e6,
        "hardening_exponent": 0.3,
        "strain_rate_coefficient": 0.02,
        "heating": {
            "softening_exponent": 1.0,
            "melting_temperature": 1800.0,
            "specific_heat": 450.0,
        },
    },
}
CELL_TECHNOLOGIES = {
    "tetrahedron": ["tet"],
    "hexahedron": ["full", "physical", "stiffness", "viscous", "none"],
}
RATES = {"elastic": 1.0, "plastic": 2e4}  # uniaxial strain rates, 1/s


def material(name):
    raw = {
        "run": {"end_time": 1e-6},
        "mesh": {"shape": "bar", "size": [0.01] * 3, "element_size": 0.01},
        "material": STEEL | MATERIALS[name],
    }
    return parse_scene(raw, source="bench").material


def technology(cell, tech, plastic):
    options = case.TECHNOLOGIES[tech]
    return Technology.choose(cell, options.get("integration"), options.get("hourglass"),
                             plastic=plastic)  # fmt: skip


class Probe:
    """An element force of one technology x material on the shared fields, its kernel
    ready to call with the step's dt."""

    def __init__(self, V, cell, tech, name, u, v):
        m = material(name)
        self.force = ElementForce(V, m, technology(cell, tech, m.plastic), u, v)
        self.force.params.dt = case.DT
        self.plastic = m.plastic

    def reset(self):
        """Back to the virgin state (elasto-plastic state per point), so that every round
        starts from the same state."""
        if self.force.history is not None:
            self.force.history[...] = 0.0
        self.force.f.array.fill(0.0)


def kernel_costs(body, cell, rounds, repeats):
    V = _compat.vector_space(body.msh)
    u, v = GhostedField(V), GhostedField(V)
    X = V.tabulate_dof_coordinates()
    u.array[:, 2] = -1e-3 * X[:, 2]  # uniform compression 1e-3
    probes = {
        (tech, name): Probe(V, cell, tech, name, u, v)
        for tech in CELL_TECHNOLOGIES[cell]
        for name in MATERIALS
    }
    times = {}
    for _ in range(rounds):
        for regime, rate in RATES.items():
            v.array[:] = 0.0
            v.array[:, 2] = -rate * X[:, 2]
            for (tech, name), probe in probes.items():
                if regime == "plastic" and not probe.plastic:
                    continue
                probe.reset()
                kernel = probe.force._kernel
                for _ in range(3):  # into plastic flow (regime "plastic")
                    kernel()
                seconds = case.block(kernel, repeats)
                times.setdefault(f"{tech}:{name}:{regime}", []).append(seconds)
    strains = {
        f"{tech}:{name}": float(probe.force.plastic_strains().max(initial=0.0))
        for (tech, name), probe in probes.items()
        if probe.plastic
    }
    return {k: statistics.median(v) for k, v in times.items()}, times, strains


def step_costs(body, cell, n, rounds, steps, technologies):
    times = {}
    for _ in range(rounds):
        for tech in technologies:
            for name in MATERIALS:
                sc = case.scene(cell, n, steps, 100, tech, STEEL | MATERIALS[name])
                sim = build_simulation(sc, comm, f"/tmp/rwall-bench-costs-{comm.size}", body=body)
                sim.run()
                s = sim.history.summary
                if s["status"] != "done":
                    raise RuntimeError(f"{tech} {name}: {s['status']}: {s['reason']}")
                times.setdefault(f"{tech}:{name}", []).append(s["wall_seconds"] / (s["steps"] + 1))
    return {k: statistics.median(v) for k, v in times.items()}, times


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--cell", default="hexahedron")
    p.add_argument("--n", type=int, default=22)
    p.add_argument("--rounds", type=int, default=5)
    p.add_argument("--steps", type=int, default=200)
    p.add_argument("--step-rounds", type=int, default=2)
    p.add_argument("--step-technologies", help="technologies of the whole steps (default: all)")
    p.add_argument("--json", required=True)
    a = p.parse_args()
    case.fixed_step()
    body = body_mesh(comm, case.scene(a.cell, a.n, 1, 1, CELL_TECHNOLOGIES[a.cell][0]).mesh)
    cells = body.num_cells
    repeats = max(3, int(1e6 / cells))
    t0 = time.perf_counter()
    kernel, kernel_all, strains = kernel_costs(body, a.cell, a.rounds, repeats)
    kernel_seconds = time.perf_counter() - t0
    techs = a.step_technologies.split(",") if a.step_technologies else CELL_TECHNOLOGIES[a.cell]
    step, step_all = step_costs(body, a.cell, a.n, a.step_rounds, a.steps, techs)
    record = {
        "cell": a.cell,
        "n": a.n,
        "cells": cells,
        "ranks": comm.size,
        "rounds": a.rounds,
        "repeats": repeats,
        "steps": a.steps + 1,
        "step_rounds": a.step_rounds,
        "kernel_seconds": kernel,
        "kernel_all": kernel_all,
        "max_plastic_strain_probe": strains,
        "kernel_phase_seconds": kernel_seconds,
        "step_seconds": step,
        "step_all": step_all,
        "materials": MATERIALS,
    }
    if comm.rank == 0:
        with open(a.json, "w") as f:
            json.dump(record, f, indent=1)


if __name__ == "__main__":
    main()
