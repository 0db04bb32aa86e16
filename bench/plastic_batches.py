"""How full the shell kernel's vectors are when its points flow: on a peer tube deck, over
every cycle, the share of the cells whose points flowed, of the cells in a batch where some
did (the batch takes the plastic return's path for all its lanes), and the lanes that flowed
in each point's vector that took the return (bench/peer_cycle.md reads it).

    .venv/bin/python bench/plastic_batches.py [--decks DIR] [--deck tube|tubec] [--end S]

A point flowed in a step when the kernel changed its plastic strain. Batches are the
kernel's (``LANES`` consecutive cells in DOLFINx's order); the same shares are also given
for batches of the cells in rings (sorted by height, then angle about the tube's axis), an
order the kernel does not use, to show what the order costs. One rank.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from peer_cycle import DECKS, ROOT
from rwall_fem.build import build_simulation, run_in_folder
from rwall_fem.radioss import load_deck
from rwall_fem.shells.elements import ShellForce


def lanes() -> int:
    """The kernels' lanes on this host (kernels/batch.h): 8 with AVX-512, else 4."""
    flags = Path("/proc/cpuinfo").read_text() if Path("/proc/cpuinfo").exists() else ""
    return 8 if " avx512f" in flags else 4


def watch(element: ShellForce, width: int, counts: dict) -> None:
    """Wrap ``element``'s kernel call so that each call adds its shares to ``counts``."""
    X = np.asarray(element.X).reshape(-1, 3)
    centre = X[np.asarray(element.cells).reshape(element.num_cells, -1)].mean(axis=1)
    angle = np.arctan2(*(centre[:, :2] - centre[:, :2].mean(axis=0)).T[::-1])
    rings = np.lexsort((angle, np.round(centre[:, 2], 9)))
    full = element.num_cells // width * width
    kernel = element._kernel

    def counted(*args, **kwargs):
        before = element.plastic_strains()
        out = kernel(*args, **kwargs)
        flowed = element.plastic_strains() != before  # (points, cells)
        batches = flowed[:, :full].reshape(len(flowed), -1, width)
        counts["steps"] += 1
        counts["cells"] += int(flowed.any(axis=0).sum())
        counts["in flowing batches"] += width * int(batches.any(axis=(0, 2)).sum())
        counts["in flowing batches, rings"] += width * int(
            flowed[:, rings][:, :full].reshape(len(flowed), -1, width).any(axis=(0, 2)).sum())
        counts["lanes"] += int(batches.sum())
        counts["vectors"] += int(batches.any(axis=2).sum())
        return out

    element._kernel = counted


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--decks", default=str(ROOT.parent / "shared" / "peer-decks"))
    parser.add_argument("--deck", default="tubec", choices=sorted(DECKS))
    parser.add_argument("--end", type=float, default=None, help="end time (s)")
    a = parser.parse_args()
    width = lanes()
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        subprocess.run([sys.executable, str(Path(a.decks) / "gen_shell.py"), *DECKS[a.deck],
                        "--name", a.deck, "--out", str(folder)], check=True,
                       capture_output=True)  # fmt: skip
        sim = build_simulation(load_deck(folder / f"{a.deck}_0000.rad"), out=folder / "run")
        if a.end:
            sim.end_time = a.end
        (element,) = sim.internal.elements
        counts = dict.fromkeys(["steps", "cells", "in flowing batches",
                                "in flowing batches, rings", "lanes", "vectors"], 0)  # fmt: skip
        watch(element, width, counts)
        run_in_folder(sim)
    per_step = element.num_cells * counts["steps"]
    print(f"{a.deck}: {counts['steps']} kernel calls, {element.num_cells} cells, "
          f"{width} lanes, {element.points} points")
    print(f"  cells whose points flowed          {counts['cells'] / per_step:6.1%}")
    print(f"  cells in batches where some did    {counts['in flowing batches'] / per_step:6.1%}")
    print(f"  the same, batches of rings         "
          f"{counts['in flowing batches, rings'] / per_step:6.1%}")
    print(f"  lanes that flowed per point vector through the return  "
          f"{counts['lanes'] / max(counts['vectors'], 1):.2f} of {width}")


if __name__ == "__main__":
    main()
