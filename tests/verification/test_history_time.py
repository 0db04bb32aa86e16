"""Rows of the histories at the multiples of ``output.history_time`` (Radioss /TFILE,
LS-DYNA *DATABASE_GLSTAT dt) instead of every step.

The reference is the same scene with a row every step (``history_interval = 1``), whose
times are those of every step: a timed run must have a row at the first step at or after
each multiple k T of its interval, at the first step and at the last, and nowhere else.
Skipping rows changes no step, so at the rows both runs have the energies and works
are the same sums (to the bit); the wall and contact impulses are integrals booked every
step, so the last row's impulse is the every-step run's, and a row's force is the mean
force since the previous row: the every-step forces integrated over the steps between
the two rows, divided by the time between them.
"""

import copy

import numpy as np
import pytest
from conftest import bar_scene, run
from mpi4py import MPI
from test_contact import two_bars
from test_time_step import crush_scene

from rwall_fem import build_simulation, parse_scene
from rwall_fem.output.wall_table import WALL_COLUMNS

COLUMN = {name: k for k, name in enumerate(WALL_COLUMNS)}
IMPULSE = slice(COLUMN["impulse_x"], COLUMN["impulse_z"] + 1)
FORCE = slice(COLUMN["force_x"], COLUMN["force_z"] + 1)
INTERVAL = 4.1e-7  # s: 2.4 steps of the bar, so that rows are 2 or 3 steps apart
ERRORS = ("balance_error", "energy_error_percent")  # over E_ref, the largest at a row


def bar(**output) -> dict:
    """A 10 mm steel bar at 10 m/s on a plane wall, three wave transits."""
    raw = bar_scene(elements=10)
    raw["output"] |= output
    return raw


def expected_rows(times: np.ndarray, interval: float) -> np.ndarray:
    """Indices of the steps of ``times`` (s, every step) that a run with rows every
    ``interval`` (s) writes: the first, the first at or after each multiple, the last."""
    dt = np.diff(times).min()
    multiples = interval * np.arange(1, int(times[-1] / interval) + 1)
    picks = np.searchsorted(times, multiples - 1e-6 * dt)
    return np.unique([0, *picks, len(times) - 1])


def common_rows(every: np.ndarray, timed: np.ndarray) -> np.ndarray:
    """Rows of the every-step table ``every`` at the times of the rows of ``timed``."""
    rows = np.searchsorted(every[:, 0], timed[:, 0])
    assert np.array_equal(every[rows, 0], timed[:, 0])
    return rows


def mean_forces(every: np.ndarray, rows: np.ndarray) -> np.ndarray:
    """The every-step wall forces integrated over the steps since the previous row, over
    the time since then (N): what the timed run's rows after the first must show."""
    t = every[:, 0]
    steps = np.diff(t, prepend=np.nan)[:, None] * every[:, FORCE]
    return np.array([steps[a + 1 : b + 1].sum(axis=0) / (t[b] - t[a])
                     for a, b in zip(rows[:-1], rows[1:], strict=True)])  # fmt: skip


def test_rows_at_the_multiples_of_the_interval_keep_the_books(shared_dir):
    """Rows at the first step at or after each multiple of history_time, the first and
    the last step; the energy columns equal the every-step run's at those rows (to the
    bit: the same sums), the impulse at the end too, a row's force the mean since the
    previous row (to 1e-12 of the peak force)."""
    every = run(bar(history_interval=1), shared_dir / "every")
    timed = run(bar(history_time=INTERVAL), shared_dir / "timed")
    e_all, e_timed = every.history.energy, timed.history.energy
    steps = expected_rows(e_all[:, 0], INTERVAL)
    assert 10 < len(steps) < 0.5 * len(e_all)
    assert np.array_equal(e_timed[:, 0], e_all[steps, 0])
    rows = common_rows(e_all, e_timed)
    columns = timed.history.balance.columns
    for k, name in enumerate(columns):
        if name not in ERRORS:
            assert np.array_equal(e_timed[:, k], e_all[rows, k]), name
    balance = columns.index("balance_error")  # E_ref may differ by the rows skipped
    assert np.abs(e_timed[:, balance] - e_all[rows, balance]).max() <= 1e-14

    w_all, w_timed = every.history.wall(0), timed.history.wall(0)
    assert np.array_equal(w_timed[:, 0], e_timed[:, 0])
    assert np.array_equal(w_timed[-1, IMPULSE], w_all[-1, IMPULSE])
    # The bar has rebounded: about 2 m v on the wall (the rest is its vibration).
    assert w_all[-1, COLUMN["impulse_z"]] == pytest.approx(-2 * every.info["mass"] * 10.0, rel=0.05)
    peak = np.abs(w_all[:, FORCE]).max()
    assert np.abs(w_timed[1:, FORCE] - mean_forces(w_all, rows)).max() <= 1e-12 * peak
    assert timed.history.summary["steps"] == every.history.summary["steps"]


