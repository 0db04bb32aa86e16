"""Time histories of a run: ``energy.csv``, ``walls.csv`` and ``summary.json``.

At each sample every rank puts its share of what is booked (energies, works, wall
impulses and contacts, whether it received SIGTERM) into named arrays that one
``Allreduce`` sums; the energy balance (:mod:`~rwall_fem.output.energy`), the wall
table (:mod:`~rwall_fem.output.wall_table`) and the guards
(:mod:`~rwall_fem.output.guards`) then read the same sums on every rank.

Rows are written in whole lines, at least every ``FLUSH_SECONDS`` of wall time and when
the run ends or stops, so a killed run leaves complete lines up to its last flush.
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np

from rwall_fem.output.energy import EnergyBalance, initial_kinetic_energy
from rwall_fem.output.guards import Guards
from rwall_fem.output.schedule import Every
from rwall_fem.output.summary import momentum, run_summary, write_summary
from rwall_fem.output.tables import CsvTable
from rwall_fem.output.wall_table import WALL_COLUMNS, WallTable

__all__ = ["FLUSH_SECONDS", "History"]

FLUSH_SECONDS = 1.0  # longest wall time between writes of the CSV files, s


class History:
    """Recorder of the energies and wall forces every ``every`` steps (and at the last
    step) of ``sim``, into ``directory``; it writes the run summary when closed.

    :attr:`energy` and :meth:`wall` give the samples as arrays, :attr:`summary` the
    summary once the run has ended; :attr:`balance` is the energy balance.
    """

    def __init__(self, sim, directory: Path, *, every: int, guards: Guards, plot: bool = False):
        self.directory = Path(directory)
        self.steps = Every(every, sim.num_steps)
        self.guards = guards
        self.plot = plot  # draw histories.png at the end
        comm, walls = sim.comm, sim.walls
        self.initial_momentum = momentum(sim.state, walls, comm)
        self.balance = EnergyBalance(
            initial_kinetic_energy(sim.state, walls, comm),
            stored=("kinetic", *sim.internal.energy_names),
            parts=sim.internal.energy_parts,
        )
        self.wall_table = WallTable(walls)
        self.summary: dict | None = None
        self._energy_csv = CsvTable(self.directory / "energy.csv", self.balance.columns, comm)
        self._walls_csv = CsvTable(self.directory / "walls.csv", WALL_COLUMNS, comm)
        self._tables = [self._energy_csv] + ([self._walls_csv] if walls else [])
        self._written_at = time.monotonic()
        self._sums = _Sums(
            comm,
            {name: () for name in (*self.balance.stored, *self.balance.parts)}
            | {"external_work": (), "wall_work": (len(walls), 2), "terminate": ()}
            | self.wall_table.sums,
        )

    def due(self, step: int) -> bool:
        return step in self.steps

    def record(self, sim, s) -> None:
        """Sample step ``s.step`` after its update: the kinetic energy K^n is the update's,
        the works are booked up to step n."""
        local = self._sums.local
        local["kinetic"][...] = s.kinetic
        for name, value in sim.internal.energies(s).items():
            local[name][...] = value
        local["external_work"][...] = (
            sum(f.work(s) for f in sim.forces)
            + sum(w.driving_work for w in sim.walls)
            + sum(b.work for b in sim.boundaries)
        )
        for i, w in enumerate(sim.walls):
            local["wall_work"][i] = w.normal_work, w.friction_work
        # Sent with the sums, so that every rank stops at the same step when any got SIGTERM.
        local["terminate"][...] = sim.terminate_requested
        self.wall_table.fill(local)
        total = self._sums.reduce()

        energies = {
            name: float(total[name]) for name in (*self.balance.stored, *self.balance.parts)
        }
        for w in sim.walls:
            if w.motion.dynamic:  # the same on every rank: not part of the sum
                kinetic = 0.5 * w.motion.mass * w.motion.previous_velocity @ w.motion.velocity
                energies["kinetic"] += kinetic
        energies["external_work"] = float(total["external_work"])
        energies["wall_work"] = float(total["wall_work"].sum())
        row = self.balance.sample(s.t, energies)
        self._energy_csv.rows.append(row)
        self._walls_csv.rows += self.wall_table.rows(s, total)
        if time.monotonic() - self._written_at > FLUSH_SECONDS:
            self._flush()
        self.guards.check(
            s, self.balance.error, finite=self._sums.finite(), terminate=bool(total["terminate"])
        )

    def checkpoint_state(self) -> dict[str, np.ndarray]:
        """The energy balance, the wall table, the momentum of the start and how many rows
        ``energy.csv`` and ``walls.csv`` have; both files are flushed first, so that they
        hold those rows when the checkpoint exists."""
        self._flush()
        rows = [len(self._energy_csv.rows), len(self._walls_csv.rows)]
        arrays = {"initial_momentum": self.initial_momentum, "rows": np.array(rows)}
        arrays |= {f"balance_{k}": v for k, v in self.balance.checkpoint_state().items()}
        return arrays | {f"walls_{k}": v for k, v in self.wall_table.checkpoint_state().items()}

    def restore_state(self, arrays: dict[str, np.ndarray]) -> None:
        """Also reads back the rows of ``energy.csv`` and ``walls.csv`` up to the checkpoint
        and drops those after it; ValueError if the files do not hold them, or if the
        energy row of the checkpoint's step is not the one in the file."""
        self.initial_momentum = arrays["initial_momentum"].copy()
        self.balance.restore_state(
            {k.removeprefix("balance_"): v for k, v in arrays.items() if k.startswith("balance_")}
        )
        self.wall_table.restore_state(
            {k.removeprefix("walls_"): v for k, v in arrays.items() if k.startswith("walls_")}
        )
        energy_rows, wall_rows = arrays["rows"].tolist()
        self._energy_csv.resume(energy_rows)
        self._walls_csv.resume(wall_rows)
        latest = self._energy_csv.rows[-1] if energy_rows else ()
        if list(latest) != arrays["balance_latest"].tolist():
            raise ValueError(
                f"{self._energy_csv.path}: row {energy_rows} is not the checkpoint's (the file "
                "was changed, or is another run's)"
            )

    def _flush(self) -> None:
        self._written_at = time.monotonic()
        for table in self._tables:
            table.flush()

    @property
    def energy(self) -> np.ndarray:
        """Energy samples as an array with the columns of ``energy.csv``."""
        return np.array(self._energy_csv.rows)

    def wall(self, i: int) -> np.ndarray:
        """Samples of wall ``i`` as an array with the columns of ``walls.csv``."""
        return np.array([r for r in self._walls_csv.rows if r[1] == i])

    def close(self, sim) -> None:
        """Write ``summary.json`` and the rows not yet written, close the CSV files (rank 0)
        and draw ``histories.png`` if asked."""
        peaks = self.wall_table.peak_contacts
        self.summary = run_summary(sim, self.balance, peaks, self.initial_momentum)
        for table in self._tables:
            table.close()
        if sim.comm.rank == 0:
            write_summary(self.directory, self.summary)
            if self.plot and self._energy_csv.rows:
                from rwall_fem.output.plots import plot_histories

                plot_histories(self.directory)


class _Sums:
    """Named arrays of given shapes packed in one buffer, summed over the ranks of ``comm``
    by one ``Allreduce``: :attr:`local` is this rank's share, :attr:`total` the sums."""

    def __init__(self, comm, shapes: dict[str, tuple]):
        self.comm = comm
        sizes = [math.prod(shape) for shape in shapes.values()]
        self._local, self._total = np.zeros(sum(sizes)), np.zeros(sum(sizes))
        ends = np.cumsum(sizes)
        self.local, self.total = {}, {}
        for (name, shape), size, end in zip(shapes.items(), sizes, ends, strict=True):
            self.local[name] = self._local[end - size : end].reshape(shape)
            self.total[name] = self._total[end - size : end].reshape(shape)

    def reduce(self) -> dict[str, np.ndarray]:
        self.comm.Allreduce(self._local, self._total)
        return self.total

    def finite(self) -> bool:
        """Whether every sum is finite (a NaN or Inf anywhere on any rank makes one not)."""
        return bool(np.isfinite(self._total).all())
