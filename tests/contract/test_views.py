"""What the frames show, checked on their pixels: a Taylor rod cut open along its axis shows
its plastic strain on the cut face, the body fills the picture, one colour range serves every
frame, ``render --view`` draws a finished run again with another view, and a body that
erodes away is drawn as its loose nodes (issue 28, class 4) while the run ends normally."""

import copy
import json
import math
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from mpi4py import MPI

from rwall_fem import SceneError, build_simulation, parse_scene

COMM = MPI.COMM_WORLD
SIZE = (400, 300)  # pixels: small pictures, fast tests
BACKGROUND = np.array([255, 255, 255])  # pyvista's document theme
LOOSE = np.array([64, 64, 64])  # the loose nodes' colour (#404040)


def _render(*args):
    """``python -m rwall_fem.output.render ARGS`` in a process of its own (rank 0)."""
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMI", "PMIX"))}
    return subprocess.run(
        [sys.executable, "-m", "rwall_fem.output.render", *map(str, args)],
        env=env, capture_output=True, text=True,
    )  # fmt: skip


def _pictures(directory) -> list[np.ndarray]:
    import imageio.v2 as imageio

    files = sorted((Path(directory) / "frames").glob("frame_*.png"))
    return [imageio.imread(f)[..., :3].astype(int) for f in files]


def _saturation(pixels: np.ndarray) -> np.ndarray:
    """max - min of the channels (0-255): 0 for white, black and every grey."""
    return pixels.max(axis=-1) - pixels.min(axis=-1)


def taylor_scene(view: dict | None = None) -> dict:
    """A copper rod (radius 3.2 mm, 12.8 mm long, 0.8 mm cells) striking a rigid plane at
    227 m/s for 8 us: its impact end yields (plastic strain ~0.3), its far end does not."""
    raw = {
        "run": {"end_time": 8e-6, "dt_scale": 0.9},
        "mesh": {"shape": "round_bar", "radius": 3.2e-3, "length": 12.8e-3,
                 "element_size": 0.8e-3, "cell": "hexahedron"},
        "material": {"model": "elastic_plastic", "density": 8930.0, "young": 117e9,
                     "poisson": 0.35, "hardening": "linear", "yield_stress": 400e6,
                     "hardening_modulus": 100e6},
        "initial": {"velocity": [0.0, 0.0, -227.0]},
        "wall": [{"kind": "plane", "point": [0, 0, 0], "normal_point": [0, 0, 1]}],
        "output": {"frames": 3, "color": "plastic_strain", "plot": False,
                   "view": {"cut": "x", "size": list(SIZE), **(view or {})}},
    }  # fmt: skip
    return raw


def test_a_cut_taylor_rod_shows_its_plastic_strain_inside(shared_dir):
    """Cut along its axis, the rod's section is coloured by the plastic-strain map (viridis:
    saturated colours, not the greys of the walls, edges and background) over most of its
    outline; the impact end (bottom of the picture) is yellow-green (high strain, near the
    top of the range), the far end dark violet (no strain, the bottom of the map). The rod
    fills more than half of the picture's height, and every frame carries the same colour
    bar (one range for the run)."""
    sim = build_simulation(parse_scene(taylor_scene(), source="test"), COMM, shared_dir)
    assert sim.run() == "done"
    if COMM.rank != 0:
        return
    pictures = _pictures(shared_dir)
    assert len(pictures) == 3 and pictures[0].shape == (SIZE[1], SIZE[0], 3)
    last = pictures[-1]
    band = last[int(0.10 * SIZE[1]) : int(0.84 * SIZE[1])]  # between the time and the bar
    body = _saturation(band) > 40  # the coloured rod (viridis is saturated everywhere)
    rows = np.flatnonzero(body.any(axis=1))
    assert rows.size and rows[-1] - rows[0] >= 0.5 * SIZE[1]
    # Inside the rod's outline (its rows, between its leftmost and rightmost coloured
    # pixel), most pixels are of the colour map: the cut face is drawn, filled.
    inside = np.concatenate([row[np.flatnonzero(m)[0] : np.flatnonzero(m)[-1] + 1]
                             for row, m in zip(band, body, strict=True) if m.any()])  # fmt: skip
    assert np.mean(_saturation(inside) > 40) > 0.7
    top, bottom = band[rows[0] + 3], band[rows[-1] - 3]  # far end, impact end
    top, bottom = top[_saturation(top) > 40], bottom[_saturation(bottom) > 40]
    # viridis: 0 is violet (68, 1, 84): blue above red, little green; high strain is
    # green to yellow: green above blue.
    assert np.median(top[:, 2] - top[:, 1]) > 30
    assert np.median(bottom[:, 1] - bottom[:, 2]) > 0
    bar = [p[int(0.84 * SIZE[1]) :] for p in pictures]  # the colour bar and its labels
    assert all(np.array_equal(bar[0], b) for b in bar[1:])