def test_contact_impulses_between_rows(shared_dir):
    """contacts.csv of two bars meeting head-on, a row every 5e-7 s: at the energy rows,
    the impulse at the end that of the run with a row every step (to the bit), the
    contact energies equal at the common rows."""
    raw = two_bars(shared_dir, end_time=1.2e-5)
    every = run(raw | {"output": raw["output"] | {"history_interval": 1}}, shared_dir / "ce")
    timed = run(raw | {"output": raw["output"] | {"history_time": 5e-7}}, shared_dir / "ct")
    c_all, c_timed = every.history.contact(0), timed.history.contact(0)
    assert np.array_equal(c_timed[:, 0], timed.history.energy[:, 0])
    assert len(c_timed) < 0.5 * len(c_all)
    rows = common_rows(c_all, c_timed)
    assert np.array_equal(c_timed[-1, 5:8], c_all[-1, 5:8])  # the impulse, N s
    assert abs(c_all[-1, 7]) > 0
    assert np.array_equal(c_timed[:, 10:], c_all[rows, 10:])  # energies, J


@pytest.mark.skipif(MPI.COMM_WORLD.size == 1, reason="compares a partitioned run with a serial one")
def test_rows_do_not_depend_on_the_ranks(shared_dir, tmp_path):
    """On N ranks and on one, the same rows (the ranks agree on them from the time alone),
    with the same values to 1e-10 of their scale."""
    raw = bar(history_time=INTERVAL)
    raw["mesh"]["size"] = [3e-3, 2e-3, 1e-2]  # several cells across: a real partition
    parallel = run(raw, shared_dir / "parallel")
    serial = run(raw, tmp_path, comm=MPI.COMM_SELF)
    e_par, e_ser = parallel.history.energy, serial.history.energy
    assert np.array_equal(e_par[:, 0], e_ser[:, 0])
    scale = serial.history.summary["energy"]["initial"]
    assert np.abs(e_par[:, 1:5] - e_ser[:, 1:5]).max() <= 1e-10 * scale
    w_par, w_ser = parallel.history.wall(0), serial.history.wall(0)
    assert np.abs(w_par[:, IMPULSE] - w_ser[:, IMPULSE]).max() <= 1e-10 * np.abs(
        w_ser[:, IMPULSE]).max()  # fmt: skip


class Killed(Exception):
    """What a kill does to a run, here at a chosen step."""


class KillAt:
    """Recorder that kills the run at ``step`` (before its update)."""

    def __init__(self, step):
        self.step = step

    def due(self, s):
        return s.step == self.step

    def record(self, sim, s):
        raise Killed

    def close(self, sim):
        pass


def test_a_resume_between_rows_equals_the_uninterrupted_run(shared_dir):
    """Killed after a checkpoint at a step that is not a row, resumed from it: energy.csv,
    walls.csv and summary.json are those of the run that never stopped (bit for bit)."""
    raw = bar(history_time=INTERVAL, checkpoint_steps=7)

    def build(directory):
        scene = parse_scene(copy.deepcopy(raw), source="test")
        return build_simulation(scene, MPI.COMM_WORLD, directory)

    whole = run(raw, shared_dir / "whole")
    out = shared_dir / "killed"
    sim = build(out)
    sim.recorders.append(KillAt(31))
    with pytest.raises(Killed):
        sim.run()
    resumed = build(out)
    resumed.checkpoints.resume(resumed)
    assert resumed.first_step == 29
    times = whole.history.energy[:, 0]
    assert resumed.state.t not in times  # step 28 wrote no row
    assert resumed.run() == "done"
    MPI.COMM_WORLD.Barrier()
    assert np.array_equal(resumed.state.u, whole.state.u)
    if MPI.COMM_WORLD.rank == 0:
        for name in ("energy.csv", "walls.csv"):
            assert (out / name).read_text() == (shared_dir / "whole" / name).read_text(), name
        a, b = resumed.history.summary, whole.history.summary
        assert {k: v for k, v in a.items() if k != "wall_seconds"} == {
            k: v for k, v in b.items() if k != "wall_seconds"
        }


def test_a_run_stopped_by_dt_min_ends_with_its_row(shared_dir):
    """The crushed copper bar stopped by run.dt_min: rows at the first step at or after
    0.4 us, and one at the step that stopped the run (its time is the
    summary's), between multiples."""
    raw = crush_scene(dt_min=1e-7)
    raw["output"] = {"plot": False, "history_time": 4e-7}
    sim = run(raw, shared_dir)
    assert sim.status.startswith("stopped") and "run.dt_min" in sim.status
    times = sim.history.energy[:, 0]
    assert times[-1] == sim.history.summary["time"] == sim.state.t
    reached = np.floor(times / 4e-7 + 1e-9)
    assert np.array_equal(reached[:-1], np.arange(len(times) - 1)) and len(times) > 6
    assert times[-1] - reached[-1] * 4e-7 > sim.state.dt  # the stop is no multiple's step
