"""Restart (Radioss /RFILE): checkpoints, ``run --resume``, and what a resume refuses.

The reference of a resumed run is the same scene run without a stop: the time loop is
deterministic on a given partition, so the outputs must be equal to the last bit
(tolerance 0), which is within any round-off.
"""

import copy
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from conftest import SCENE, StopAt, bar_scene
from mpi4py import MPI

import rwall_fem.checkpoint
import rwall_fem.output.frames
import rwall_fem.output.history
from rwall_fem import build_simulation, parse_scene
from rwall_fem.checkpoint import CheckpointError
from rwall_fem.cli import main
from rwall_fem.output import OutputError

# Every kind of state a step carries over: a hyperelastic body (an adaptive step that
# varies) with viscous hourglass control (accumulated energy), gravity, a driven face, a
# wall carried by a main node with filtered friction, and a sliding wall on a velocity
# history.
SCENE_WITH_STATE = {
    "run": {"end_time": 6e-5},
    "mesh": {
        "shape": "bar",
        "origin": [0.0, 0.0, 2e-4],
        "size": [0.004, 0.004, 0.012],
        "element_size": 0.002,
    },
    "material": {"model": "neo_hookean", "density": 7850.0, "young": 210e9, "poisson": 0.3},
    "element": {"hourglass": "viscous"},
    "initial": {"velocity": [1.0, 0.0, -10.0]},
    "gravity": {"acceleration": [0.0, 0.0, -9.81]},
    "boundary": [{"group": "top", "velocity": [1.0, 0.0, 0.0], "components": "x"}],
    "wall": [
        {
            "kind": "plane",
            "point": [0.0, 0.0, 0.0],
            "normal_point": [0.0, 0.0, 1.0],
            "slide": "friction",
            "friction": 0.3,
            "friction_filter": {"coefficient": 0.5},
            "motion": {"mass": 0.01, "velocity": [0.0, 0.0, 0.0]},
        },
        {
            "kind": "plane",
            "point": [0.0043, 0.0, 0.0],
            "normal_point": [-1.0, 0.0, 0.0],
            "motion": {"velocity": [[0.0, -5.0, 0.0, 0.0], [1e-4, -10.0, 0.0, 0.0]]},
        },
    ],
    "output": {
        "frames": 4,
        "fields": 3,
        "history_interval": 3,
        "plot": False,
        "checkpoint_steps": 7,
    },
}


class Killed(Exception):
    """What a kill does to a run, here at a chosen moment."""


def build(raw, directory, comm=MPI.COMM_WORLD):
    return build_simulation(parse_scene(copy.deepcopy(raw), source="test"), comm, directory)


def checkpoints(directory: Path) -> list[str]:
    return sorted(p.name for p in (directory / "checkpoint").iterdir())