def test_render_view_draws_a_finished_run_again(shared_dir):
    """``render DIR --view ...`` writes the frames again with the new view (here uncut and
    zoomed out, at another size), from the run's frame data; a wrong view is refused in
    one line naming the key, and the frames stay."""
    raw = taylor_scene()
    raw["run"]["end_time"] = 2e-6
    raw["output"]["frames"] = 2
    build_simulation(parse_scene(copy.deepcopy(raw), source="test"), COMM, shared_dir).run()
    if COMM.rank != 0:
        return
    before = _pictures(shared_dir)
    result = _render(shared_dir, "--view", "zoom = 0.5, size = [320, 320], azimuth = 90")
    assert result.returncode == 0, result.stderr
    after = _pictures(shared_dir)
    assert len(after) == 2 and after[0].shape == (320, 320, 3)
    body = _saturation(after[-1]) > 40
    rows = np.flatnonzero(body[int(0.1 * 320) : int(0.84 * 320)].any(axis=1))
    assert 0.1 * 320 < rows[-1] - rows[0] < 0.5 * 320  # zoomed out: half as tall as fitted
    assert before[0].shape != after[0].shape
    for text, words in [
        ('cut = "w"', 'cut: must be "x", "y", "z"'),
        ("zoom = 0", "zoom: must be a finite number in (0, 100]"),
        ("range = [2, 1]", "range: must be \"auto\" or [low, high] with low < high"),
        ("size = [10, 10]", "size: must be [width, height], integers in [64, 4096]"),
        ("focus = \"nose\"", "view.focus: 'nose' is not a part of this body"),
        ("cut = {point = [0, 0, 1], normal = [0, 0, 1]}",
         "view.cut: the plane through [0.0, 0.0, 1.0] normal to [0.0, 0.0, 1.0] does not cut"),
        ("zoom = ", "--view: not a TOML inline table's keys"),
    ]:
        refused = _render(shared_dir, "--view", text)
        assert refused.returncode == 2, text
        lines = refused.stderr.strip().splitlines()
        assert len(lines) == 1 and words in lines[0], (text, lines)
    assert len(_pictures(shared_dir)) == 2


def test_a_fixed_range_colours_every_frame_alike(shared_dir):
    """range = [0, 2]: a plastic strain of at most ~0.3 stays in the violet-blue lower sixth
    of the map, in every frame."""
    raw = taylor_scene({"range": [0.0, 2.0], "cut": "y"})
    raw["run"]["end_time"] = 8e-6
    build_simulation(parse_scene(copy.deepcopy(raw), source="test"), COMM, shared_dir).run()
    if COMM.rank != 0:
        return
    for picture in _pictures(shared_dir):
        band = picture[int(0.10 * SIZE[1]) : int(0.84 * SIZE[1])]
        coloured = band[_saturation(band) > 40]
        assert coloured.size and np.mean(coloured[:, 2] > coloured[:, 1]) > 0.9  # blue > green


@pytest.mark.parametrize(
    "view, message",
    [
        ({"cut": {"point": [0, 0, 1.0], "normal": [0, 0, 1]}},
         "output.view.cut: the plane through [0.0, 0.0, 1.0] normal to [0.0, 0.0, 1.0] does "
         "not cut the body"),
        ({"focus": "nose"}, "output.view.focus: 'nose' is not a part of this body (a body "
         "without [[part]])"),
    ],
)  # fmt: skip
def test_a_view_the_body_cannot_give_is_refused_before_the_run(view, message, shared_dir):
    with pytest.raises(SceneError, match=re.escape(message)):
        build_simulation(parse_scene(taylor_scene(view), source="test"), COMM, shared_dir)


