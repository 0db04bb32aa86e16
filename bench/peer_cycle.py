"""Where a cycle of the peer tube decks goes: microseconds per cycle of each phase of the
time loop, on the deck as it is (bench/peer_cycle.md reads it).

    .venv/bin/python bench/peer_cycle.py [--decks DIR] [--only tube,tubec] [--end S]
        [--profile N]

Each deck (``../shared/peer-decks/gen_shell.py tube --h 2.5``, and with ``--contact``) is
generated in a temporary folder and built as ``rwall-fem run`` builds it; its end time is
cut to ``--end`` seconds (default: the deck's, 4 ms). The phases the loop calls are
wrapped by CPU-time timers (about a microsecond per call: CPU times, the machine
being shared): the shell kernels (the compiled
element pass), the rest of the internal force (scatters, zeroing, -f/m), each contact
interface (and, inside it, its compiled force pass), the choice of the step, the walls,
the update pass, the history and the other recorders; what is left is the loop itself.
Then ``--profile`` N cycles run again under cProfile, whose 12 heaviest functions (own
time per cycle, cProfile's overhead included) are printed. One rank, one thread.
"""

from __future__ import annotations

import argparse
import cProfile
import functools
import pstats
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from rwall_fem.build import build_simulation, run_in_folder
from rwall_fem.radioss import load_deck

ROOT = Path(__file__).resolve().parents[1]
DECKS = {"tube": ["tube", "--h", "2.5"], "tubec": ["tube", "--h", "2.5", "--contact"]}


def timer(table: dict, name: str, call):
    """``call`` wrapped so that its seconds add up in ``table[name]``."""

    @functools.wraps(call)
    def timed(*args, **kwargs):
        t0 = time.process_time()
        try:
            return call(*args, **kwargs)
        finally:
            table[name] = table.get(name, 0.0) + time.process_time() - t0

    return timed


def phases(starter: Path, out: Path, end: float | None) -> tuple[dict, int]:
    """Seconds per cycle of each phase of a run of the deck, and its cycles."""
    sim = build_simulation(load_deck(starter), out=out)
    if end:
        sim.end_time = end
    table: dict = {}
    internal = sim.internal
    for element in getattr(internal, "elements", []):
        element._kernel = timer(table, "shell kernels", element._kernel)
    internal.accelerate = timer(table, "internal force", internal.accelerate)
    for contact in sim.contacts:
        contact.accelerate = timer(table, "contact", contact.accelerate)
        lib = contact.lib

        class Timed:  # the compiled force pass, apart
            def __getattr__(self, name, lib=lib):
                call = getattr(lib, name)
                return timer(table, "contact forces", call) if name == "contact_forces" else call

        contact.lib = Timed()
    sim.step_size.choose = timer(table, "step choice", sim.step_size.choose)
    for wall in sim.walls:
        wall.constrain = timer(table, "walls", wall.constrain)
    for boundary in sim.boundaries:
        boundary.constrain = timer(table, "boundaries", boundary.constrain)
    sim.update = timer(table, "update pass", sim.update)
    if sim.history is not None:
        sim.history.record = timer(table, "history record", sim.history.record)
    for recorder in sim.recorders:
        recorder.record = timer(table, "other recorders", recorder.record)
    cpu = time.process_time()
    run_in_folder(sim)  # its closing (plots) is a few CPU ms per run: not per cycle
    cpu = time.process_time() - cpu
    cycles = sim.history.summary["steps"] + 1
    table["internal force"] -= table["shell kernels"]
    if "contact" in table:
        table["contact"] -= table["contact forces"]
    table = {k: v / cycles for k, v in table.items()}
    table["loop and the rest"] = cpu / cycles - sum(table.values())
    table["cycle (CPU)"] = cpu / cycles
    return table, cycles


def profile(starter: Path, out: Path, cycles: int) -> list[tuple[str, float]]:
    """The 12 functions with most own time per cycle over ``cycles`` cycles."""
    sim = build_simulation(load_deck(starter), out=out)
    sim.end_time = cycles * sim.state.dt
    profiler = cProfile.Profile()
    profiler.enable()
    run_in_folder(sim)
    profiler.disable()
    done = sim.history.summary["steps"] + 1
    # The closing waits once for the drawing of histories.png (a read of its pipe): not a
    # cost of the cycles.
    rows = [(f"{Path(file).name}:{line}({name})", own / done)
            for (file, line, name), (_, _, own, _, _) in pstats.Stats(profiler).stats.items()
            if "TextIOWrapper" not in name]  # fmt: skip
    return sorted(rows, key=lambda r: -r[1])[:12]


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--decks", default=str(ROOT.parent / "shared" / "peer-decks"))
    parser.add_argument("--only", default=",".join(DECKS))
    parser.add_argument("--end", type=float, default=None, help="end time (s)")
    parser.add_argument("--profile", type=int, default=2000, help="cycles under cProfile")
    a = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        for name in a.only.split(","):
            folder = Path(tmp) / name
            folder.mkdir()
            subprocess.run([sys.executable, str(Path(a.decks) / "gen_shell.py"), *DECKS[name],
                            "--name", name, "--out", str(folder)], check=True,
                           capture_output=True)  # fmt: skip
            starter = folder / f"{name}_0000.rad"
            table, cycles = phases(starter, folder / "run", a.end)
            print(f"{name}: {cycles} cycles, microseconds per cycle")
            for phase, seconds in table.items():
                print(f"  {phase:20s} {1e6 * seconds:8.1f}")
            if a.profile:
                print(f"{name}: cProfile over {a.profile} cycles, own microseconds per cycle")
                for function, seconds in profile(starter, folder / "profile", a.profile):
                    print(f"  {1e6 * seconds:8.1f}  {function}")


if __name__ == "__main__":
    main()
