"""``rwall-fem study --quick``: output structure, and errors that shrink with refinement.

Timings are never checked (another job may share the machine); the errors are, against
the independent references of :mod:`rwall_fem.study.cases` (1-D wave theory, the exponential
decay of a heavy wall on a free bar).
"""

import csv

import numpy as np
import pytest
from mpi4py import MPI

from rwall_fem.study import CASES, run_study

# The study measures wall time against accuracy on one rank; its runs are the same scenes
# that the rest of the suite runs on 2 ranks. Running it twice would double the suite's
# longest test for nothing new.
pytestmark = pytest.mark.serial


@pytest.fixture(scope="module")
def quick(tmp_path_factory):
    """One quick study for the whole module, in a directory every rank sees."""
    comm = MPI.COMM_WORLD
    path = tmp_path_factory.mktemp("study") if comm.rank == 0 else None
    path = comm.bcast(path, root=0)
    rows = run_study(path, quick=True, comm=comm, echo=None)
    return path, rows


def test_quick_study_writes_csv_table_summary_and_plots(quick):
    path, rows = quick
    for name in ["study.csv", "study.md", "summary.md"] + [f"study_{c}.png" for c in CASES]:
        assert (path / name).is_file(), name
    with open(path / "study.csv") as f:
        table = list(csv.DictReader(f))
    assert len(table) == len(rows)
    for column in ["case", "cell", "dt_scale", "element_size", "cells", "steps", "dt",
                   "wall_seconds", "ns_per_cell_step", "wall_share", "balance_error"]:  # fmt: skip
        assert column in table[0], column
    assert {r["cell"] for r in table} == {"tetrahedron", "hexahedron"}
    assert {float(r["dt_scale"]) for r in table} == {0.5, 0.9}
    summary = (path / "summary.md").read_text()
    assert "1 % rebound velocity error" in summary and "halving it costs" in summary
    assert (path / "study_bar.png").read_bytes()[:4] == b"\x89PNG"


def test_every_rank_has_the_same_rows(quick):
    _, rows = quick
    comm = MPI.COMM_WORLD
    assert comm.allgather(repr(rows)) == [repr(rows)] * comm.size


@pytest.mark.parametrize(
    "case, quantities",
    [("bar", ["rebound", "impulse", "duration"]), ("moving_wall", ["wall_velocity"])],
)
def test_errors_shrink_with_refinement(quick, case, quantities):
    _, rows = quick
    for cell in ("tetrahedron", "hexahedron"):
        for dt_scale in (0.5, 0.9):
            series = sorted(
                (
                    r
                    for r in rows
                    if (r["case"], r["cell"], r["dt_scale"]) == (case, cell, dt_scale)
                ),
                key=lambda r: -r["element_size"],
            )
            assert len(series) >= 3
            assert np.all(np.diff([r["cells"] for r in series]) > 0)
            for key in quantities:
                errors = np.abs([r[f"error_{key}"] for r in series])
                # O(h): the finest run is at least 1.5x better than the coarsest.
                assert errors[-1] < errors[0] / 1.5, (cell, dt_scale, key, errors)
            for r in series:
                assert r["balance_error"] < 1e-9
                assert 0.0 < r["wall_share"] < 0.2
