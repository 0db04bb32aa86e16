"""The results folder: checked before meshing, held by one run at a time, and cleared of
what an earlier run left (before: a second run left the first run's walls.csv, frames/
and animation.gif behind, and two runs into one folder interleaved energy.csv and
crashed; an unwritable folder was found only after meshing).

Commands run in-process on every rank unless they need a process of their own.
"""

import os
import socket
import subprocess
import sys
import tempfile
import time

import pytest
from conftest import SCENE
from mpi4py import MPI

from rwall_fem.cli import main
from rwall_fem.output.folder import LOCK

NO_PICTURES = SCENE.replace("frames = 3", "frames = 0\nplot = false")
EARLIER = ["walls.csv", "animation.gif", "animation.mp4", "fields.xdmf", "fields.h5"]


@pytest.fixture
def scene_file(shared_dir):
    path = shared_dir / "scene.toml"
    if MPI.COMM_WORLD.rank == 0:
        path.write_text(NO_PICTURES)
    MPI.COMM_WORLD.Barrier()
    return path


def rank0(capsys) -> tuple[str, list[str]]:
    """stdout and the lines of stderr of rank 0 (empty elsewhere)."""
    captured = capsys.readouterr()
    if MPI.COMM_WORLD.rank:
        return "", []
    return captured.out, captured.err.strip().splitlines()


def test_a_folder_in_use_is_refused_in_one_line(scene_file, shared_dir, capsys):
    out = shared_dir / "out"
    if MPI.COMM_WORLD.rank == 0:  # a live run of this host holds it: this process
        out.mkdir()
        (out / LOCK).write_text(f"{os.getpid()} {socket.gethostname()} 2026-12-01 10:00:00\n")
    MPI.COMM_WORLD.Barrier()
    assert main(["run", str(scene_file), "--out", str(out)]) == 2
    stdout, err = rank0(capsys)
    if MPI.COMM_WORLD.rank == 0:
        assert len(err) == 1 and f"{out} is in use by run {os.getpid()}" in err[0], err
        assert "choose another --out" in err[0] and "Traceback" not in err[0]
        assert sorted(p.name for p in out.iterdir()) == [LOCK]  # nothing written, lock kept


def test_a_lock_left_by_a_killed_run_is_taken_over(scene_file, shared_dir, capsys):
    out = shared_dir / "out"
    if MPI.COMM_WORLD.rank == 0:
        gone = subprocess.Popen(["true"])
        gone.wait()  # a process of this host that no longer exists
        out.mkdir()
        (out / LOCK).write_text(f"{gone.pid} {socket.gethostname()} 2026-12-01 10:00:00\n")
    MPI.COMM_WORLD.Barrier()
    assert main(["run", str(scene_file), "--out", str(out), "--quiet"]) == 0
    if MPI.COMM_WORLD.rank == 0:
        assert not (out / LOCK).exists() and (out / "summary.json").exists()


def test_outputs_of_an_earlier_run_are_removed_and_said(scene_file, shared_dir):
    """A run without frames and fields into a folder where an earlier run left them: they
    go (the run log names them); a file of the user's stays; no lock is left."""
    out = shared_dir / "out"
    if MPI.COMM_WORLD.rank == 0:
        (out / "frames" / "data").mkdir(parents=True)
        (out / "frames" / "frame_0000.png").write_bytes(b"old")
        for name in [*EARLIER, "notes.txt"]:
            (out / name).write_text("old")
    MPI.COMM_WORLD.Barrier()
    raw = SCENE.replace("frames = 3", "frames = 0\nplot = false")
    raw = raw.replace(
        '[[wall]]\nkind = "plane"\npoint = [0.0, 0.0, 0.0]\nnormal_point = [0.0, 0.0, 1.0]\n', ""
    )
    if MPI.COMM_WORLD.rank == 0:
        scene_file.write_text(raw)
    MPI.COMM_WORLD.Barrier()
    assert main(["run", str(scene_file), "--out", str(out), "--quiet"]) == 0
    if MPI.COMM_WORLD.rank == 0:
        left = sorted(p.name for p in out.iterdir())
        assert left == ["energy.csv", "notes.txt", "run.log", "summary.json"], left
        log = (out / "run.log").read_text()
        assert (
            "removed the outputs of an earlier run: walls.csv, fields.xdmf, fields.h5, "
            "animation.gif, animation.mp4, frames" in log
        )


def test_an_unusable_out_is_refused_before_meshing(scene_file, shared_dir, capsys):
    assert main(["run", str(scene_file), "--out", str(scene_file / "out")]) == 2
    stdout, err = rank0(capsys)
    if MPI.COMM_WORLD.rank == 0:
        assert err == [
            f"rwall-fem: error: --out: {scene_file} is not a folder (a file); choose another "
            "folder (--out or output.directory)"
        ]
        assert "mesh:" not in stdout


@pytest.mark.serial
def test_a_read_only_working_directory_without_out(tmp_path):
    """The default folder ("results") in a working directory nobody can write to: sysfs
    refuses new folders even to root (a folder of mode 555 would not stop root)."""
    try:
        os.rmdir(tempfile.mkdtemp(dir="/sys"))
        pytest.skip("/sys is writable here")
    except OSError:
        pass
    (tmp_path / "scene.toml").write_text(SCENE)
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMI", "PMIX"))}
    result = subprocess.run(
        [sys.executable, "-m", "rwall_fem", "run", str(tmp_path / "scene.toml")],
        cwd="/sys", env=env, capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert result.returncode == 2, result.stderr
    assert result.stderr.splitlines() == [
        f"rwall-fem: error: {tmp_path / 'scene.toml'}: output.directory: cannot create "
        "/sys/results in /sys (Operation not permitted); choose another folder (--out or "
        "output.directory)"
    ]
    assert "mesh:" not in result.stdout


@pytest.mark.serial
def test_a_second_run_into_a_busy_folder_leaves_the_first_alone(tmp_path):
    """Two real runs: the second is refused while the first writes; the first's
    energy.csv has only whole lines of its own."""
    long = NO_PICTURES.replace("end_time = 2e-5", "end_time = 1.0")
    (tmp_path / "scene.toml").write_text(long)
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMI", "PMIX"))}
    command = [sys.executable, "-m", "rwall_fem", "run", "scene.toml", "--out", "out", "--quiet"]
    first = subprocess.Popen(command, cwd=tmp_path, env=env, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while not (tmp_path / "out" / "energy.csv").exists():
        assert first.poll() is None and time.monotonic() < deadline
        time.sleep(0.1)
    second = subprocess.run(command, cwd=tmp_path, env=env, capture_output=True, text=True)
    first.terminate()
    _, first_err = first.communicate(timeout=60)
    assert second.returncode == 2
    assert len(second.stderr.splitlines()) == 1 and "is in use by run" in second.stderr
    assert f"run {first.pid} on {socket.gethostname()}" in second.stderr
    assert first.returncode == 3 and "terminated by SIGTERM" in first_err
    lines = (tmp_path / "out" / "energy.csv").read_text().splitlines()
    assert len({len(line.split(",")) for line in lines}) == 1 and len(lines) > 2
    assert not (tmp_path / "out" / LOCK).exists()
