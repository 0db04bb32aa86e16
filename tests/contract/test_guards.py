"""Run guards and what a stopped run leaves behind (Radioss /STOP, LS-DYNA ENDENG)."""

import csv
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from conftest import SCENE, bar_scene, mpi_launch, run
from mpi4py import MPI

from rwall_fem import build_simulation, parse_scene
from rwall_fem.output.wall_table import WALL_COLUMNS

# time, kinetic, internal, hourglass, external and wall work, balance error, total energy,
# error in %, dt (the default element is a one-point hexahedron with hourglass control)
ENERGY_COLUMNS = 10


def complete_rows(path: Path, columns: int) -> list[list[float]]:
    """Every line of a CSV file, each checked to be complete and numeric."""
    rows = list(csv.reader(open(path)))
    assert all(len(r) == columns for r in rows)
    return [[float(x) for x in r] for r in rows[1:]]


def test_nan_in_the_state_stops_the_run_and_names_the_node(shared_dir):
    sim = build_simulation(
        parse_scene(bar_scene(elements=10), source="test"), MPI.COMM_WORLD, shared_dir
    )
    if MPI.COMM_WORLD.rank == 0:
        sim.state.v[0, 2] = np.nan  # what an instability leaves behind
    status = sim.run()
    assert status.startswith("stopped: step 0, t = 0 s: NaN or Inf in the nodal state")
    assert "first bad node" in status and " m" in status
    if MPI.COMM_WORLD.rank == 0:
        summary = json.loads((Path(shared_dir) / "summary.json").read_text())
        assert summary["status"] == "stopped" and "NaN" in summary["reason"]
        complete_rows(Path(shared_dir) / "energy.csv", ENERGY_COLUMNS)


def test_energy_error_guard(shared_dir):
    raw = bar_scene(elements=10)
    raw["run"]["max_energy_error"] = 1e-300  # any round-off trips it
    sim = run(raw, shared_dir)
    assert "energy balance error" in sim.status and "exceeds run.max_energy_error" in sim.status
    assert "fastest node" in sim.status and "|v| = " in sim.status
    assert sim.history.summary["status"] == "stopped"
    assert len(sim.history.energy) < sim.planned_steps + 1


# The same bar, run for a second of simulated time (about 10^7 steps): it is stopped first.
LONG = SCENE.replace("end_time = 2e-5", "end_time = 1.0").replace("frames = 3", "frames = 0")


def _start_long_run(tmp_path, *extra, launch=(), env=None, ready=20000):
    """Start the long run (on ``launch``'s ranks, if given) into ``tmp_path/out``; return
    once energy.csv holds ``ready`` bytes."""
    (tmp_path / "scene.toml").write_text(LONG)
    if env is None:
        env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMI", "PMIX"))}
    process = subprocess.Popen(
        [*launch, sys.executable, "-m", "rwall_fem", "run", "scene.toml", "--out", "out",
         "--quiet", *extra],
        cwd=tmp_path,
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )  # fmt: skip
    energy = tmp_path / "out" / "energy.csv"
    deadline = time.monotonic() + 120
    while not (energy.exists() and energy.stat().st_size > ready):
        assert process.poll() is None and time.monotonic() < deadline
        time.sleep(0.2)
    return process


def _stopped_cleanly(out: Path, stderr: str, reason: str) -> dict:
    """One line on stderr naming ``reason``; the summary says stopped, with the steps done
    (those of the last row of energy.csv, fewer than planned); histories.png drawn."""
    assert stderr.strip().startswith("rwall-fem: stopped: step ")
    assert reason in stderr and len(stderr.strip().splitlines()) == 1, stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "stopped" and reason in summary["reason"]
    rows = complete_rows(out / "energy.csv", ENERGY_COLUMNS)
    assert summary["energy"]["kinetic"] == rows[-1][1] and summary["time"] == rows[-1][0]
    assert summary["steps"] == round(rows[-1][0] / summary["dt"]) < summary["planned_steps"]
    complete_rows(out / "walls.csv", len(WALL_COLUMNS))
    deadline = time.monotonic() + 60  # drawn by a process of its own, which may outlive mpirun
    while not (out / "histories.png").exists():
        assert time.monotonic() < deadline
        time.sleep(0.2)
    return summary


@pytest.mark.serial
def test_sigterm_stops_cleanly_and_writes_the_summary(tmp_path):
    process = _start_long_run(tmp_path)
    process.send_signal(signal.SIGTERM)
    _, stderr = process.communicate(timeout=120)
    assert process.returncode == 3
    _stopped_cleanly(tmp_path / "out", stderr, "terminated by SIGTERM")


