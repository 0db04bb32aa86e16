"""Which cells set the step of the peer tube deck, and by OpenRadioss's rule written out
here (not the kernel's): docs/radioss.md ("Against OpenRadioss") reads the figure.

    .venv/bin/python bench/tube_step.py --figure docs/tube_step.png [--decks DIR]
    .venv/bin/python bench/tube_step.py OUT [OUT_ISHELL1] --figure FIG

Without OUT it generates the tube deck (../shared/peer-decks/gen_shell.py tube --h 2.5,
Ishell 24 and 1) into a temporary folder and runs both (`rwall-fem run X_0000.rad`, the
Ishell 24 one with `--set output.fields=8`; some 2 minutes of CPU on one rank); with OUT it
reads those results (fields.xdmf/fields.h5 and energy.csv). For each snapshot it computes
every cell's step from its nodes, 0.9 L_c / sqrt(E / rho), with QEPH's L_c (CZCORC1 and
CNDT3's sqrt(1 + dn^2) - dn, dn = 0.015) and CDLEN3's (Ishell 1, on the projection),
prints the smallest against the run's step, and draws the run's step against time beside
OpenRadioss's mean steps (4 ms over its cycles) and the last snapshot's cells coloured by
their QEPH step.
"""

from __future__ import annotations

import argparse
import json
import math
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import h5py
import numpy as np

E, RHO, SCALE, DN = 210e9, 7850.0, 0.9, 0.015
OPENRADIOSS_CYCLES = {"Ishell 24": 21666, "Ishell 1": 19651, "Ishell 24, self-contact": 18127}
END = 4e-3


def frame_coordinates(x):
    """The in-plane coordinates (n, 4) of the cells x (n, 4, 3) about their centroids, in
    the frame of the normal d13 x d24 (OpenRadioss's CLSKEW3 / CNVEC3 normal)."""
    c = x.mean(axis=1, keepdims=True)
    n = np.cross(x[:, 2] - x[:, 0], x[:, 3] - x[:, 1])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    r = x[:, 1] + x[:, 2] - x[:, 0] - x[:, 3]
    e1 = r - np.sum(r * n, axis=1, keepdims=True) * n
    e1 /= np.linalg.norm(e1, axis=1, keepdims=True)
    e2 = np.cross(n, e1)
    d = x - c
    return np.einsum("nik,nk->ni", d, e1), np.einsum("nik,nk->ni", d, e2)


def projected_area(X, Y):
    """The area (m^2) of the cells with in-plane coordinates X, Y (n, 4): half the cross
    product of the diagonals."""
    return 0.5 * ((X[:, 2] - X[:, 0]) * (Y[:, 3] - Y[:, 1])
                  - (X[:, 3] - X[:, 1]) * (Y[:, 2] - Y[:, 0]))


def qeph_length(X, Y):
    """CZCORC1's L_c times CNDT3's sqrt(1 + dn^2) - dn (m)."""
    area = projected_area(X, Y)
    l13 = 0.25 * ((X[:, 0] - X[:, 2]) ** 2 + (Y[:, 0] - Y[:, 2]) ** 2)
    l24 = 0.25 * ((X[:, 1] - X[:, 3]) ** 2 + (Y[:, 1] - Y[:, 3]) ** 2)
    hs = np.maximum(np.abs(X[:, 1] * Y[:, 3] - Y[:, 1] * X[:, 3]),
                    np.abs(X[:, 0] * Y[:, 2] - Y[:, 0] * X[:, 2])) / area  # fmt: skip
    c1 = np.hypot(X[:, 1] + X[:, 2] - X[:, 0] - X[:, 3], Y[:, 1] + Y[:, 2] - Y[:, 0] - Y[:, 3])
    c2 = np.hypot(X[:, 2] + X[:, 3] - X[:, 0] - X[:, 1], Y[:, 2] + Y[:, 3] - Y[:, 0] - Y[:, 1])
    fac1 = 1.0 + np.minimum(0.5, 0.25 * (np.maximum(c1, c2) / np.minimum(c1, c2) - 1.0))
    f = 3.413 * np.maximum(0.0, 4.0 * area / (c1 * c2) - 0.7071)
    faci = 2.0 * fac1 * (0.78 + 0.22 * f**3)
    s1 = np.maximum(np.sqrt(faci * (1.25 + hs) * np.maximum(l13, l24)), 1e-300)
    return area / s1 * (math.sqrt(1 + DN**2) - DN)


def cdlen3_length(X, Y):
    """CDLEN3's L_c (m): max(A / longest diagonal, shortest side or diagonal)."""
    area = projected_area(X, Y)
    pairs = [(0, 1), (1, 2), (2, 3), (3, 0), (0, 2), (1, 3)]
    l2 = np.stack([(X[:, j] - X[:, i]) ** 2 + (Y[:, j] - Y[:, i]) ** 2 for i, j in pairs])
    return np.sqrt(np.maximum(area**2 / np.maximum(l2[4], l2[5]), l2.min(axis=0)))


def snapshots(out: Path):
    """(time, node positions (m), cells) of each snapshot in out/fields.xdmf."""
    text = (out / "fields.xdmf").read_text()
    with h5py.File(out / "fields.h5", "r") as h5:
        X = h5[re.search(r"fields\.h5:(/\S+/geometry)<", text).group(1)][...]
        cells = h5[re.search(r"fields\.h5:(/\S+/topology)<", text).group(1)][...]
        grids = re.findall(r'<Time Value="([^"]+)"\s*/>(.*?)</Grid>', text, re.S)
        for t, grid in grids:
            m = re.search(r'Attribute Name="displacement".*?fields\.h5:(/[^<\s]+)', grid, re.S)
            if m is None:
                continue
            u = h5[m.group(1)][...]
            yield float(t), X + u[:, :3], cells