# --- issue 28, class 4: a body that erodes away ---------------------------------------------

STEEL = {
    "model": "elastic_plastic", "density": 7850.0, "young": 200e9, "poisson": 0.3,
    "hardening": "linear", "yield_stress": 400e6, "hardening_modulus": 1e9,
}  # fmt: skip
FAILURE = {"criterion": "plastic_strain", "plastic_strain": 0.2}


def pulled_bar(cells: int, weak: int) -> dict:
    """A steel bar of ``cells`` 1 mm hexahedra (fully integrated: uniform cells fail
    together) along z, its end faces pulled apart at up to 1.2 m/s each; the first ``weak``
    cells (its front, a part of their own) fail at a plastic strain of 0.2, the others never.
    Run until the weak cells have all failed, with 4 frames."""
    h, speed = 1e-3, 1.2
    length = cells * h
    rate = 2 * speed / length  # the strain rate of both halves (the same steel)
    pull = 1.5 * math.expm1(0.2) / rate
    ramp = 0.3 * pull
    table = [[ramp * x, 0.0, 0.0, speed * (3 * x**2 - 2 * x**3)] for x in np.linspace(0, 1, 5)]
    raw = {
        "run": {"end_time": pull + ramp},
        "mesh": {"shape": "bar", "size": [h, h, length], "element_size": h,
                 "cell": "hexahedron", "front_length": weak * h},
        "element": {"integration": "full"},
        "material": STEEL,
        "boundary": [
            {"group": "bottom", "velocity": [[t, 0, 0, -v] for t, _, _, v in table],
             "components": "z"},
            {"group": "top", "velocity": table, "components": "z"},
        ],
        "part": [{"name": "weak", "volumes": ["front"], "material": STEEL | {"failure": FAILURE}},
                 {"name": "strong", "volumes": ["body"]}],
        "output": {"frames": 4, "plot": False, "history_interval": 100},
    }  # fmt: skip
    if weak == cells:  # one body, without parts
        raw["mesh"].pop("front_length")
        raw["material"] = raw.pop("part")[0]["material"]
    return raw


@pytest.mark.parametrize("cells, weak", [(4, 4), (8, 4)], ids=["all", "front half"])
def test_a_body_that_erodes_away_ends_normally_drawn_as_points(shared_dir, cells, weak):
    """Every cell of the bar erodes (all), or those of its front half (on 2 ranks, one rank's
    share: the partition of a bar of 8 cells in a row gives each rank 4 in a row, so that
    one rank is left no live cell): the run ends "done", the frames are all drawn, and
    the last shows the nodes no live cell holds as dark points (all: nothing but them)."""
    raw = pulled_bar(cells, weak)
    sim = build_simulation(parse_scene(copy.deepcopy(raw), source="test"), COMM, shared_dir)
    assert sim.run() == "done"
    if COMM.rank != 0:
        return
    summary = json.loads((Path(shared_dir) / "summary.json").read_text())
    assert summary["status"] == "done"
    assert summary["erosion"]["eroded_cells"] == weak
    pictures = _pictures(shared_dir)
    assert len(pictures) == 4
    last = pictures[-1]
    band = last[int(0.10 * last.shape[0]) : int(0.84 * last.shape[0])]
    dark = np.all(np.abs(band - LOOSE) <= 8, axis=-1)
    assert dark.sum() >= 4  # the loose nodes, a few pixels each
    coloured = _saturation(band) > 40
    if weak == cells:
        assert not coloured.any()  # no cell is left to draw
    else:
        assert coloured.sum() > 100  # the strong half is drawn


# --- the renderer beside the time loop (rwall_fem.output.worker) ---------------------------


def _partial_files(directory) -> list[Path]:
    """Files left half-written (rwall_fem.output.atomic's hidden partial names)."""
    return sorted(Path(directory).rglob(".*.partial.*"))


