"""Time histories of a run: ``energy.csv``, ``walls.csv`` and ``summary.json``.

At each sample every rank puts its share of what is booked (energies, works, wall
impulses and contacts, which stop signals it received) into named arrays that one
``Allreduce`` sums; the energy balance (:mod:`~rwall_fem.output.energy`), the wall
table (:mod:`~rwall_fem.output.wall_table`) and the guards
(:mod:`~rwall_fem.output.guards`) then read the same sums on every rank.

Rows stream to disk (:mod:`~rwall_fem.output.tables`) in whole lines, at least every
``FLUSH_SECONDS`` of wall time and when the run ends or stops, so a killed run leaves
complete lines up to its last flush, and memory stays flat however long the run.

Samples are due every ``history_interval`` steps or, with ``history_time``, at the first
step at or after each multiple of that time (:mod:`~rwall_fem.output.schedule`), and at the
first and the last step (a stop by the time step, a guard or a signal included). A step
that is not a sample costs a comparison of times here: what is booked between samples is booked by the
effects themselves (works and impulses are integrals summed every step; energies and
forces are read at the samples), and the ranks, which agree on the time, agree on the
samples without exchanging a word.

Stop signals (SIGTERM, SIGINT) are honoured within about ``POLL_SECONDS`` of wall time
whatever the history's interval is: between samples the ranks also agree, at steps they
all derive from the measured time per step, on whether any of them received one (one
small ``Allreduce``); if so the step becomes a sample and the run stops there. Open
MPI's ``mpirun`` sends SIGTERM one second before SIGKILL: that second is enough.
"""

from __future__ import annotations

import contextlib
import math
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

from rwall_fem import interrupts
from rwall_fem.output import OutputError
from rwall_fem.output.energy import TINY, WORKS, EnergyBalance, initial_kinetic_energy
from rwall_fem.output.guards import Guards
from rwall_fem.output.schedule import Every, Interval
from rwall_fem.output.summary import momentum, reserve_summary, run_summary, write_summary
from rwall_fem.output.tables import CsvTable
from rwall_fem.output.units import column_scales, summary_in
from rwall_fem.output.wall_table import WALL_COLUMNS, WallTable
from rwall_fem.units import SI, UnitSystem

__all__ = ["FLUSH_SECONDS", "POLL_SECONDS", "History", "history_schedule"]

FLUSH_SECONDS = 1.0  # longest wall time between writes of the CSV files, s
POLL_SECONDS = 0.1  # longest wall time between agreements on stop signals, s
SIGNALS = ("SIGTERM", "SIGINT")  # the stop requests the ranks agree on


def history_schedule(output) -> Every | Interval:
    """When the rows are due, from the scene's ``[output]``: at the multiples of
    ``history_time`` (s) if given, else every ``history_interval`` steps."""
    if output.history_time is not None:
        return Interval(output.history_time)
    return Every(output.history_interval)