ROOT = Path(__file__).resolve().parents[1]


def run_decks(decks: Path, folder: Path) -> tuple[Path, Path]:
    """Generate the tube deck with Ishell 24 and 1 into ``folder``, run both there, and
    return their results directories (the first with 8 snapshots of the fields)."""
    outs = []
    for name, ishell, extra in (("tube", "24", ["--set", "output.fields=8"]), ("tube1", "1", [])):
        subprocess.run([sys.executable, str(decks / "gen_shell.py"), "tube", "--h", "2.5",
                        "--ishell", ishell, "--name", name, "--out", str(folder)],
                       check=True, capture_output=True)  # fmt: skip
        out = folder / f"out_{name}"
        deck = str(folder / f"{name}_0000.rad")
        command = [sys.executable, "-m", "rwall_fem", "run", deck, "--quiet", "--out", str(out)]
        subprocess.run(command + extra, check=True)
        outs.append(out)
    return outs[0], outs[1]


def main():
    """Run the decks (or read their results), print and draw."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("out", type=Path, nargs="?",
                    help="results of the tube deck, Ishell 24, with fields (default: run it)")
    ap.add_argument("ishell1", type=Path, nargs="?", help="results of the Ishell 1 deck")
    ap.add_argument("--decks", type=Path, default=ROOT.parent / "shared" / "peer-decks")
    ap.add_argument("--figure", type=Path)
    a = ap.parse_args()
    if a.out is None:
        with tempfile.TemporaryDirectory() as tmp:
            a.out, a.ishell1 = run_decks(a.decks, Path(tmp))
            report(a)
    else:
        report(a)


def report(a):
    c = math.sqrt(E / RHO)
    run = np.genfromtxt(a.out / "energy.csv", delimiter=",", names=True)
    last = None
    print("time (ms)  run's dt (ns)  QEPH rule (ns)  CDLEN3 rule (ns)  cell at (mm)")
    for t, x, cells in snapshots(a.out):
        X, Y = frame_coordinates(x[cells])
        dt_q = SCALE * qeph_length(X, Y) / c
        dt_b = SCALE * cdlen3_length(X, Y) / c
        k = int(np.argmin(dt_q))
        i = int(np.argmin(np.abs(run["time"] - t)))
        where = ", ".join(f"{v * 1e3:.1f}" for v in x[cells[k]].mean(axis=0))
        print(f"{t * 1e3:8.3f}  {run['dt'][i] * 1e9:12.1f}  {dt_q.min() * 1e9:14.1f}  "
              f"{dt_b.min() * 1e9:16.1f}  ({where})")  # fmt: skip
        last = (t, x, cells, dt_q)
    for name, cycles in OPENRADIOSS_CYCLES.items():
        print(f"OpenRadioss {name}: {cycles} cycles, mean step {END / cycles * 1e9:.1f} ns")
    for name, out in (("Ishell 24", a.out), ("Ishell 1", a.ishell1)):
        if out is not None:
            print(f"rwall_fem {name}: {_cycles(out)} cycles, mean step "
                  f"{END / _cycles(out) * 1e9:.1f} ns")  # fmt: skip
    if a.figure:
        _figure(a, run, last)


def _cycles(out: Path) -> int:
    """The run's number of steps."""
    return json.loads((out / "summary.json").read_text())["steps"]


def _figure(a, run, last):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax, bx) = plt.subplots(1, 2, figsize=(11, 4.2))
    label = "rwall_fem, Ishell {} ({} cycles)"
    ax.plot(run["time"] * 1e3, run["dt"] * 1e9, label=label.format(24, _cycles(a.out)))
    if a.ishell1:
        r1 = np.genfromtxt(a.ishell1 / "energy.csv", delimiter=",", names=True)
        ax.plot(r1["time"] * 1e3, r1["dt"] * 1e9, label=label.format(1, _cycles(a.ishell1)))
    for (name, cycles), style in zip(OPENRADIOSS_CYCLES.items(), ("--", ":", "-.")):
        ax.axhline(END / cycles * 1e9, color="k", ls=style, lw=0.8,
                   label=f"OpenRadioss {name}: mean of {cycles} cycles")  # fmt: skip
    ax.set_xlabel("time (ms)")
    ax.set_ylabel("step (ns)")
    ax.legend(fontsize=7)
    ax.set_title("the step of the peer tube deck (no self-contact)", fontsize=9)
    t, x, cells, dt_q = last
    centre = x[cells].mean(axis=1)
    angle = np.arctan2(centre[:, 1] - 0.025, centre[:, 0] - 0.025)
    sc = bx.scatter(np.degrees(angle), centre[:, 2] * 1e3, c=dt_q * 1e9, s=6, cmap="viridis_r",
                    vmax=float(np.percentile(dt_q, 50) * 1e9))  # fmt: skip
    fig.colorbar(sc, ax=bx, label="cell's step, QEPH rule (ns)")
    bx.set_xlabel("angle about the tube's axis (degrees)")
    bx.set_ylabel("height of the cell's centre (mm)")
    bx.set_title(f"cells at {t * 1e3:.2f} ms, by OpenRadioss's QEPH rule", fontsize=9)
    fig.tight_layout()
    fig.savefig(a.figure, dpi=80)
    print(f"figure: {a.figure}")


if __name__ == "__main__":
    main()
