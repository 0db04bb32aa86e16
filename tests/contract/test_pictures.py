"""Frames of a run: cell fields gathered with the body, the colourings a body offers, and
the renderer's command line (``python -m rwall_fem.output.render``, ``rwall-fem render``)."""

import copy
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import bar_scene
from mpi4py import MPI

from rwall_fem import SceneError, build_simulation, parse_scene

WEIGHTS = np.array([1.0, 2.0, 3.0])  # the test's cell field: WEIGHTS . centre, m


def _render(*args, cwd=None):
    """``python -m rwall_fem.output.render ARGS`` in a process of its own (rank 0)."""
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMI", "PMIX"))}
    return subprocess.run(
        [sys.executable, "-m", "rwall_fem.output.render", *map(str, args)],
        env=env,
        cwd=cwd,
        capture_output=True,
        text=True,
    )


def _scene(color="normal_velocity"):
    raw = bar_scene(elements=6, h=2e-3, cell="hexahedron", end_time=2e-6)
    raw["output"].update(frames=2, color=color)
    return parse_scene(copy.deepcopy(raw), source="test.toml")


def test_cell_fields_are_stored_and_coloured(shared_dir):
    """A cell field given by the internal force lands on its cells in the frame data of
    every rank's share, and the renderer colours by it; an unknown field is refused."""
    sim = build_simulation(_scene(), out=shared_dir)
    internal = sim.internal
    centres = internal.X[internal.cells].mean(axis=1)
    internal.cell_fields = lambda state: {"plastic_strain": centres @ WEIGHTS}
    sim.run()
    if MPI.COMM_WORLD.rank != 0:
        return
    data = Path(shared_dir) / "frames" / "data"
    mesh = np.load(data / "mesh.npz")
    cells = mesh["topology"].reshape(len(mesh["cell_types"]), -1)[:, 1:]
    expected = mesh["points"][cells].mean(axis=1) @ WEIGHTS
    for frame in sorted(data.glob("frame_*.npz")):
        assert np.allclose(np.load(frame)["cell_plastic_strain"], expected, rtol=1e-12)
    result = _render(shared_dir, "--color", "plastic_strain")
    assert result.returncode == 0, result.stderr
    assert len(list((Path(shared_dir) / "frames").glob("frame_*.png"))) == 2
    refused = _render(shared_dir, "--color", "damage")
    assert refused.returncode == 2 and "Traceback" not in refused.stderr
    assert refused.stderr.strip().splitlines() == [
        "rwall-fem: error: color 'damage': not a field of this body; choose one of "
        "normal_velocity, speed, displacement (its cell fields: plastic_strain)"
    ]


def test_an_elastic_body_has_no_plastic_strain_to_colour():
    with pytest.raises(SceneError, match=r"output\.color: 'plastic_strain' is not a field"):
        build_simulation(_scene("plastic_strain"))


@pytest.mark.serial
def test_the_renderer_has_a_help_and_refuses_in_one_line(tmp_path):
    helped = _render("--help")
    assert helped.returncode == 0 and helped.stdout.startswith("usage:")
    assert "--color" in helped.stdout and not helped.stderr
    missing = _render(tmp_path / "nowhere")
    assert missing.returncode == 2
    assert missing.stderr.splitlines() == [
        f"rwall-fem: error: {tmp_path / 'nowhere'}: no such folder"
    ]
    empty = _render(tmp_path)
    assert empty.returncode == 2 and "no frame data" in empty.stderr
    assert len(empty.stderr.splitlines()) == 1


def test_a_body_of_parts_is_coloured_by_part(shared_dir):
    """output.color = "part": each cell of the frames holds its part's index (the 4 mm
    front of the bar 0, the rest 1), mesh.npz the parts' names, and the renderer paints
    each part in its own colour (tab10's blue and orange are both in the picture)."""
    raw = bar_scene(elements=6, h=2e-3, cell="hexahedron", end_time=2e-6)
    raw["output"].update(frames=2, color="part")
    raw["mesh"]["front_length"] = 0.004
    raw["part"] = [{"name": "nose", "volumes": ["front"]}, {"name": "body"}]
    build_simulation(parse_scene(copy.deepcopy(raw), source="test"), out=shared_dir).run()
    if MPI.COMM_WORLD.rank != 0:
        return
    data = Path(shared_dir) / "frames" / "data"
    mesh = np.load(data / "mesh.npz")
    assert json.loads(str(mesh["parts"])) == ["nose", "body"]
    cells = mesh["topology"].reshape(len(mesh["cell_types"]), -1)[:, 1:]
    in_front = mesh["points"][cells][:, :, 2].mean(axis=1) < 0.004
    for frame in sorted(data.glob("frame_*.npz")):
        assert np.array_equal(np.load(frame)["cell_part"], np.where(in_front, 0.0, 1.0))
    result = _render(shared_dir, "--color", "part")
    assert result.returncode == 0, result.stderr
    import imageio.v2 as imageio

    picture = imageio.imread(Path(shared_dir) / "frames" / "frame_0001.png")[..., :3].reshape(-1, 3)
    for colour in ("#1f77b4", "#ff7f0e"):
        rgb = np.array([int(colour[i : i + 2], 16) for i in (1, 3, 5)])
        assert (np.abs(picture.astype(int) - rgb).max(axis=1) <= 60).sum() > 50, colour
