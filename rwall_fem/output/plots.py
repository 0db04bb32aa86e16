"""``histories.png``: energies and wall forces over time, drawn from the CSV files."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from rwall_fem.output.atomic import whole
from rwall_fem.output.energy import WORKS

__all__ = ["balance_curve", "plot_histories"]


def balance_curve(energy: np.ndarray) -> np.ndarray:
    """The energy balance over time (J) from the rows of ``energy.csv`` (a structured
    array): every stored energy (``total_energy``: hourglass, rotational, contact and rigid
    bodies' too) less every work booked; the initial energy, to the balance error."""
    works = [name for name in WORKS if name in energy.dtype.names]
    return energy["total_energy"] - sum(energy[name] for name in works)


def plot_histories(directory: str | Path) -> Path:
    """Draw ``energy.csv`` (and ``walls.csv``) of ``directory`` into ``histories.png``."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    directory = Path(directory)
    energy = np.genfromtxt(directory / "energy.csv", delimiter=",", names=True, ndmin=1)
    walls_file = directory / "walls.csv"
    walls = None
    if walls_file.is_file():
        walls = np.genfromtxt(walls_file, delimiter=",", names=True, ndmin=1)
    rows = 2 if walls is not None and walls.size else 1
    figure, axes = plt.subplots(rows, 1, figsize=(8, 3.2 * rows), sharex=True, squeeze=False)
    t = energy["time"] * 1e3
    ax = axes[0, 0]
    rigid = ("rigid_body",) if "rigid_body" in energy.dtype.names else ()
    for name in ("kinetic", *rigid, "internal", "external_work", "wall_work"):
        ax.plot(t, energy[name], label=name.replace("_", " "))
    ax.plot(t, balance_curve(energy), "k--", label="stored energies - works")
    ax.set_ylabel("energy (J)")
    ax.legend(fontsize=8, loc="best")
    ax.set_title(f"max |balance error| {np.abs(energy['balance_error']).max():.1e}", fontsize=9)
    if rows == 2:
        ax = axes[1, 0]
        for wall in np.unique(walls["wall"]).astype(int):
            row = walls[walls["wall"] == wall]
            normal = np.sqrt(sum(row[f"normal_force_{c}"] ** 2 for c in "xyz"))
            tangential = np.sqrt(sum(row[f"tangential_force_{c}"] ** 2 for c in "xyz"))
            ax.plot(row["time"] * 1e3, normal, label=f"wall[{wall}] |normal force|")
            if tangential.any():
                ax.plot(row["time"] * 1e3, tangential, label=f"wall[{wall}] |tangential force|")
        ax.set_ylabel("force (N)")
        ax.legend(fontsize=8, loc="best")
    axes[-1, 0].set_xlabel("time (ms)")
    figure.tight_layout()
    path = directory / "histories.png"
    with whole(path) as partial:
        figure.savefig(partial, dpi=110)
    plt.close(figure)
    return path
