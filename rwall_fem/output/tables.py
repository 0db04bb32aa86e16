"""CSV files that stream to disk and that a killed run leaves readable.

Rank 0 keeps the rows as they come, at most ``PENDING_LINES`` of them (or what
:meth:`CsvTable.flush` has not yet written): memory stays flat however long the run.
The pending rows are turned into lines together (one ``repr`` of them all) and go to
the file in one write followed by a flush, so the file only ever holds whole lines.
Other ranks keep nothing (the rows are sums over ranks, the same everywhere). A resumed
run keeps the rows up to its checkpoint (:meth:`CsvTable.resume`).
"""

from __future__ import annotations

import contextlib
import itertools
import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from rwall_fem.output import OutputError

__all__ = ["PENDING_LINES", "CsvTable"]

PENDING_LINES = 1000  # rows kept before they are written, whatever the time since the last


class CsvTable:
    """Rows with the columns ``columns``, written to ``path`` by rank 0 of ``comm``, each
    value times its column's ``scales`` if given (another unit system than SI's)."""

    def __init__(self, path: Path, columns: Sequence[str], comm, scales=None):
        self.path, self.columns, self.comm = Path(path), list(columns), comm
        self.scales = scales
        self.count = 0  # rows so far
        self.error: OutputError | None = None  # why the file could not be written (rank 0)
        self._pending: list[str] = []
        self._file = None
        self._closed = False

    def append(self, row: Sequence) -> None:
        """Add a row (numbers: integers are written as such, others as floats); it is
        written at the next :meth:`flush`, or now when ``PENDING_LINES`` rows are waiting."""
        self.count += 1
        if self.comm.rank != 0:
            return
        self._pending.append(self.in_units(row))
        if len(self._pending) >= PENDING_LINES:
            with contextlib.suppress(OutputError):  # kept in :attr:`error`
                self.flush()

    def in_units(self, row: Sequence) -> Sequence:
        """``row`` as the file holds it: each float times its column's scale."""
        if self.scales is None:
            return row
        return [x * k if isinstance(x, float) else x for x, k in zip(row, self.scales, strict=True)]

    def flush(self, create: bool = False) -> None:
        """Write the pending lines and flush the file (rank 0); the first flush with lines
        to write (or ``create``) creates the directory and the file with its header.

        When the file cannot be written (a full disk), what part of the lines reached it
        is cut off, so that it ends with a whole line, nothing more is written to it, and
        :class:`~rwall_fem.output.OutputError` names it (on rank 0 alone: the caller
        makes the ranks agree), now and in :attr:`error`."""
        if self.comm.rank != 0 or self._closed or not (self._pending or self._file or create):
            return
        whole = 0  # the size of the file up to its last whole line, bytes
        try:
            if self._file is None:
                self.path.parent.mkdir(parents=True, exist_ok=True)
                self._file = open(self.path, "w")
                self._file.write(",".join(self.columns) + "\n")
                self._file.flush()
            whole = self._file.tell()
            self._file.write(_lines(self._pending))
            self._file.flush()
        except OSError as err:
            self._give_up(whole)
            self.error = OutputError(
                f"{self.path}: cannot be written ({err.strerror}); it ends with the last "
                "whole row written"
            )
            raise self.error from None
        self._pending.clear()

    def _give_up(self, whole: int) -> None:
        """Cut the file after its last whole line (at least ``whole`` bytes, what it held
        before the failed write) and write no more to it."""
        self._closed = True
        self._pending.clear()
        if self._file is None:
            return
        with contextlib.suppress(OSError):  # its buffer cannot be written: whatever is, is cut
            self._file.close()
        self._file = None
        with contextlib.suppress(OSError), open(self.path, "rb+") as file:
            file.seek(whole)
            file.truncate(whole + file.read().rfind(b"\n") + 1)

    def resume(self, count: int) -> tuple | None:
        """Continue the table of a resumed run after the first ``count`` rows of its file;
        the rows after them, written after the checkpoint, are dropped by replacing the
        file whole (rank 0, line by line). Returns the last row kept (None: none), read
        back exactly, on every rank. Raises ValueError (one line, the same on every rank)
        when the file lacks them."""
        last, error = None, None
        if self.comm.rank == 0 and count:
            temporary = self.path.with_name(self.path.name + ".partial")
            try:
                last = _copy_rows(self.path, temporary, self.columns, count)
                os.replace(temporary, self.path)
                self._file = open(self.path, "a")
            except (OSError, ValueError) as err:
                error = f"{self.path}: {err.strerror}" if isinstance(err, OSError) else str(err)
                temporary.unlink(missing_ok=True)
        last, error = self.comm.bcast((last, error), root=0)
        if error:
            raise ValueError(error)
        self.count = count
        return last

    def close(self) -> None:
        """Write what is left and close the file (made, with its header, if no row came)."""
        self.flush(create=True)
        if self._file is not None:
            self._file.close()
        self._closed = True

    def read(self) -> np.ndarray:
        """Every row written so far, as an array (rows, columns), on every rank: rank 0
        flushes and reads the file, the others receive it (collective)."""
        rows = None
        if self.comm.rank == 0:
            self.flush(create=True)
            rows = np.loadtxt(self.path, delimiter=",", skiprows=1, ndmin=2)
            rows = rows.reshape(-1, len(self.columns))
        return self.comm.bcast(rows, root=0)


def _copy_rows(path: Path, target: Path, columns: Sequence[str], count: int) -> tuple:
    """Copy the header and the first ``count`` rows of the CSV file ``path`` to ``target``
    (on disk when this returns), each checked to be a whole line of numbers with the
    ``columns``; returns the last, read back exactly (integers as int)."""
    header = ",".join(columns)
    kept, last = 0, None
    with open(path) as source, open(target, "w") as copy:
        if source.readline().rstrip("\n") != header:
            raise ValueError(f"{path}: its columns are not those of this run")
        copy.write(header + "\n")
        for line in source:
            if kept == count or not line.endswith("\n"):  # enough, or a line cut by a kill
                break
            try:
                last = tuple(map(_number, line.rstrip("\n").split(",")))
            except ValueError:
                raise ValueError(f"{path}: a row of the first {count} is not numbers") from None
            if len(last) != len(columns):
                raise ValueError(
                    f"{path}: a row of the first {count} has not {len(columns)} columns"
                )
            copy.write(line)
            kept += 1
        if kept < count:
            raise ValueError(f"{path}: holds {kept} rows; the checkpoint has {count}")
        copy.flush()
        os.fsync(copy.fileno())
    return last


def _number(text: str) -> int | float:
    return int(text) if text.lstrip("-").isdigit() else float(text)


def _lines(rows: list[Sequence]) -> str:
    """The CSV lines of ``rows`` of numbers: integers as such, floats as their shortest
    exact decimal (``repr``). Rows of Python ints and floats alone, as the history
    makes them, are turned into text by one ``repr`` of them all."""
    if not rows:
        return ""
    rows = [list(row) for row in rows]
    if not set(map(type, itertools.chain.from_iterable(rows))) <= {int, float}:
        rows = [[x if isinstance(x, int) else float(x) for x in row] for row in rows]
    return repr(rows)[2:-2].replace("], [", "\n").replace(", ", ",") + "\n"
