"""The peer decks (../shared/peer-decks: the bar on a plane, the copper Taylor rod, the
shell tube and plate) run through the deck reader, against OpenRadioss's answers on them.

    .venv/bin/python bench/peer_decks.py [--decks DIR] [--rod-h 0.8] [--only bar,rod,shells]

Generates the decks into a temporary folder (gen_taylor needs gmsh and meshes/round_bar.geo),
runs them with load_deck (the rod with run.dt_scale = 0.05: rwall_fem's step is fixed for a
run and the rod's crushed cells need it; the shell decks as they are) and prints each figure
beside OpenRadioss's. The shell decks (gen_shell.py, h 2.5 mm): the tube with Ishell 24, with
its self-contact and with Ishell 1, the plate with Ishell 24 and 1, in triangles, and
elastic at 5 m/s: some 3 minutes of CPU in all on one rank (measured on the first Zen 4:
the tubes 39 and 42 s, the plates 11, 11, 18 and 14 s; the contact tube 18 s on a later
one).
"""

import argparse
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

from rwall_fem.build import build_simulation, run_in_folder
from rwall_fem.output.wall_table import WALL_COLUMNS
from rwall_fem.radioss import load_deck

ROOT = Path(__file__).resolve().parents[1]
# OpenRadioss's answers (../shared/peer-decks/README.md)
BAR = {1.0: {"impulse": 1.5386, "contact": 39.14e-6, "rebound": 9.600},
       0.5: {"impulse": 1.5387, "contact": 39.21e-6, "rebound": 9.602}}  # fmt: skip
ROD = {0.8: {"length": 21.45e-3, "radius": 6.94e-3}, 0.4: {"length": 21.54e-3, "radius": 7.19e-3}}
# The shell decks at h 2.5 mm: (gen_shell.py arguments, OpenRadioss's figures in SI units;
# fold: the 10-us mean force around the first fold, N).
SHELLS = {
    "tube": (["tube"], {"cycles": 21666, "travel": 28.57e-3, "velocity": -5.29,
                        "plastic": 734.0, "fold": 81.8e3, "fold_time": 0.07e-3, "impulse": 94.1}),
    "tube_contact": (["tube", "--contact"], {"cycles": 18127, "travel": 28.07e-3,
                     "velocity": -4.70, "plastic": 791.0, "impulse": 106.0}),
    "tube_ishell1": (["tube", "--ishell", "1"], {"cycles": 19651, "travel": 28.63e-3,
                     "velocity": -5.19, "plastic": 727.0, "fold": 81.6e3,
                     "hourglass": 33.0}),
    "plate": (["plate"], {"cycles": 5219, "travel": 17.95e-3, "rebound": 4.85,
                          "impulse": 24.92, "peak": 24.8e3, "peak_time": 1.26e-3,
                          "plastic": 186.9}),
    "plate_ishell1": (["plate", "--ishell", "1"], {"cycles": 4599, "travel": 17.94e-3,
                      "rebound": 4.90, "impulse": 24.98, "peak": 24.8e3, "plastic": 187.8}),
    "plate_tria": (["plate", "--tria"], {"cycles": 6602, "travel": 17.90e-3, "rebound": 4.89,
                   "impulse": 24.95, "peak": 24.9e3, "plastic": 187.7}),
    "plate_elastic": (["plate", "--law", "1", "--v0", "5", "--tend", "4"],
                      {"cycles": 10435, "travel": 4.35e-3, "rebound": 4.49, "impulse": 9.49,
                       "peak": 9.84e3, "peak_time": 1.24e-3}),
}  # fmt: skip
FOLD_WINDOW = 10e-6  # s, OpenRadioss's mean around the first fold


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


def shell_figures(starter: Path, out: Path) -> dict:
    """Cycles and the wall's figures of a shell deck: the main node's largest travel (m),
    its final velocity (m/s), the wall impulse (N s), the peak force (N) and its time (s)
    (the tube: the largest 10-us mean force of the first 0.2 ms, its first-cycle spike
    left out, as OpenRadioss's figure), the plastic work (J)."""
    sim = build_simulation(load_deck(starter), out=out)
    run_in_folder(sim)
    s = sim.history.summary
    rows = sim.history.wall(0)
    col = {name: rows[:, WALL_COLUMNS.index(name)] for name in WALL_COLUMNS}
    t, z = col["time"], col["position_z"]
    tube = "tube" in starter.name
    figures = {"cycles": s["steps"], "travel": z[0] - z.min(),
               "velocity" if tube else "rebound": col["velocity_z"][-1],
               "impulse": col["impulse_z"][-1]}  # fmt: skip
    if tube:
        # the mean force over [t - w/2, t + w/2], from the cumulative impulse, every w up
        # to 0.2 ms: the first fold is its largest maximum after its first minimum (the
        # elastic wave of the tied wall's first cycles comes before)
        centre = np.arange(FOLD_WINDOW / 2, 0.2e-3, FOLD_WINDOW)
        impulse = col["impulse_z"]
        mean = (np.interp(centre + FOLD_WINDOW / 2, t, impulse)
                - np.interp(centre - FOLD_WINDOW / 2, t, impulse)) / FOLD_WINDOW  # fmt: skip
        first_minimum = int(np.argmax(np.diff(mean) > 0))
        k = first_minimum + int(mean[first_minimum:].argmax())
        figures["fold"], figures["fold_time"] = mean[k], centre[k]
    else:
        k = np.abs(col["force_z"]).argmax()
        figures["peak"], figures["peak_time"] = abs(col["force_z"][k]), t[k]
    if s.get("plastic_work") is not None:
        figures["plastic"] = s["plastic_work"]
    figures["hourglass"] = s["energy"].get("hourglass", 0.0)
    return figures


def show(name, ours, theirs):
    for key, value in ours.items():
        ref = theirs.get(key)
        diff = f"{100 * (value / ref - 1):+.2f} %" if ref else ""
        print(f"{name:14s} {key:10s} {value:.5g}  OpenRadioss {ref if ref else '-'}  {diff}")


if __name__ == "__main__":
    parser = argparse.ArgumentParser()
    parser.add_argument("--decks", default=str(ROOT.parent / "shared" / "peer-decks"))
    parser.add_argument("--bar-h", type=float, default=1.0)
    parser.add_argument("--rod-h", type=float, default=0.8)
    parser.add_argument("--only", default="bar,rod,shells", help="which: bar, rod, shells")
    args = parser.parse_args()
    DECKS, only = args.decks, args.only.split(",")
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        if "bar" in only:
            generate("gen_bar.py", tmp, "--h", str(args.bar_h), "--name", "bar")
            show(f"bar h {args.bar_h}", bar_figures(tmp / "bar_0000.rad", tmp / "bar"),
                 BAR.get(args.bar_h, BAR[1.0]))  # fmt: skip
        if "rod" in only:
            generate("gen_taylor.py", tmp, "--h", str(args.rod_h), "--icpre", "1",
                     "--no-state", "--name", "rod", "--geo",
                     str(ROOT / "meshes" / "round_bar.geo"))  # fmt: skip
            show(f"rod h {args.rod_h}", rod_figures(tmp / "rod_0000.rad", tmp / "rod"),
                 ROD.get(args.rod_h, ROD[0.8]))  # fmt: skip
        for name, (deck, theirs) in SHELLS.items() if "shells" in only else ():
            generate("gen_shell.py", tmp, *deck, "--h", "2.5", "--name", name)
            show(name, shell_figures(tmp / f"{name}_0000.rad", tmp / name), theirs)
