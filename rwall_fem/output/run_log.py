"""``run.log``: what a Radioss user reads in 0000.out/0001.out, an LS-DYNA user in d3hsp.

Written by rank 0 into the results folder: the code and library versions, the command,
the ranks, the scene as it ran (every key, defaults and ``--set`` overrides applied),
the mesh, the time step and the effects, the warnings of the build, then a cycle line
every ``output.print_interval`` steps, or 21 times over the run (cycle, time, dt, energy
balance error in %, elapsed wall time, and the cell that controls the step: its
calibrated stable step and where it is, as Radioss's listing names the element) and the
final figures. :class:`CycleLines` prints the same cycle
lines to a stream (the command line's stderr when it is not a terminal), so batch and
MPI logs show progress.
"""

from __future__ import annotations

import contextlib
import dataclasses
import json
import logging
import shlex
import socket
import sys
import time
from pathlib import Path
from typing import TextIO

from rwall_fem.output import OutputError
from rwall_fem.output.projection import CycleSteps, StepCollapse, steps_left
from rwall_fem.output.schedule import Every, Times

__all__ = ["CycleLines", "RunLog", "cycle_schedule", "scene_text"]

log = logging.getLogger("rwall_fem")

_HEADER = (
    f"{'cycle':>10} {'time (s)':>12} {'dt (s)':>11} {'energy error %':>15} {'elapsed (s)':>12}"
    f" {'steps left':>11} {'left (s)':>10} {'limit (s)':>11}  controlling cell"
)


def cycle_schedule(end_time: float, every: int | None) -> CycleSteps:
    """When cycle lines are written: every ``every`` steps, or 21 times over the run (s)
    and at least every 1/20 of the steps planned (:class:`CycleSteps`)."""
    return CycleSteps(Every(every) if every else Times(21, end_time))


class _Pace:
    """The wall time per step (s) since the first cycle line, for the time left."""

    def __init__(self):
        self.started, self.step = None, 0

    def elapsed(self, s) -> float:
        if self.started is None:
            self.started, self.step = time.perf_counter(), s.step
        return time.perf_counter() - self.started

    def left(self, steps: int, s, elapsed: float) -> str:
        """The wall time (s) ``steps`` more steps take at the pace so far, in words."""
        done = s.step - self.step
        return f"{steps * elapsed / done:.4g}" if done > 0 else "-"


def _cycle_line(sim, s, elapsed: float, pace: _Pace) -> str:
    """A cycle line; "steps left" and "left (s)": the steps to the end at the current step
    and the wall time they take at the pace so far (:mod:`rwall_fem.output.projection`)."""
    error = sim.history.balance.error if sim.history is not None else None
    percent = "-" if error is None else f"{100.0 * error:.4g}"
    left = steps_left(sim, s)
    line = (f"{s.step:>10d} {s.t:>12.5e} {s.dt:>11.4e} {percent:>15} {elapsed:>12.1f}"
            f" {left:>11d} {pace.left(left, s, elapsed):>10}")  # fmt: skip
    cell = sim.step_size.controlling_cell()
    if cell is None:
        return line
    where = ", ".join(f"{c:.4g}" for c in cell[1])
    part = f" in part {cell[3]}" if cell[3] else ""
    return f"{line} {cell[0]:>11.4e}  at ({where}) m{part}"


class CycleLines:
    """Recorder that prints a cycle line to ``stream`` when ``schedule`` (of
    :func:`cycle_schedule`) says, under a header line. It runs on one rank, after the run
    log at the same steps (which finds the controlling cell, a collective call)."""

    def __init__(self, stream: TextIO, schedule: Every | Times):
        self.stream, self.steps = stream, schedule
        self._pace = _Pace()

    def due(self, s) -> bool:
        return self.steps.due(s)

    def record(self, sim, s) -> None:
        self.steps.taken(sim, s)
        if self._pace.started is None:
            print(f"rwall-fem: {_HEADER}", file=self.stream, flush=True)
        line = _cycle_line(sim, s, self._pace.elapsed(s), self._pace)
        print(f"rwall-fem: {line}", file=self.stream, flush=True)

    def close(self, sim) -> None:
        """Nothing to close."""