def test_the_renderer_beside_the_loop_draws_what_the_renderer_after_it_draws(
    shared_dir, monkeypatch
):
    """RWALL_FEM_RENDER=worker (on 2 ranks too: rank 0 feeds it): every frame is drawn,
    pixel for pixel as ``render`` draws the same folder after the run, and no partial file
    is left."""
    monkeypatch.setenv("RWALL_FEM_RENDER", "worker")
    raw = taylor_scene()
    raw["run"]["end_time"] = 2e-6
    sim = build_simulation(parse_scene(raw, source="test"), COMM, shared_dir)
    assert sim.run() == "done"
    if COMM.rank != 0:
        return
    beside = _pictures(shared_dir)
    assert len(beside) == 3 and not _partial_files(shared_dir)
    result = _render(shared_dir, "--color", "plastic_strain")
    assert result.returncode == 0, result.stderr
    after = _pictures(shared_dir)
    assert all(np.array_equal(a, b) for a, b in zip(beside, after, strict=True))


def test_a_renderer_beside_the_loop_that_fails_is_replaced(shared_dir, monkeypatch, capfd):
    """A renderer beside the loop that dies at once: the run goes on, says so in one
    warning line at the end, and draws every frame after the loop."""
    from rwall_fem.output import worker

    monkeypatch.setenv("RWALL_FEM_RENDER", "worker")
    monkeypatch.setattr(worker, "renderer_command", lambda *args: [
        sys.executable, "-c", "import sys; sys.exit('the renderer broke')"])  # fmt: skip
    raw = taylor_scene()
    raw["run"]["end_time"] = 2e-6
    sim = build_simulation(parse_scene(raw, source="test"), COMM, shared_dir)
    assert sim.run() == "done"
    if COMM.rank != 0:
        return
    err = capfd.readouterr().err
    assert "warning: the renderer beside the run failed (the renderer broke)" in err
    assert len(_pictures(shared_dir)) == 3 and not _partial_files(shared_dir)


class _Breaks:
    """A recorder that fails at the first step past ``time`` (s): a run failing midway."""

    def __init__(self, time: float):
        self.time = time

    def due(self, state) -> bool:
        return state.t > self.time

    def record(self, sim, state) -> None:
        raise RuntimeError("broken midway")

    def close(self, sim) -> None:
        """Nothing to close."""


def test_a_run_failing_midway_keeps_every_frame_written(shared_dir, monkeypatch):
    """A run that fails at half its time, with the renderer beside the loop: the error
    reaches the caller, and each frame stored before it is drawn, whole."""
    monkeypatch.setenv("RWALL_FEM_RENDER", "worker")
    raw = taylor_scene()
    raw["output"]["frames"] = 5
    sim = build_simulation(parse_scene(raw, source="test"), COMM, shared_dir)
    sim.recorders.append(_Breaks(0.5 * raw["run"]["end_time"]))
    with pytest.raises(RuntimeError, match="broken midway"):
        sim.run()
    if COMM.rank != 0:
        return
    stored = sorted((Path(shared_dir) / "frames" / "data").glob("frame_*.npz"))
    assert len(stored) == 3  # at 0, 2 and 4 us of 8
    assert len(_pictures(shared_dir)) == 3 and not _partial_files(shared_dir)


def test_a_renderer_whose_run_is_gone_draws_nothing(shared_dir):
    """``render DIR --follow PID`` (what the run starts): when its stdin ends before
    ``end`` it leaves at once without drawing; when PID is not its parent (the run was
    killed) it ends itself (exit 3) without drawing."""
    raw = taylor_scene()
    raw["run"]["end_time"] = 2e-6
    build_simulation(parse_scene(raw, source="test"), COMM, shared_dir).run()
    if COMM.rank != 0:
        return
    for png in (Path(shared_dir) / "frames").glob("frame_*.png"):
        png.unlink()
    command = [sys.executable, "-m", "rwall_fem.output.render", str(shared_dir), "--follow"]
    env = {k: v for k, v in os.environ.items() if not k.startswith(("OMPI_", "PMI", "PMIX"))}
    left = subprocess.run([*command, str(os.getpid())], input="", env=env, capture_output=True,
                          text=True, timeout=120)  # fmt: skip
    assert left.returncode == 0, left.stderr
    orphan = subprocess.Popen([*command, "1"], stdin=subprocess.PIPE, env=env,
                              stderr=subprocess.PIPE, text=True)  # fmt: skip
    orphan.wait(timeout=120)  # its stdin open: it ends by itself
    err = orphan.stderr.read()
    orphan.stdin.close()
    assert orphan.returncode == 3 and "terminated by SIGTERM" in err, err
    assert not _pictures(shared_dir) and not _partial_files(shared_dir)
