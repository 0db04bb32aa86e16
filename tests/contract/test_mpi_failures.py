"""A failure on one rank while the model is built reaches every rank: one line, exit 2,
every rank ends (before: rank 0 printed gmsh's traceback and rank 1 waited for ever).

gmsh runs on rank 0 alone, so a bad mesh file is the failure only rank 0 sees. Each
case starts a job of 2 ranks of this leg's MPI (Open MPI on the Debian leg, MPICH on the
PyPI leg) with a time-out: a hang fails the test instead of blocking the suite. The bad
scenes (``test_bad_scenes.py``) also run in-process on 2 ranks under ``make test``.
"""

import subprocess
import sys
from pathlib import Path

import pytest
from conftest import mpi_launch

BAD = Path(__file__).resolve().parents[1] / "bad_scenes"


@pytest.mark.serial
@pytest.mark.parametrize(
    "command, scene, message",
    [
        ("run", "62_mesh_file_geo_syntax_error.toml", "syntax_error.geo: gmsh cannot read it"),
        ("check", "63_mesh_file_garbage.toml", "garbage.msh: not a gmsh mesh file"),
    ],
)
def test_a_bad_mesh_file_ends_every_rank_with_one_line(command, scene, message, tmp_path):
    launch, env = mpi_launch(2)
    args = [str(BAD / scene)] + (["--out", str(tmp_path / "out")] if command == "run" else [])
    result = subprocess.run(
        [*launch, sys.executable, "-m", "rwall_fem", command, *args],
        env=env,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert result.returncode == 2, result.stderr
    ours = [line for line in result.stderr.splitlines() if line.startswith("rwall-fem:")]
    assert len(ours) == 1 and message in ours[0], result.stderr
    assert "Traceback" not in result.stderr
    assert not (tmp_path / "out").exists()  # refused before anything was written
