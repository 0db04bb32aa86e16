"""The peer shell decks timed in OpenRadioss and in rwall_fem on this machine: CPU time,
cycles and the loop-time ratio (1 thread / 1 rank each).

    .venv/bin/python bench/openradioss_timing.py [--openradioss DIR] [--decks DIR]
        [--only tube,tubec,plate] [--repeat N] [--keep DIR]

DIR holds OpenRadioss's executables ``starter_linux64_gf`` and ``engine_linux64_gf``
(default ``$OPENRADIOSS_PATH/exec``, else ``../openradioss-src/exec`` beside the clone);
``bench/openradioss/build.sh SRC`` builds them from a snapshot of OpenRadioss's sources;
without them the script says so in one line and stops (exit 0). Each deck
(``../shared/peer-decks/gen_shell.py``: the tube at h 2.5 mm, Ishell 24; the same tube with
self-contact, ``/INTER/TYPE7``, ``tubec``; the plate, Ishell 24, 20 m/s) runs ``--repeat``
times in each code, alternately, and the medians are printed: OpenRadioss's engine (its
starter not counted) with OMP_NUM_THREADS=1, its cycles from the ``TOTAL NUMBER OF CYCLES`` line
it prints;
rwall_fem's time loop in this process (set-up not counted). CPU times, not wall times: the
machine is shared, and a CPU time does not count the cycles other processes took; the
1-minute load average before each deck is printed beside them. ``--keep DIR`` keeps
OpenRadioss's listings (``NAME_0000.out``, ``NAME_0001.out``) and time histories there, to
check its answers against ``../shared/peer-decks/README.md``.
"""

import argparse
import os
import statistics
import re
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from rwall_fem.build import build_simulation, run_in_folder
from rwall_fem.radioss import load_deck

ROOT = Path(__file__).resolve().parents[1]
DECKS = {"tube": ["tube", "--h", "2.5"], "tubec": ["tube", "--h", "2.5", "--contact"],
         "plate": ["plate", "--h", "2.5"]}
STARTER, ENGINE = "starter_linux64_gf", "engine_linux64_gf"


def children_cpu() -> float:
    """CPU seconds (user + system) of the finished children so far."""
    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def openradioss(folder: Path, name: str, exe: Path) -> dict:
    """Starter, then engine, in ``folder``: the engine's CPU and wall seconds and cycles."""
    env = dict(os.environ, OMP_NUM_THREADS="1", OMP_STACKSIZE="400m")
    lib = exe / ".." / "extlib" / "hm_reader" / "linux64"
    env["LD_LIBRARY_PATH"] = f"{exe}:{lib}:" + env.get("LD_LIBRARY_PATH", "")
    env.setdefault("RAD_CFG_PATH", str(exe / ".." / "hm_cfg_files"))
    subprocess.run([str(exe / STARTER), "-i", f"{name}_0000.rad", "-np", "1", "-nt", "1"],
                   cwd=folder, env=env, check=True, capture_output=True)  # fmt: skip
    cpu, wall = children_cpu(), time.perf_counter()
    command = [str(exe / ENGINE), "-i", f"{name}_0001.rad", "-nt", "1"]
    done = subprocess.run(command, cwd=folder, env=env, check=True, capture_output=True,
                          text=True)  # fmt: skip
    # the closing count; the NC= progress lines come only every /PRINT cycles
    cycles = re.findall(r"TOTAL NUMBER OF CYCLES\s*:\s*(\d+)", done.stdout)
    return {"cpu": children_cpu() - cpu, "wall": time.perf_counter() - wall,
            "cycles": int(cycles[-1]) if cycles else None}  # fmt: skip


def ours(starter: Path, out: Path) -> dict:
    """rwall_fem's time loop on the deck as it is: CPU and wall seconds, cycles."""
    sim = build_simulation(load_deck(starter), out=out)
    cpu = time.process_time()
    run_in_folder(sim)
    cpu = time.process_time() - cpu
    s = sim.history.summary
    return {"cpu": cpu, "wall": s["wall_seconds"], "cycles": s["steps"]}


def median(runs: list) -> dict:
    """The median CPU and wall seconds of repeated runs, and their cycles (the last run's)."""
    return {"cpu": statistics.median(r["cpu"] for r in runs),
            "wall": statistics.median(r["wall"] for r in runs), "cycles": runs[-1]["cycles"]}


def keep(folder: Path, name: str, into: Path) -> None:
    """Copy OpenRadioss's listings and time histories of deck ``name`` into ``into``."""
    into.mkdir(parents=True, exist_ok=True)
    for path in folder.glob(f"{name}*"):
        if path.suffix != ".rad" and path.is_file():
            shutil.copy2(path, into / path.name)


if __name__ == "__main__":
    parser = argparse.ArgumentParser()
    default = Path(os.environ.get("OPENRADIOSS_PATH", ROOT.parent / "openradioss-src")) / "exec"
    parser.add_argument("--openradioss", default=str(default))
    parser.add_argument("--decks", default=str(ROOT.parent / "shared" / "peer-decks"))
    parser.add_argument("--only", default=",".join(DECKS), help="decks, comma-separated")
    parser.add_argument("--repeat", type=int, default=1, help="runs of each deck in each code")
    parser.add_argument("--keep", help="folder for OpenRadioss's listings and time histories")
    args = parser.parse_args()
    only = args.only.split(",")
    if not set(only) <= set(DECKS) or args.repeat < 1:
        print(f"--only: decks among {', '.join(DECKS)}; --repeat: 1 or more")
        sys.exit(2)
    exe = Path(args.openradioss)
    if not all((exe / name).is_file() for name in (STARTER, ENGINE)):
        print(f"SKIPPED: no OpenRadioss {STARTER} and {ENGINE} in {exe} (--openradioss DIR)")
        sys.exit(0)
    print(f"medians of {args.repeat} run(s) each")
    print("deck   code         CPU (s)   wall (s)   cycles   CPU per cycle (ms)")
    with tempfile.TemporaryDirectory() as tmp:
        for name in only:
            folder = Path(tmp) / name
            folder.mkdir()
            subprocess.run([sys.executable, str(Path(args.decks) / "gen_shell.py"), *DECKS[name],
                            "--name", name, "--out", str(folder)], check=True,
                           capture_output=True)  # fmt: skip
            load = os.getloadavg()[0]
            their_runs, my_runs = [], []
            for _ in range(args.repeat):
                their_runs.append(openradioss(folder, name, exe))
                my_runs.append(ours(folder / f"{name}_0000.rad", folder / "rwall_fem"))
            if args.keep:
                keep(folder, name, Path(args.keep) / name)
            theirs, mine = median(their_runs), median(my_runs)
            print(f"{name:6s} load average before: {load:.1f}")
            for code, r in (("OpenRadioss", theirs), ("rwall_fem", mine)):
                per = 1e3 * r["cpu"] / r["cycles"] if r["cycles"] else float("nan")
                print(f"{name:6s} {code:11s} {r['cpu']:9.2f} {r['wall']:10.2f} "
                      f"{r['cycles'] or '-':>8} {per:12.3f}")  # fmt: skip
            print(f"{name:6s} loop-time ratio (CPU, OpenRadioss / rwall_fem): "
                  f"{theirs['cpu'] / mine['cpu']:.2f}; cycles {mine['cycles']} against "
                  f"{theirs['cycles']}")  # fmt: skip
            shutil.rmtree(folder, ignore_errors=True)