def test_a_resumed_run_equals_an_uninterrupted_one(shared_dir, monkeypatch):
    """Stopped by SIGTERM, resumed, killed while writing a checkpoint, resumed again: the
    outputs and the final state are those of the run that never stopped (bit for bit)."""
    monkeypatch.setattr(  # frames are compared as data: no pictures
        rwall_fem.output.frames.subprocess,
        "run",
        lambda args, **kwargs: subprocess.CompletedProcess(args, 0, "", ""),
    )
    comm, root = MPI.COMM_WORLD, Path(shared_dir)
    whole = build(SCENE_WITH_STATE, root / "whole")
    assert whole.run() == "done"

    out = root / "stopped"
    sim = build(SCENE_WITH_STATE, out)
    sim.recorders.append(StopAt(74))  # during the impact on wall[0], steps 69 to 83
    # The ranks agree on stop signals at every sample and, between samples, about every
    # POLL_SECONDS of wall time: none between these samples, 3 steps apart.
    monkeypatch.setattr(rwall_fem.output.history, "POLL_SECONDS", 1e9)
    assert sim.run().startswith("stopped: step 75,")  # the next history sample
    comm.Barrier()
    assert checkpoints(out) == ["step_0000000075"]

    sim = build(SCENE_WITH_STATE, out)
    sim.checkpoints.resume(sim)
    assert sim.first_step == 76
    write = rwall_fem.checkpoint._write

    def killed_at_84(path, header, arrays):
        if header["step"] != 84:
            return write(path, header, arrays)
        path.write_bytes(b"PK\x03\x04")  # the start of a zip file, and then nothing
        raise Killed

    monkeypatch.setattr(rwall_fem.checkpoint, "_write", killed_at_84)
    with pytest.raises(Killed):
        sim.run()
    comm.Barrier()
    assert checkpoints(out) == ["partial", "step_0000000077"]
    energy_rows = (out / "energy.csv").read_text().splitlines()  # up to step 84
    whole_rows = (root / "whole" / "energy.csv").read_text().splitlines()
    assert len(energy_rows) == 1 + 84 // 3 + 1 and energy_rows == whole_rows[: len(energy_rows)]

    monkeypatch.setattr(rwall_fem.checkpoint, "_write", write)
    sim = build(SCENE_WITH_STATE, out)
    sim.checkpoints.resume(sim)
    assert sim.first_step == 78
    assert sim.run() == "done"
    comm.Barrier()

    assert np.array_equal(sim.state.u, whole.state.u)
    assert np.array_equal(sim.state.v, whole.state.v)
    a, b = whole.walls[0], sim.walls[0]
    assert (b.first_contact, b.last_contact) == (a.first_contact, a.last_contact)
    assert b.friction_work == a.friction_work
    assert comm.allreduce(b.friction_work) < 0
    assert np.array_equal(b.motion.offset, a.motion.offset) and a.motion.offset[2] < 0
    if comm.rank == 0:
        for name in ("energy.csv", "walls.csv", "fields.xdmf"):
            assert (out / name).read_text() == (root / "whole" / name).read_text(), name
        summaries = [json.loads((d / "summary.json").read_text()) for d in (root / "whole", out)]
        for summary in summaries:
            summary.pop("wall_seconds")
        assert summaries[0] == summaries[1]
        frames = sorted((root / "whole" / "frames" / "data").glob("*.npz"))
        assert [f.name for f in frames] == sorted(
            f.name for f in (out / "frames" / "data").glob("*.npz")
        )
        assert len(frames) == 5  # mesh.npz and 4 frames
        for path in frames:
            with np.load(path) as x, np.load(out / "frames" / "data" / path.name) as y:
                assert all(np.array_equal(x[k], y[k]) for k in x.files), path.name


def test_a_state_with_nan_keeps_the_last_good_checkpoint(shared_dir):
    raw = bar_scene(elements=4)
    raw["output"]["checkpoint_steps"] = 2

    class Spoil(StopAt):
        def record(self, sim, s):
            s.v[:1] = np.nan

    sim = build(raw, shared_dir)
    sim.recorders.append(Spoil(5))
    assert "NaN or Inf" in sim.run()
    MPI.COMM_WORLD.Barrier()
    assert checkpoints(Path(shared_dir)) == ["step_0000000004"]


def test_a_checkpoint_that_cannot_be_written_fails_the_run_on_every_rank(shared_dir):
    raw = bar_scene(elements=4)
    raw["output"]["checkpoint_steps"] = 2
    if MPI.COMM_WORLD.rank == 0:
        (Path(shared_dir) / "checkpoint").write_text("a file where the directory goes")
    MPI.COMM_WORLD.Barrier()
    sim = build(raw, shared_dir)
    with pytest.raises(OutputError, match=r"^checkpoint: .*checkpoint/partial: "):
        sim.run()
    assert sim.status.startswith("failed: OutputError") and sim.history.energy[-1][0] > 0


def test_a_resume_refuses_another_scene_outputs_that_lack_rows_or_none(shared_dir):
    raw = bar_scene(elements=4)
    raw["run"]["end_time"] = 1e-6
    out = Path(shared_dir)
    empty = build(raw, out / "empty")
    with pytest.raises(CheckpointError, match=r"empty/checkpoint: no checkpoint to resume from"):
        empty.checkpoints.resume(empty)

    raw["output"]["checkpoint_steps"] = 2
    assert build(raw, out / "run").run() == "done"
    other = copy.deepcopy(raw)
    other["wall"][0]["slide"] = "tied"
    other["output"]["checkpoint_steps"] = 3  # how often is free to change
    sim = build(other, out / "run")
    with pytest.raises(CheckpointError, match=r"another scene: wall\[0\]\.slide is 'tied', was "):
        sim.checkpoints.resume(sim)

    if MPI.COMM_WORLD.rank == 0:
        energy = out / "run" / "energy.csv"
        energy.write_text(energy.read_text().splitlines()[0] + "\n")
    MPI.COMM_WORLD.Barrier()
    sim = build(raw, out / "run")
    with pytest.raises(CheckpointError, match=r"energy\.csv: holds 0 rows; the checkpoint has \d+"):
        sim.checkpoints.resume(sim)


