"""``summary.json`` is written when a run starts ("running") with room for the final
summary, which a full disk cannot then take away (issue 28, class 8). The full disk is
simulated here (a new file cannot be written: ENOSPC); ``tests/contract/test_robustness.py``
fills a real 64 kB tmpfs when it may mount one."""

import errno
import json

import pytest
from conftest import bar_scene
from mpi4py import MPI

from rwall_fem.output import OutputError, summary


def full_disk(path, text):
    raise OSError(errno.ENOSPC, "No space left on device")


def test_the_final_summary_takes_the_room_kept_at_the_start(tmp_path, monkeypatch):
    summary.reserve_summary(tmp_path, {"status": "running", "steps": 0})
    room = (tmp_path / "summary.json").stat().st_size
    assert json.loads((tmp_path / "summary.json").read_text())["status"] == "running"
    monkeypatch.setattr(summary, "_write_new", full_disk)
    final = {"status": "failed", "reason": "energy.csv: no space", "steps": 1234,
             "energy": {"kinetic": float("nan")}}  # fmt: skip
    summary.write_summary(tmp_path, final)
    written = json.loads((tmp_path / "summary.json").read_text())
    assert written == final | {"energy": {"kinetic": None}, "non_finite": ["energy.kinetic"]}
    assert (tmp_path / "summary.json").stat().st_size == room  # not grown
    assert not (tmp_path / ".summary.json.partial").exists()


def test_a_summary_larger_than_its_room_is_refused_naming_the_file(tmp_path, monkeypatch):
    summary.reserve_summary(tmp_path, {"status": "running"})
    monkeypatch.setattr(summary, "_write_new", full_disk)
    with pytest.raises(OutputError, match=r"summary.json: cannot be written \(No space left"):
        summary.write_summary(tmp_path, {"reason": "x" * (4 * summary.RESERVE_BYTES)})
    assert json.loads((tmp_path / "summary.json").read_text())["status"] == "running"


class ReadSummary:
    """Recorder that reads ``summary.json`` at step 3 of the run."""

    def __init__(self, directory):
        self.directory, self.seen = directory, None

    def due(self, s):
        return s.step == 3

    def record(self, sim, s):
        if sim.comm.rank == 0:  # rank 0 writes it
            self.seen = json.loads((self.directory / "summary.json").read_text())

    def close(self, sim):
        pass


def test_summary_json_says_running_while_the_run_goes(shared_dir):
    from rwall_fem import build_simulation, parse_scene

    raw = bar_scene(elements=10)
    sim = build_simulation(parse_scene(raw, source="test"), MPI.COMM_WORLD, shared_dir)
    reader = ReadSummary(shared_dir)
    sim.recorders.append(reader)
    sim.run()
    MPI.COMM_WORLD.Barrier()  # rank 0 has written the final summary
    if MPI.COMM_WORLD.rank:
        return
    assert reader.seen["status"] == "running" and reader.seen["steps"] == 0
    assert reader.seen["mass"] == pytest.approx(sim.info["mass"])
    final = json.loads((shared_dir / "summary.json").read_text())
    assert final["status"] == "done" and final["steps"] == sim.state.step
