"""CSV tables stream: rows reach the file as they are made, in whole lines, and nothing
but the few lines not yet written is kept (before: every row of the run stayed in
memory, about 1.3 kB per history sample)."""

import numpy as np
from mpi4py import MPI

from rwall_fem.output.tables import PENDING_LINES, CsvTable


def test_rows_reach_the_file_as_they_are_made(shared_dir):
    comm = MPI.COMM_WORLD
    path = shared_dir / "table.csv"
    table = CsvTable(path, ["step", "value"], comm)
    rows = [(i, 0.1 * i) for i in range(3 * PENDING_LINES + 7)]
    for row in rows:
        table.append(row)
    if comm.rank == 0:  # without a flush: all but the last few are on disk, in whole lines
        lines = path.read_text().splitlines()
        assert lines[0] == "step,value"
        assert len(lines) - 1 >= len(rows) - PENDING_LINES
        assert all(line == f"{i},{0.1 * i!r}" for i, line in enumerate(lines[1:]))
    table.close()
    assert table.count == len(rows)
    assert np.array_equal(table.read(), np.array(rows, dtype=float))  # on every rank