@pytest.mark.skipif(MPI.COMM_WORLD.size == 1, reason="needs a checkpoint of fewer ranks")
def test_a_resume_refuses_another_rank_count(shared_dir):
    raw = bar_scene(elements=4)
    raw["run"]["end_time"] = 1e-6
    raw["output"]["checkpoint_steps"] = 2
    out = Path(shared_dir)
    if MPI.COMM_WORLD.rank == 0:
        assert build(raw, out, MPI.COMM_SELF).run() == "done"
    sim = build(raw, out)
    message = r"written by a run on 1 rank\(s\); this run has 2: resume on 1"
    with pytest.raises(CheckpointError, match=message):
        sim.checkpoints.resume(sim)


def test_command_line_resume(shared_dir, capsys):
    """``run --resume`` of a finished run starts again from its latest checkpoint and
    writes the same outputs; with another scene it refuses in one line, exit 2."""
    comm, out = MPI.COMM_WORLD, Path(shared_dir)
    if comm.rank == 0:
        (out / "scene.toml").write_text(SCENE)
    comm.Barrier()
    scene = str(out / "scene.toml")
    args = ["run", scene, "--out", str(out / "run"), "--quiet", "--set", "output.frames=0"]
    assert main([*args, "--set", "output.checkpoint_steps=40"]) == 0
    comm.Barrier()
    first = (out / "run" / "energy.csv").read_text()
    steps = json.loads((out / "run" / "summary.json").read_text())["steps"]
    assert steps % 40 and checkpoints(out / "run") == [f"step_{steps // 40 * 40:010d}"]
    assert main([*args, "--resume"]) == 0
    comm.Barrier()
    assert (out / "run" / "energy.csv").read_text() == first
    capsys.readouterr()
    assert main([*args, "--resume", "--set", "initial.velocity=[0, 0, -4]"]) == 2
    if comm.rank == 0:
        lines = capsys.readouterr().err.strip().splitlines()
        assert len(lines) == 1 and "another scene: initial.velocity is (0.0, 0.0, -4.0)" in lines[0]


@pytest.mark.serial
def test_sigterm_writes_a_checkpoint_of_the_step_it_stopped_at(tmp_path):
    """A real SIGTERM: the run stops at a history sample and leaves its checkpoint."""
    long_run = SCENE.replace("end_time = 2e-5", "end_time = 1.0").replace("frames = 3", "")
    (tmp_path / "scene.toml").write_text(long_run)
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMI", "PMIX"))}
    command = [sys.executable, "-m", "rwall_fem", "run", "scene.toml", "--out", "out", "--quiet"]
    process = subprocess.Popen(command, cwd=tmp_path, env=env, stderr=subprocess.PIPE, text=True)
    energy = tmp_path / "out" / "energy.csv"
    while not (energy.exists() and energy.stat().st_size > 20000):
        assert process.poll() is None
        time.sleep(0.2)
    process.send_signal(signal.SIGTERM)
    _, stderr = process.communicate(timeout=120)
    assert process.returncode == 3 and "terminated by SIGTERM" in stderr
    step = int(stderr.split("stopped: step ")[1].split(",")[0])
    assert checkpoints(tmp_path / "out") == [f"step_{step:010d}"]
    with np.load(tmp_path / "out" / "checkpoint" / f"step_{step:010d}" / "rank_0.npz") as npz:
        header = json.loads(str(npz["header"]))
        assert header["step"] == step and header["ranks"] == 1
        assert int(npz["state/clock"][0]) == step


def test_checkpoints_every_so_many_seconds_look_at_the_clock_seldom(monkeypatch):
    """On a clock that advances 1 ms per step, a checkpoint every second is due at step
    1000 (within the last gap between looks at the clock, at most 1/20 of the interval),
    after a few dozen looks, the same on every rank (rank 0's clock decides)."""
    clock = {"now": 0.0, "looks": 0}

    def monotonic():
        clock["looks"] += 1
        return clock["now"]

    monkeypatch.setattr(rwall_fem.checkpoint.time, "monotonic", monotonic)
    schedule = rwall_fem.checkpoint.Checkpoints(
        Path("unused"), MPI.COMM_WORLD, {"scene": {}}, seconds=1.0
    )
    schedule.start(1)
    clock["looks"] = 0
    for step in range(1, 2000):
        clock["now"] = 1e-3 * step
        if schedule.due(step):
            break
    assert 1000 <= step <= 1050
    assert clock["looks"] < 40 if MPI.COMM_WORLD.rank == 0 else clock["looks"] == 0