class RunLog:
    """Recorder of ``directory/run.log`` (rank 0 of ``comm``): the header when the run
    starts, a cycle line when ``schedule`` (of :func:`cycle_schedule`) says, the final
    figures when it ends. ``facts`` are lines on what was built (mesh, step, walls,
    warnings); ``frames`` the number of frames rendered after the time loop (said, on the
    log and on the logger, when it ends). :attr:`ended_at` is when it closed
    (``time.perf_counter``)."""

    def __init__(self, directory: Path, scene, facts: list[str], *, schedule, comm, frames=0):
        self.path = Path(directory) / "run.log"
        self.scene, self.facts, self.comm = scene, facts, comm
        self.steps, self.frames = schedule, frames
        self.ended_at = None
        self._file = None
        self._pace = _Pace()
        self._collapse = StepCollapse()  # warns once when the step collapses
        self._failed = False  # the file could not be written: it is written no more

    def due(self, s) -> bool:
        return self.steps.due(s)

    def record(self, sim, s) -> None:
        """A cycle line (rank 0). A log that cannot be written (a full disk) is no longer
        written, and the history ends the run on every rank (it makes them agree)."""
        self.steps.taken(sim, s)
        sim.step_size.controlling_cell()  # collective: on every rank, for the cycle lines
        warning = self._collapse.check(sim, s)  # collective when it warns
        if self.comm.rank != 0 or self._failed:
            return
        try:
            if self._file is None:
                self._start(sim)
            line = _cycle_line(sim, s, self._pace.elapsed(s), self._pace)
            self._write(line if warning is None else f"{line}\nwarning: {warning}")
        except OutputError as err:
            sim.history.write_failed(err)

    def write(self, line: str) -> None:
        """Add ``line`` to the log (rank 0; after the run, the file is opened again)."""
        if self.comm.rank != 0 or self._failed:
            return
        if self._file is None:
            try:
                with open(self.path, "a") as file:
                    file.write(line + "\n")
            except OSError as err:
                raise self._failure(err) from None
        else:
            self._write(line)

    def _write(self, text: str) -> None:
        try:
            self._file.write(text + "\n")
            self._file.flush()
        except OSError as err:
            raise self._failure(err) from None

    def _failure(self, err: OSError) -> OutputError:
        """The error of a log that cannot be written, which is then written no more."""
        self._failed = True
        if self._file is not None:
            with contextlib.suppress(OSError):
                self._file.close()
            self._file = None
        return OutputError(f"{self.path}: cannot be written ({err.strerror})")

    def _start(self, sim) -> None:
        from rwall_fem import __version__
        from rwall_fem.provenance import git_hash, library_versions

        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self._file = open(self.path, "a" if sim.first_step else "w")  # a resume continues
        except OSError as err:
            raise self._failure(err) from None
        versions = ", ".join(f"{k} {v}" for k, v in library_versions().items())
        resumed = ["", f"resumed at step {sim.first_step}"] if sim.first_step else []
        lines = [
            *resumed,
            f"rwall-fem {__version__} (git {git_hash() or 'unknown: not a git checkout'})",
            f"started {time.strftime('%Y-%m-%d %H:%M:%S %z')} on {socket.gethostname()}, "
            f"{self.comm.size} MPI rank(s)",
            f"command: {shlex.join(sys.argv)}",
            f"versions: {versions}",
            "",
            f"scene {self.scene.source}, as it runs (defaults and overrides applied):",
            *("    " + line for line in scene_text(self.scene).splitlines()),
            "",
            *self.facts,
            "",
            f"cycles ({self._when()}; energy error of the latest sample; steps left and "
            "left (s): to the end at the current step and at the pace so far; limit: the "
            "stable step of the controlling cell):",
            _HEADER,
        ]
        self._write("\n".join(lines))

    def _when(self) -> str:
        if isinstance(self.steps.schedule, Every):
            return f"a line every {self.steps.k} steps"
        return "21 lines over the run, and one at least every 1/20 of the steps planned"

    def close(self, sim) -> None:
        """Write the final figures of the run (the history's summary) and close the file."""
        self.ended_at = time.perf_counter()
        if self.frames:
            log.info("rendering %d frames after the time loop", self.frames)
        if self.comm.rank != 0 or self._failed:
            return
        if self._file is None:  # the run ended before its first step
            self._start(sim)
        summary = sim.history.summary if sim.history is not None else None
        self._write("")
        self._write(f"ended: {sim.status}")
        if summary is not None:
            e = summary["energy"]
            energies = ", ".join(
                f"{k} {v:.6g} J" for k, v in e.items() if k != "max_balance_error" and v is not None
            )
            self._write(
                f"steps: {summary['steps']} of {summary['planned_steps']} planned; "
                f"t = {summary['time']:.6g} s of {summary['end_time']:.6g} s; "
                f"time loop {sim.wall_seconds:.3f} s on rank 0"
            )
            self._write(f"energies: {energies}")
            self._write(f"max energy balance error: {e['max_balance_error']:.3e}")
            for w in summary["walls"]:
                impulse = ", ".join(f"{x:.6g}" for x in w["impulse"])
                self._write(
                    f"{w['name']}: impulse ({impulse}) N s, work {w['work']:.6g} J, "
                    f"peak contacts {w['peak_contacts']}"
                )
        if self.frames:
            self._write(f"rendering {self.frames} frames after the time loop")
        self._file.close()
        self._file = None


