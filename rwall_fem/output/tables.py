"""CSV files that a killed run leaves readable: rows are written in whole lines.

Every rank keeps the rows in memory (they are the same on every rank: sums over
ranks); rank 0 appends the rows not yet written when the table is flushed.
"""

from __future__ import annotations

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

    def close(self) -> None:
        """Write what is left and close the file."""
        self.flush()
        if self._file is not None:
            self._file.close()


def _line(row) -> str:
    """A CSV line of the numbers in ``row``: integers as such, floats as their shortest
    exact decimal."""
    return ",".join(repr(x) if isinstance(x, int) else repr(float(x)) for x in row) + "\n"
