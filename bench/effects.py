"""Per-step cost with and without each effect: `python bench/effects.py` -> bench/effects.md.

One scene (a soft block of 4,096 hexahedra resting on a plane), run with one effect
switched on at a time, the variants alternating in rounds; the figure is the median over
the rounds of the time loop's wall time per step (start-up excluded). What a scene does
not ask for is not in its pipeline, so the base line is what every scene pays. The same
block cut into two parts of one material (its lower half a part of its own: two kernel
calls, the interface books) is measured against the one-part block, elastic and plastic.
"""

import copy
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

from mpi4py import MPI

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))
from rwall_fem import build_simulation, parse_scene  # noqa: E402

BASE = {
    "run": {"end_time": 0.02},
    "mesh": {"shape": "bar", "size": [0.016, 0.016, 0.016], "element_size": 0.001},
    "material": {"model": "linear_elastic", "density": 1000.0, "young": 1e6, "poisson": 0.3},
    "initial": {"velocity": [0.0, 0.0, -0.1]},
    "wall": [{"kind": "plane", "point": [0, 0, 0], "normal_point": [0, 0, 1]}],
    "output": {"frames": 0, "history_interval": 100, "plot": False},
}
ROUNDS = 5
J2 = {
    "model": "elastic_plastic", "hardening": "linear", "yield_stress": 2e3,
    "hardening_modulus": 1e4,
}  # fmt: skip
TWO_PARTS = {
    "mesh": {"front_length": 0.008},
    "part": [{"name": "lower", "volumes": ["front"]}, {"name": "upper", "volumes": ["body"]}],
}
VARIANTS = {
    "base: linear elastic, fixed plane, free sliding": {},
    "+ gravity": {"gravity": {"acceleration": [0, 0, -9.81]}},
    "+ Coulomb friction": {"wall.0": {"slide": "friction", "friction": 0.3}},
    "+ friction filter": {
        "wall.0": {"slide": "friction", "friction": 0.3, "friction_filter": {"steps": 20}}
    },
    "+ main-node wall (moving)": {"wall.0": {"motion": {"mass": 1.0, "velocity": [0, 0, 0.1]}}},
    "+ history every step": {"output": {"history_interval": 1}},
    "+ fields (10 snapshots)": {"output": {"fields": 10}},
    "large deformation (neo-Hookean)": {"material": {"model": "neo_hookean"}},
    "J2 plasticity (elastic_plastic, linear hardening)": {"material": J2},
    "two parts of one material (the lower half a part of its own)": TWO_PARTS,
    "J2 plasticity, two parts": TWO_PARTS | {"material": J2},
}  # fmt: skip
# Two parts against one: (one part, two parts) rows of VARIANTS.
PART_PAIRS = {
    "linear elastic": (
        "base: linear elastic, fixed plane, free sliding",
        "two parts of one material (the lower half a part of its own)",
    ),
    "J2 plasticity": (
        "J2 plasticity (elastic_plastic, linear hardening)",
        "J2 plasticity, two parts",
    ),
}


def scene(changes):
    raw = copy.deepcopy(BASE)
    for key, value in changes.items():
        if key.startswith("wall."):
            raw["wall"][int(key.split(".")[1])] |= value
        elif isinstance(value, list):
            raw[key] = value
        else:
            raw[key] = raw.get(key, {}) | value
    return parse_scene(raw, source="bench")


# The internal force of one part and of two, in one process on a finer mesh of the bar.
PART_CELLS = 0.0005  # m: element size, 32,768 hexahedra
PART_BLOCKS, PART_CALLS = 25, 10


def internal_force_of_parts(comm, out: str) -> dict[str, tuple[float, float, int]]:
    """Per law of :data:`PART_PAIRS`, seconds per internal-force pass (the kernels of the
    parts, the scatters, -f/m, the parts' books) of the body as one part and as two, on
    the state after a few steps: medians of alternating blocks of calls in one process
    (steadier than whole runs, whose spread on a shared machine is of the size sought)."""
    passes = {}
    for law, (one, two) in PART_PAIRS.items():
        sims = []
        for k, name in enumerate((one, two)):
            changes = copy.deepcopy(VARIANTS[name])
            changes["mesh"] = changes.get("mesh", {}) | {"element_size": PART_CELLS}
            changes["run"] = {"end_time": 2e-3}
            sim = build_simulation(scene(changes), comm, Path(out) / f"{law} {k}")
            sim.run()
            sims.append(sim)
        times = ([], [])
        for _ in range(PART_BLOCKS):
            for sim, seconds in zip(sims, times, strict=True):
                comm.Barrier()
                t0 = time.perf_counter()
                for _ in range(PART_CALLS):
                    sim.internal.accelerate(sim.state)
                seconds.append((time.perf_counter() - t0) / PART_CALLS)
        cells = sims[0].info["cells"]
        passes[law] = (statistics.median(times[0]), statistics.median(times[1]), cells)
    return passes


def main():
    comm = MPI.COMM_WORLD
    load = [os.getloadavg()[0]]
    times = {name: [] for name in VARIANTS}
    steps = {}
    with tempfile.TemporaryDirectory() as out:
        out = comm.bcast(out, root=0)
        for _ in range(ROUNDS):  # the variants alternate, so that all see the same machine
            for name, changes in VARIANTS.items():
                sim = build_simulation(scene(changes), comm, out)
                sim.run()
                steps[name] = sim.history.summary["steps"] + 1
                times[name].append(sim.wall_seconds / steps[name])
        passes = internal_force_of_parts(comm, out)
    rows = [
        (name, sim.info["cells"], steps[name], statistics.median(t)) for name, t in times.items()
    ]
    load.append(os.getloadavg()[0])
    if comm.rank == 0:
        base = rows[0][3]
        lines = [
            "# Per-step cost of each effect",
            "",
            f"`python bench/effects.py` on {comm.size} rank(s); {rows[0][1]} hexahedra, "
            f"{rows[0][2]} steps (the base), median of {ROUNDS} alternating runs of the time "
            "loop. 1-minute load average "
            f"before / after: {load[0]:.2f} / {load[1]:.2f} (this measurement counts about 1 "
            "per rank itself: well above that, another job shares the cores and the ratios "
            "are noise).",
            "",
            "| scene | ms / step | x base |",
            "|---|---|---|",
        ]
        lines += [f"| {n} | {t * 1e3:.3f} | {t / base:.2f} |" for n, _, _, t in rows]
        cost = {n: t for n, _, _, t in rows}
        ratios = ", ".join(
            f"{law} {cost[two] / cost[one]:.3f}x" for law, (one, two) in PART_PAIRS.items()
        )
        lines += ["", f"A body of two parts against the same body as one part, per step: {ratios}."]
        cells = next(iter(passes.values()))[2]
        lines += [
            "",
            f"The internal force alone (kernels, scatters, -f/m, the parts' books) on {cells:,} "
            f"hexahedra, medians of {PART_BLOCKS} alternating blocks of {PART_CALLS} passes in "
            "one process:",
            "",
            "| law | one part (ms) | two parts (ms) | x |",
            "|---|---|---|---|",
        ]
        lines += [
            f"| {law} | {a * 1e3:.3f} | {b * 1e3:.3f} | {b / a:.3f} |"
            for law, (a, b, _) in passes.items()
        ]
        Path(__file__).with_name("effects.md").write_text("\n".join(lines) + "\n")
        print("\n".join(lines))


if __name__ == "__main__":
    main()
