"""What the partitioned contact search costs: steps per second of the tube crush with
self-contact (``demos/tube_crush.toml``, shortened) on 1 and 2 ranks, for this tree and
for each ``--tree`` (a checkout of older code), and the bytes the contact exchanges per
step (``summary.json``'s ``exchanged_bytes`` of the interface, where the code reports it).

    python bench/contact_partition.py [--tree NAME=DIR ...] [--ranks 1 2] [--repeats 3]
                                      [--end-time 2.5e-3]

Runs are taken in turn (every tree and rank count once, then again), so that the
machine's load falls on all alike; the figures are the medians of the loop's steps per
second (``summary.json``: steps / wall_seconds). With ``--cpu`` each run is timed inside
the process instead, in CPU time (steadier on a loaded machine): the loop's steps per CPU
second and the share of the contact interface's step (the largest over the ranks).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "demos" / "tube_crush.toml"
FOLDER = Path("/tmp/rwall_fem-bench-contact")


def _env(tree: Path) -> dict:
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMI", "PMIX"))}
    env.update(PYTHONPATH=str(tree), PYTHONDONTWRITEBYTECODE="1")
    return env


def _run(tree: Path, ranks: int, end_time: float, folder: Path) -> dict:
    """One run's summary.json."""
    command = [sys.executable, "-m", "rwall_fem", "run", str(SCENE), "--out", str(folder),
               "--quiet", "--set", f"run.end_time={end_time}", "--set", "output.frames=0"]  # fmt: skip
    if ranks > 1:
        command = ["mpirun", "--allow-run-as-root", "--oversubscribe", "-n", str(ranks), *command]
    subprocess.run(command, env=_env(tree), cwd=tree, check=True)
    return json.loads((folder / "summary.json").read_text())


def _inner(end_time: float, folder: Path) -> None:
    """Run the tube in this process (under mpirun: every rank), timing in CPU seconds the
    loop and the contact interfaces' steps; rank 0 prints one JSON line."""
    import time

    from mpi4py import MPI

    from rwall_fem import build_simulation, parse_scene

    raw = tomllib.loads(SCENE.read_text())
    raw["run"]["end_time"] = end_time
    raw["output"] = {"plot": False}
    comm = MPI.COMM_WORLD
    sim = build_simulation(parse_scene(raw, source="bench"), comm, folder)
    spent = [0.0]
    for contact in sim.contacts:
        step = contact.accelerate

        def timed(s, step=step):
            start = time.process_time()
            step(s)
            spent[0] += time.process_time() - start

        contact.accelerate = timed
    start = time.process_time()
    sim.run()
    loop = comm.allreduce(time.process_time() - start, op=MPI.MAX)
    contact = comm.allreduce(spent[0], op=MPI.MAX)
    if comm.rank == 0:
        print(json.dumps({"steps": sim.state.step, "loop": loop, "contact": contact}))


def _cpu_run(tree: Path, ranks: int, end_time: float, folder: Path) -> dict:
    command = [sys.executable, str(Path(__file__).resolve()), "--inner", "--end-time",
               str(end_time), "--out", str(folder)]  # fmt: skip
    if ranks > 1:
        command = ["mpirun", "--allow-run-as-root", "--oversubscribe", "-n", str(ranks), *command]
    done = subprocess.run(command, env=_env(tree), cwd=tree, check=True, capture_output=True,
                          text=True)  # fmt: skip
    return json.loads(done.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tree", action="append", default=[], help="NAME=DIR of older code")
    parser.add_argument("--ranks", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--end-time", type=float, default=2.5e-3)
    parser.add_argument("--cpu", action="store_true", help="CPU time inside the process")
    parser.add_argument("--inner", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--out", type=Path, default=FOLDER / "inner", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.inner:
        return _inner(args.end_time, args.out)
    trees = {"this": ROOT} | {k: Path(v) for k, v in (t.split("=", 1) for t in args.tree)}
    rates: dict = {(name, n): [] for name in trees for n in args.ranks}
    facts: dict = {}
    for _ in range(args.repeats):
        for name, tree in trees.items():
            for n in args.ranks:
                if args.cpu:
                    r = _cpu_run(tree, n, args.end_time, FOLDER / f"{name}-{n}")
                    rates[name, n].append(r["steps"] / r["loop"])
                    facts[name, n] = (r["steps"], f"contact {r['contact'] / r['loop']:.1%}",
                                      None)  # fmt: skip
                    print(name, n, f"{rates[name, n][-1]:.1f} steps/CPU s", facts[name, n],
                          flush=True)  # fmt: skip
                    continue
                summary = _run(tree, n, args.end_time, FOLDER / f"{name}-{n}")
                rates[name, n].append(summary["steps"] / summary["wall_seconds"])
                contact = summary["contacts"][0]
                facts[name, n] = (summary["steps"], contact.get("sorts"),
                                  contact.get("exchanged_bytes"))  # fmt: skip
                print(name, n, f"{rates[name, n][-1]:.1f} steps/s", facts[name, n], flush=True)
    print(f"| tree | ranks | steps/s (median of {args.repeats}) | steps | sorts | "
          "bytes exchanged per step |")
    print("|---|---|---|---|---|---|")
    for (name, n), values in rates.items():
        steps, sorts, sent = facts[name, n]
        per_step = "-" if sent is None else f"{sent / steps:.0f}"
        print(f"| {name} | {n} | {statistics.median(values):.1f} | {steps} | {sorts} | "
              f"{per_step} |")


if __name__ == "__main__":
    main()