class History:
    """Recorder of the energies and wall forces of ``sim`` into ``directory`` when its
    ``schedule`` says (and at the last step); it writes the run summary when closed.

    :attr:`energy` and :meth:`wall` read the samples back from the files as arrays
    (collective calls; in the files' ``units``), :attr:`summary` is the summary once the
    run has ended (SI);
    :attr:`balance` is the energy balance.
    """

    def __init__(self, sim, directory: Path, *, schedule: Every | Interval, guards: Guards,
                 plot: bool = False, units: UnitSystem = SI):  # fmt: skip
        self.directory = Path(directory)
        self.units = units  # of the files (:mod:`~rwall_fem.output.units`); SI in memory
        self.steps = schedule
        self.guards = guards
        self.plot = plot  # draw histories.png at the end
        comm, walls = sim.comm, sim.walls
        rigid = self.rigid = sim.rigid_bodies
        self.initial_momentum = momentum(sim.state, walls, comm, rigid)
        self.mass_scaling = getattr(sim.step_size, "mass_scaling", None)
        scaled = self.mass_scaling is not None
        self.erosion = getattr(sim.internal, "erosion", None)  # cells that may erode
        self.step_changes = getattr(sim.internal, "corrects", False)  # a varying step's
        self.damping = [f for f in sim.forces if getattr(f, "column", None) == "damping_work"]
        booked = {"external_work": True, "wall_work": True, "damping_work": bool(self.damping),
                  "mass_scaling_work": scaled, "step_change_work": self.step_changes}  # fmt: skip
        works = [name for name in WORKS if booked[name]]
        # A body of [[part]]s: the energies of each part, which add up to the body's.
        explicit = getattr(sim.internal, "explicit", False)
        self.part_columns = sim.internal.part_columns() if explicit else ()
        self.contacts = sim.contacts
        contact_energies = ("contact_energy", "contact_friction") if sim.contacts else ()
        self.balance = EnergyBalance(
            initial_kinetic_energy(sim.state, walls, comm, rigid),
            stored=("kinetic", *(("rigid_body",) if rigid else ()), *sim.internal.energy_names,
                    *contact_energies),  # fmt: skip
            parts=sim.internal.energy_parts,
            works=works,
            extras=(("added_mass", "added_mass_percent") if scaled else ())
            + (("eroded_cells",) if self.erosion is not None else ())
            + self.part_columns,
        )
        self.wall_table = WallTable(walls)
        self.summary: dict | None = None
        self._energy_csv = CsvTable(self.directory / "energy.csv", self.balance.columns, comm,
                                    column_scales(self.balance.columns, "energy", units))
        self._walls_csv = CsvTable(self.directory / "walls.csv", WALL_COLUMNS, comm,
                                   column_scales(WALL_COLUMNS, "walls", units))  # fmt: skip
        self._tables = [self._energy_csv] + ([self._walls_csv] if walls else [])
        self._contacts_csv = None
        if sim.contacts:
            from rwall_fem.contact.interface import CONTACT_COLUMNS

            self._contacts_csv = CsvTable(self.directory / "contacts.csv", CONTACT_COLUMNS,
                                          comm, column_scales(CONTACT_COLUMNS, "walls", units))
            self._tables.append(self._contacts_csv)
        self._written_at = time.monotonic()
        self._sums = _Sums(
            comm,
            {name: () for name in (*self.balance.stored, *self.balance.parts)}
            | {"external_work": (), "wall_work": (len(walls), 2), "mass_scaling_work": ()}
            | {"damping_work": ()}
            | {"step_change_work": (), "eroded_cells": (), "parts": (len(self.part_columns),)}
            | {"signals": (len(SIGNALS),), "seconds": (), "failed": ()}
            | {f"contact[{i}]": () for i in range(len(sim.contacts))}
            | self.wall_table.sums,
        )
        self._poll = _Sums(comm, {"signals": (len(SIGNALS),), "seconds": (), "failed": ()})
        self._failure: OutputError | None = None  # an output that rank 0 could not write
        self._next_poll = 0  # the next step at which the ranks agree on stop signals
        # Step and wall time of the latest agreement (none yet: since the history was built).
        self._last: tuple[int, float] | None = None
        self._built = time.perf_counter()
        self._drawing: subprocess.Popen | None = None

    def start(self, sim) -> None:
        """Write ``summary.json`` as the run starts (or resumes): ``status`` "running",
        with room for the final summary, so that a disk that fills during the run cannot
        keep the run's verdict from being written (collective; a failure to write it
        ends the run at the ranks' next agreement)."""
        summary = run_summary(sim, self.balance, self.wall_table.peak_contacts,
                              self.initial_momentum)  # fmt: skip
        summary |= {"status": "running", "reason": None}
        if sim.comm.rank == 0:
            try:
                reserve_summary(self.directory, summary_in(summary, self.units))
            except OutputError as err:
                self.write_failed(err)

    def due(self, s) -> bool:
        return self.steps.due(s) or s.step >= self._next_poll

    def record(self, sim, s) -> None:
        """Sample step ``s.step`` after its update: the kinetic energy K^n is the update's,
        the works are booked up to step n. Between samples, only agree on stop signals;
        the step becomes a sample if any rank received one, or if the step size is about
        to stop the run."""
        if time.monotonic() - self._written_at > FLUSH_SECONDS:
            self._flush()
        stopping = sim.step_size.stop_reason is not None
        if not (self.steps.due(s) or stopping) and not self._stop_requested(sim, s):
            return
        self.steps.taken(s)
        local = self._sums.local
        rigid = self.rigid
        local["kinetic"][...] = (s.kinetic - sum(r.nodal_kinetic(s) for r in rigid) if rigid
                                 else s.kinetic)  # fmt: skip
        for name, value in sim.internal.energies(s).items():
            local[name][...] = value
        if sim.contacts:
            books = [c.energies() for c in sim.contacts]
            for name in ("contact_energy", "contact_friction"):
                local[name][...] = sum(b[name] for b in books)
            for i, b in enumerate(books):
                local[f"contact[{i}]"][...] = b["contact_energy"]
        local["external_work"][...] = (
            sum(f.work(s) for f in sim.forces if f not in self.damping)
            + sum(w.driving_work for w in sim.walls)
            + sum(b.work for b in sim.boundaries)
            + sum(r.gravity_work(s) for r in self.rigid)
        )
        for i, w in enumerate(sim.walls):
            local["wall_work"][i] = w.normal_work, w.friction_work
        local["damping_work"][...] = sum(f.work(s) for f in self.damping)
        if self.mass_scaling is not None:
            local["mass_scaling_work"][...] = self.mass_scaling.work
        if self.step_changes:
            local["step_change_work"][...] = sim.internal.step_change_work()
        if self.erosion is not None:
            local["eroded_cells"][...] = self.erosion.count
        if self.part_columns:
            local["parts"][:] = sim.internal.part_values(s)
        # Sent with the sums, so that every rank stops at the same step when any got a signal.
        self._fill_agreement(local, sim)
        self.wall_table.fill(local)
        total = self._sums.reduce()
        self._plan_next_poll(s, total)
        self._stop_if_failed(total)

        energies = {
            name: float(total[name]) for name in (*self.balance.stored, *self.balance.parts)
        }
        for w in sim.walls:
            if w.motion.dynamic:  # the same on every rank: not part of the sum
                kinetic = 0.5 * w.motion.mass * w.motion.previous_velocity @ w.motion.velocity
                energies["kinetic"] += kinetic
        if self.rigid:  # the same on every rank: not part of the sum
            energies["rigid_body"] = sum(r.kinetic for r in self.rigid)
        energies["external_work"] = float(total["external_work"])
        energies["wall_work"] = float(total["wall_work"].sum())
        if self.damping:
            energies["damping_work"] = float(total["damping_work"])
        extras = dict(zip(self.part_columns, total["parts"].tolist(), strict=True))
        if self.step_changes:
            energies["step_change_work"] = float(total["step_change_work"])
        if self.mass_scaling is not None:
            energies["mass_scaling_work"] = float(total["mass_scaling_work"])
            extras |= {
                "added_mass": self.mass_scaling.added,
                "added_mass_percent": self.mass_scaling.added_percent,
            }
        if self.erosion is not None:
            extras["eroded_cells"] = int(total["eroded_cells"])
        self._energy_csv.append(self.balance.sample(s.t, energies, s.dt, extras))
        for row in self.wall_table.rows(s, total):
            self._walls_csv.append(row)
        for i, contact in enumerate(sim.contacts):
            energy = float(total[f"contact[{i}]"])
            self._contacts_csv.append(contact.row(s.t, i, energy))
        received = total["signals"].tolist()
        signals = tuple(name for name, n in zip(SIGNALS, received, strict=True) if n)
        self.guards.check(
            s,
            self.balance.error,
            finite=self._sums.finite(),
            signals=signals,
            step_work=energies.get("step_change_work", 0.0) / max(self.balance.reference, TINY),
        )

    def _fill_agreement(self, local: dict, sim) -> None:
        """This rank's stop signals, its wall time since the latest agreement (s) and
        whether it failed to write an output."""
        local["signals"][:] = [name in sim.stop_requests for name in SIGNALS]
        local["seconds"][...] = time.perf_counter() - (self._last or (0, self._built))[1]
        failed = self._failure or next((t.error for t in self._tables if t.error), None)
        local["failed"][...] = failed is not None

    def write_failed(self, error: OutputError) -> None:
        """An output of this rank could not be written (rank 0 writes most alone): the
        run ends at the next agreement of the ranks, within ``POLL_SECONDS``, on every
        rank with this error."""
        self._failure = self._failure or error

    def _stop_if_failed(self, total: dict) -> None:
        """Raise :class:`OutputError` on every rank when any failed to write an output."""
        if total["failed"]:
            failed = self._failure or next((t.error for t in self._tables if t.error), None)
            raise failed or OutputError("an output of another rank could not be written")

    def _plan_next_poll(self, s, total: dict) -> None:
        """The next agreement, about ``POLL_SECONDS`` of wall time ahead at the mean time
        per step since the latest one (the same on every rank: from the sums)."""
        steps = max(s.step - self._last[0], 1) if self._last else 1
        per_step = float(total["seconds"]) / self._sums.comm.size / steps
        ahead = POLL_SECONDS / per_step if per_step > 0 else 1.0
        self._next_poll = s.step + max(1, int(min(ahead, 1e9)))
        self._last = (s.step, time.perf_counter())

    def _stop_requested(self, sim, s) -> bool:
        """Agree with the other ranks on whether any received a stop signal (collective)."""
        self._fill_agreement(self._poll.local, sim)
        total = self._poll.reduce()
        self._plan_next_poll(s, total)
        self._stop_if_failed(total)
        return bool(total["signals"].any())

    def checkpoint_state(self) -> dict[str, np.ndarray]:
        """The energy balance, the wall table, the momentum of the start, how many rows
        ``energy.csv`` and ``walls.csv`` have and (``history_time``) the next multiple of
        the interval due; both files are flushed first, so that they
        hold those rows when the checkpoint exists (OutputError if they cannot be)."""
        self._flush()
        for table in self._tables:
            if table.error:
                raise table.error
        rows = [self._energy_csv.count, self._walls_csv.count]
        arrays = {"initial_momentum": self.initial_momentum, "rows": np.array(rows)}
        if isinstance(self.steps, Interval):
            arrays["next_row"] = np.array(self.steps.next)
        if self._contacts_csv is not None:
            arrays["contact_rows"] = np.array(self._contacts_csv.count)
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
        if isinstance(self.steps, Interval):
            self.steps.next = int(arrays["next_row"])
        energy_rows, wall_rows = arrays["rows"].tolist()
        latest = self._energy_csv.resume(energy_rows) or ()
        self._walls_csv.resume(wall_rows)
        if self._contacts_csv is not None:
            self._contacts_csv.resume(int(arrays["contact_rows"]))
        if list(latest) != list(self._energy_csv.in_units(arrays["balance_latest"].tolist())):
            raise ValueError(
                f"{self._energy_csv.path}: row {energy_rows} is not the checkpoint's (the file "
                "was changed, or is another run's)"
            )

    def _flush(self) -> None:
        """Write the pending rows; a file that cannot be written keeps its error, which
        the ranks agree on at the next sample or poll."""
        self._written_at = time.monotonic()
        for table in self._tables:
            with contextlib.suppress(OutputError):
                table.flush()

    @property
    def energy(self) -> np.ndarray:
        """Energy samples, read back from ``energy.csv``, with its columns (collective)."""
        return self._energy_csv.read()

    def contact(self, i: int) -> np.ndarray:
        """Samples of contact ``i``, read back from ``contacts.csv`` (collective)."""
        rows = self._contacts_csv.read()
        return rows[rows[:, 1] == i]

    def wall(self, i: int) -> np.ndarray:
        """Samples of wall ``i``, read back from ``walls.csv``, with its columns (collective)."""
        rows = self._walls_csv.read()
        return rows[rows[:, 1] == i]

    def close(self, sim) -> None:
        """Write ``summary.json`` and the rows not yet written, close the CSV files (rank 0)
        and draw ``histories.png`` if asked.

        The drawing runs in a process of its own session, so that it finishes even when
        this one is killed (Open MPI's ``mpirun`` sends SIGKILL one second after
        SIGTERM): after a stop signal it is not waited for here but in :meth:`wait`,
        once the caller has said that the run stopped.

        A file that cannot be written (a full disk) keeps none of the others from being
        written; the first such :class:`OutputError` is raised after them.
        """
        peaks = self.wall_table.peak_contacts
        self.summary = run_summary(sim, self.balance, peaks, self.initial_momentum)
        failures = []
        for table in self._tables:
            try:
                table.close()
            except OutputError as err:
                failures.append(err)
        if sim.comm.rank == 0:
            try:
                write_summary(self.directory, summary_in(self.summary, self.units))
            except OutputError as err:
                failures.append(err)
            if failures:
                raise failures[0]
            if self.plot and self._energy_csv.count:
                self._drawing = _draw_histories(self.directory)
                if not sim.stop_requests:
                    self.wait()

    def wait(self) -> None:
        """Wait for ``histories.png`` to be drawn; raises :class:`OutputError` if that failed."""
        drawing, self._drawing = self._drawing, None
        if drawing is None:
            return
        _, stderr = drawing.communicate()
        if drawing.returncode != 0:
            lines = stderr.strip().splitlines() or ["no message"]
            error = OutputError(f"drawing {self.directory / 'histories.png'} failed: {lines[-1]}")
            error.add_note(stderr[-2000:])
            raise error


def _draw_histories(directory: Path) -> subprocess.Popen:
    """Start drawing ``directory/histories.png`` (:mod:`rwall_fem.output.plots`) in a new
    session, without the MPI variables of this process."""
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMI", "PMIX"))}
    code = "import sys; from rwall_fem.output.plots import plot_histories as p; p(sys.argv[1])"
    drawing = subprocess.Popen(
        [sys.executable, "-c", code, str(directory)],
        env=env,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    interrupts.adopt(drawing.pid)  # a stop signal after the time loop stops it too
    return drawing


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
        if self.comm.size == 1:  # the sums are this rank's
            self._total[:] = self._local
        else:
            self.comm.Allreduce(self._local, self._total)
        return self.total

    def finite(self) -> bool:
        """Whether every sum is finite (a NaN or Inf anywhere on any rank makes one not)."""
        return bool(np.isfinite(self._total).all())
