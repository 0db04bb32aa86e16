"""The peer decks (../shared/peer-decks: the bar on a plane, the copper Taylor rod) run
through the deck reader, against OpenRadioss's answers on them.

    .venv/bin/python bench/peer_decks.py [--decks DIR] [--rod-h 0.8]

Generates the decks into a temporary folder (gen_taylor needs gmsh and meshes/round_bar.geo),
runs them with load_deck (the rod with run.dt_scale = 0.05: rwall_fem's step is fixed for a
run and the rod's crushed cells need it) and prints each figure beside OpenRadioss's.
"""

import argparse
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from rwall_fem.build import build_simulation, run_in_folder
from rwall_fem.radioss import load_deck

ROOT = Path(__file__).resolve().parents[1]
# OpenRadioss's answers (../shared/peer-decks/README.md)
BAR = {1.0: {"impulse": 1.5386, "contact": 39.14e-6, "rebound": 9.600},
       0.5: {"impulse": 1.5387, "contact": 39.21e-6, "rebound": 9.602}}  # fmt: skip
ROD = {0.8: {"length": 21.45e-3, "radius": 6.94e-3}, 0.4: {"length": 21.54e-3, "radius": 7.19e-3}}


def generate(script: str, out: Path, *args) -> Path:
    subprocess.run([sys.executable, str(Path(DECKS) / script), *args, "--out", str(out)],
                   check=True, cwd=ROOT, capture_output=True)  # fmt: skip
    return out


def bar_figures(starter: Path, out: Path) -> dict:
    """Wall impulse (N s), end of contact (s) and rebound velocity (m/s) of the bar deck."""
    sim = build_simulation(load_deck(starter), out=out)
    run_in_folder(sim)
    s = sim.history.summary
    wall = s["walls"][0]
    return {"impulse": -wall["impulse"][2], "contact": wall["last_contact"],
            "rebound": s["final_momentum"][2] / s["mass"]}  # fmt: skip


def rod_figures(starter: Path, out: Path) -> dict:
    """Final length (m) and mushroom radius (m, half the larger extent across the axis)."""
    sim = build_simulation(load_deck(starter, ["run.dt_scale=0.05"]), out=out)
    run_in_folder(sim)
    low, high = np.array(sim.history.summary["deformed_bounds"])
    return {"length": high[2] - low[2], "radius": max(high[:2] - low[:2]) / 2,
            "radius_x": (high[0] - low[0]) / 2, "radius_y": (high[1] - low[1]) / 2}  # fmt: skip


def show(name, ours, theirs):
    for key, value in ours.items():
        ref = theirs.get(key.split("_")[0] if key not in theirs else key)
        diff = f"{100 * (value / ref - 1):+.2f} %" if ref else ""
        print(f"{name:14s} {key:10s} {value:.5g}  OpenRadioss {ref if ref else '-'}  {diff}")


if __name__ == "__main__":
    parser = argparse.ArgumentParser()
    parser.add_argument("--decks", default=str(ROOT.parent / "shared" / "peer-decks"))
    parser.add_argument("--bar-h", type=float, default=1.0)
    parser.add_argument("--rod-h", type=float, default=0.8)
    args = parser.parse_args()
    DECKS = args.decks
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        generate("gen_bar.py", tmp, "--h", str(args.bar_h), "--name", "bar")
        show(f"bar h {args.bar_h}", bar_figures(tmp / "bar_0000.rad", tmp / "bar"),
             BAR.get(args.bar_h, BAR[1.0]))  # fmt: skip
        generate("gen_taylor.py", tmp, "--h", str(args.rod_h), "--icpre", "1", "--no-state",
                 "--name", "rod", "--geo", str(ROOT / "meshes" / "round_bar.geo"))  # fmt: skip
        show(f"rod h {args.rod_h}", rod_figures(tmp / "rod_0000.rad", tmp / "rod"),
             ROD.get(args.rod_h, ROD[0.8]))  # fmt: skip