@pytest.mark.serial
def test_ctrl_c_stops_cleanly_like_sigterm(tmp_path):
    process = _start_long_run(tmp_path)
    process.send_signal(signal.SIGINT)
    _, stderr = process.communicate(timeout=120)
    assert process.returncode == 3 and "Traceback" not in stderr
    _stopped_cleanly(tmp_path / "out", stderr, "interrupted (SIGINT, Ctrl-C)")


@pytest.mark.serial
def test_a_stop_does_not_wait_for_the_next_history_sample(tmp_path):
    """With a row every 10^6 steps, the run still stops within a fraction of a second of
    SIGTERM: the step it stops at (fewer than 10^6) becomes the last row."""
    process = _start_long_run(tmp_path, "--set", "output.history_interval=1000000", ready=100)
    time.sleep(1.0)
    process.send_signal(signal.SIGTERM)
    _, stderr = process.communicate(timeout=120)
    assert process.returncode == 3
    summary = _stopped_cleanly(tmp_path / "out", stderr, "terminated by SIGTERM")
    assert 0 < summary["steps"] < 1000000


@pytest.mark.serial
def test_sigterm_to_the_mpi_launcher_stops_every_rank_cleanly(tmp_path):
    """SIGTERM to ``mpirun`` (Open MPI: SIGCONT, then SIGTERM to the ranks one second
    later, then SIGKILL one second after that) or ``mpiexec`` (MPICH forwards SIGTERM):
    the message, the summary and histories.png all come. MPICH's ``mpiexec`` exits with
    the ranks' 3; Open MPI's ``mpirun`` exits 1 after a signal whatever they return."""
    launch, env = mpi_launch(2)
    process = _start_long_run(tmp_path, launch=launch, env=env)
    process.send_signal(signal.SIGTERM)
    _, stderr = process.communicate(timeout=120)
    ours = "\n".join(line for line in stderr.splitlines() if line.startswith("rwall-fem:"))
    _stopped_cleanly(tmp_path / "out", ours, "terminated by SIGTERM")
    assert process.returncode == (3 if launch[0].endswith("mpiexec") else 1)


def test_a_simulation_runs_once(shared_dir):
    sim = run(bar_scene(elements=4), shared_dir)
    with pytest.raises(RuntimeError, match=r"already run \(done\); build a new one"):
        sim.run()


@pytest.mark.serial
def test_sigkill_leaves_complete_csv_lines(tmp_path):
    process = _start_long_run(tmp_path)
    process.kill()
    process.communicate(timeout=60)
    rows = complete_rows(tmp_path / "out" / "energy.csv", ENERGY_COLUMNS)
    assert len(rows) > 100
    # The summary written at the start still says the run was under way: never "done".
    assert json.loads((tmp_path / "out" / "summary.json").read_text())["status"] == "running"


def test_an_error_before_the_first_sample_is_raised_as_itself(shared_dir):
    """The run fails at step 0: the error itself reaches the caller, and the summary of
    the outputs (no sample yet) says how the run ended."""
    sim = build_simulation(
        parse_scene(bar_scene(elements=4), source="test"), MPI.COMM_WORLD, shared_dir
    )

    def broken(state):
        raise ArithmeticError("the force broke")

    sim.internal.accelerate = broken
    with pytest.raises(ArithmeticError, match="the force broke"):
        sim.run()
    summary = sim.history.summary
    assert summary["status"] == "failed" and "the force broke" in summary["reason"]
    assert summary["energy"]["kinetic"] is None


def test_pictures_that_fail_to_render_leave_the_other_outputs(shared_dir, monkeypatch, capsys):
    """The renderer fails: the command line says so in one line and exits 4; the summary
    and the CSV files are written all the same."""
    import rwall_fem.output.frames
    from rwall_fem.cli import main

    def failed_render(args, **kwargs):
        return subprocess.CompletedProcess(args, 1, "", "Traceback\nRuntimeError: no display")

    monkeypatch.setattr(rwall_fem.output.frames.subprocess, "run", failed_render)
    monkeypatch.setenv("RWALL_FEM_RENDER", "inline")  # the renderer started after the loop
    out = Path(shared_dir)
    if MPI.COMM_WORLD.rank == 0:
        (out / "scene.toml").write_text(SCENE)
    MPI.COMM_WORLD.Barrier()
    code = main(["run", str(out / "scene.toml"), "--out", str(out / "run"), "--quiet"])
    if MPI.COMM_WORLD.rank == 0:  # rank 0 renders
        assert code == 4
        err = capsys.readouterr().err.strip().splitlines()
        frames = out / "run" / "frames"
        assert err == [f"rwall-fem: error: outputs: rendering the frames into {frames} failed: "
                       "RuntimeError: no display"]  # fmt: skip
        summary = json.loads((out / "run" / "summary.json").read_text())
        assert summary["status"] == "done"
        complete_rows(out / "run" / "energy.csv", ENERGY_COLUMNS)
