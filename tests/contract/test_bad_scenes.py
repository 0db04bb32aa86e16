"""Every scene file in ``bad_scenes/`` has one mistake; ``rwall-fem check`` must refuse it
with exit code 2 and one line on stderr that names the file, the key path and what is
allowed (the text after ``# expect:`` in the file's second line), without a traceback.
The files are read as bytes: one of them is binary after its two lines of text.

The command runs in-process (``cli.main``), on every rank of the session: each rank gets
the same exit code, rank 0 prints the line.
"""

from pathlib import Path

import pytest
from mpi4py import MPI

from rwall_fem.cli import main

SCENES = sorted((Path(__file__).resolve().parents[1] / "bad_scenes").glob("*.toml"))


def test_there_are_at_least_fifty():
    assert len(SCENES) >= 50


@pytest.mark.parametrize("scene", SCENES, ids=[s.stem for s in SCENES])
def test_bad_scene_is_refused_in_one_line(scene, capsys):
    expected = scene.read_bytes().split(b"\n")[1].decode().removeprefix("# expect: ")
    code = main(["check", str(scene)])
    err = capsys.readouterr().err
    assert code == 2
    if MPI.COMM_WORLD.rank == 0:
        lines = err.strip().splitlines()
        assert len(lines) == 1, err
        assert lines[0].startswith(f"rwall-fem: error: {scene}") and expected in lines[0], err
        assert "Traceback" not in err