def scene_text(scene) -> str:
    """The scene as TOML-like text: every key with its value, defaults included; a key
    without a value is a comment."""
    from rwall_fem.scene.keys import Each, Sub, keys_of

    lines: list[str] = []

    def table(obj, cls, header: str | None) -> None:
        if header:
            lines.append(header)
        nested = []
        for name, (f, k) in keys_of(cls).items():
            if not _applies(obj, cls, name, k):
                continue
            value = getattr(obj, f.name)
            if dataclasses.is_dataclass(value):
                nested.append((name, value, type(value), False))
            elif isinstance(k.type, Each):
                nested += [(name, v, type(v), True) for v in value]
                if not value:
                    lines.append(f"# {name}: none")
            elif isinstance(value, tuple) and isinstance(k.type, Sub) and value:
                nested.append((name, _as_table(k.type.cls, value), None, False))
            elif value is None:
                lines.append(f"# {name}: none")
            else:
                lines.append(f"{name} = {_value(value)}")
        for name, value, sub, many in nested:
            path = f"{header.strip('[]')}.{name}" if header else name
            if sub is None:
                lines.append(f"[{path}]")
                lines.extend(f"{k} = {_value(v)}" for k, v in value.items())
            else:
                table(value, sub, f"[[{path}]]" if many else f"[{path}]")

    table(scene, type(scene), None)
    return "\n".join(lines)


def _applies(obj, cls, name: str, k) -> bool:
    """Whether the key ``name`` (a :class:`~rwall_fem.scene.keys.Key`) belongs to the table
    ``obj``: a key of its variant (a bar's keys, a plane's), under its ``when``."""
    variants = cls.__table__.variants
    if variants is not None and name != variants.on:
        chosen = getattr(obj, variants.on)
        if chosen is None and variants.instead is not None:
            keys = (variants.instead[0], *variants.instead[2])
        else:
            keys = (*variants.cases[chosen], *variants.common)
        if name not in keys:
            return False
    return all(
        getattr(obj, sibling) is None or getattr(obj, sibling) in allowed
        for sibling, allowed in k.when.items()
    )


def _as_table(cls, value: tuple) -> dict:
    """The table a Sub key was read from, given the tuple it became."""
    from rwall_fem.scene.keys import keys_of

    names = list(keys_of(cls))
    if cls.__table__.one_of:  # (which key, its value)
        return {value[0]: value[1]}
    if len(names) == 1:
        return {names[0]: value}
    return dict(zip(names, value, strict=True))


def _value(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, (str, Path)):
        return json.dumps(str(value))
    if isinstance(value, (tuple, list)):
        return "[" + ", ".join(_value(v) for v in value) + "]"
    return repr(value)
