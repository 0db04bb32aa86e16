"""CSV files that a killed run leaves readable: rows are written in whole lines.

Every rank keeps the rows in memory (they are the same on every rank: sums over
ranks); rank 0 appends the rows not yet written when the table is flushed. A resumed
run reads back the rows up to its checkpoint (:meth:`CsvTable.resume`).
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

__all__ = ["CsvTable"]


class CsvTable:
    """Rows with the columns ``columns``, written to ``path`` by rank 0 of ``comm``."""

    def __init__(self, path: Path, columns: Sequence[str], comm):
        self.path, self.columns, self.comm = Path(path), list(columns), comm
        self.rows: list[tuple] = []
        self._written = 0  # rows already in the file
        self._file = None

    def flush(self) -> None:
        """Append the rows not yet written as whole lines and flush the file (rank 0); the
        first flush creates the directory and the file with its header."""
        if self.comm.rank != 0:
            return
        if self._file is None:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self._file = open(self.path, "w")
            self._file.write(",".join(self.columns) + "\n")
        start, self._written = self._written, len(self.rows)
        self._file.write("".join(_line(r) for r in self.rows[start:]))
        self._file.flush()

    def resume(self, count: int) -> None:
        """Continue the table of a resumed run after the first ``count`` rows of its file:
        they are read back (on rank 0, then sent to every rank), and the rows after them,
        written after the checkpoint, are dropped from the file by replacing it whole.
        Raises ValueError (one line, the same on every rank) when the file lacks them."""
        rows, error = [], None
        if self.comm.rank == 0 and count:
            try:
                rows = _read_rows(self.path, self.columns, count)
                temporary = self.path.with_name(self.path.name + ".partial")
                with open(temporary, "w") as file:
                    file.write(",".join(self.columns) + "\n" + "".join(_line(r) for r in rows))
                    file.flush()
                    os.fsync(file.fileno())
                os.replace(temporary, self.path)
                self._file = open(self.path, "a")
            except (OSError, ValueError) as err:
                error = f"{self.path}: {err.strerror}" if isinstance(err, OSError) else str(err)
        rows, error = self.comm.bcast((rows, error), root=0)
        if error:
            raise ValueError(error)
        self.rows, self._written = rows, count

    def close(self) -> None:
        """Write what is left and close the file."""
        self.flush()
        if self._file is not None:
            self._file.close()


def _read_rows(path: Path, columns: Sequence[str], count: int) -> list[tuple]:
    """The first ``count`` rows of the CSV file ``path``, each a whole line with the
    ``columns``; numbers read back exactly (integers as int)."""
    lines = path.read_text().split("\n")
    if lines[0] != ",".join(columns):
        raise ValueError(f"{path}: its columns are not those of this run")
    if len(lines) < count + 2:  # the header, the rows, and what follows their last newline
        raise ValueError(f"{path}: holds {max(len(lines) - 2, 0)} rows; the checkpoint has {count}")
    try:
        rows = [tuple(map(_number, line.split(","))) for line in lines[1 : count + 1]]
    except ValueError:
        raise ValueError(f"{path}: a row of the first {count} is not numbers") from None
    if any(len(r) != len(columns) for r in rows):
        raise ValueError(f"{path}: a row of the first {count} has not {len(columns)} columns")
    return rows


def _number(text: str) -> int | float:
    return int(text) if text.lstrip("-").isdigit() else float(text)


def _line(row) -> str:
    """A CSV line of the numbers in ``row``: integers as such, floats as their shortest
    exact decimal."""
    return ",".join(repr(x) if isinstance(x, int) else repr(float(x)) for x in row) + "\n"
