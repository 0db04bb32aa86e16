"""Off-screen pictures of a run: ``python -m rwall_fem.output.render DIR [--color COLOR]``.

Reads the frame data that :class:`rwall_fem.output.frames.Frames` stored in
``DIR/frames/data`` and writes ``DIR/frames/frame_NNNN.png`` and
``DIR/animation.gif``, and ``DIR/animation.mp4`` when the ``imageio-ffmpeg``
encoder is installed (``pip install rwall_fem[mp4]``). The body is drawn on
its deformed geometry at true scale (no magnification), without its eroded cells (the
nodes no live cell holds are drawn as points), coloured as
:mod:`rwall_fem.output.coloring` says, with the walls as
:mod:`rwall_fem.output.view` draws them: flat walls opaque (the camera sees
them from their allowed side, behind the body), curved walls translucent with
their outline. The camera and the colour range are fixed once for all frames.
This module must not import DOLFINx (see :mod:`rwall_fem.output.frames`).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import zipfile
from pathlib import Path

import numpy as np

from rwall_fem import interrupts
from rwall_fem.output.coloring import COLORS, coloring
from rwall_fem.output.view import choose_view, up_direction, wall_surface
from rwall_fem.walls.shapes import shape_from_parameters

__all__ = ["COLORS", "RenderError", "body_grid", "main", "render_frames"]

WINDOW = (800, 600)  # pixels
BAR = (0.2, 0.06, 0.6, 0.04)  # the colour bar's box: x, y, width, height (of the window)
EDGES = 10  # pixels: the cell edges are drawn when cells are at least this large
WALL_COLOR = "#a9b4c2"  # a cool grey that no colour map uses
TIME_UNITS = ((1e-6, "µs"), (1e-3, "ms"), (1.0, "s"))  # the largest below the end time


class RenderError(ValueError):
    """The pictures cannot be drawn from what the folder holds (one line)."""


def render_frames(directory: str | Path, color: str = "normal_velocity") -> list[Path]:
    """Render every stored frame of the run in ``directory``, coloured by ``color`` (one of
    :data:`COLORS` or a cell field the run stored); returns the PNG paths.

    Raises RenderError for a folder without frame data or an unknown colouring.
    """
    os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    import imageio.v2 as imageio
    import pyvista

    directory = Path(directory)
    mesh, walls, paths, frames = _stored(directory)
    points = mesh["points"]
    up = up_direction(mesh.get("gravity"), walls)
    try:
        parts = tuple(json.loads(str(mesh["parts"]))) if "parts" in mesh else ()
        paint = coloring(color, frames, points, walls, up, float(mesh["speed"]), parts)
    except ValueError as err:
        raise RenderError(str(err)) from None
    body = np.concatenate([points + f["u"] for f in frames])
    size = float(np.ptp(body, axis=0).max())
    surfaces = [
        [wall_surface(pyvista, w, o, body, size) for w, o in zip(walls, f["offsets"], strict=True)]
        for f in frames
    ]
    clouds = [body, *(s.points for drawn in surfaces for s in drawn)]
    view = choose_view(points + frames[0]["u"], clouds, walls, up, WINDOW[0] / WINDOW[1])
    edges = bool(_cell_size(mesh) >= EDGES * 2 * view.scale / WINDOW[1])
    scale, unit = _time_unit(float(frames[-1]["t"]))
    decimals = _time_decimals(frames, scale)
    files = []
    for path, frame, values, drawn in zip(paths, frames, paint.values, surfaces, strict=True):
        # A frame is not cut by a stop signal (interrupts.deferred: it is raised after the
        # frame), and its plotter is closed however the frame ends: a VTK window left half
        # made or half closed fails in its destructor at exit, with a traceback.
        with interrupts.deferred():
            plotter = pyvista.Plotter(off_screen=True, window_size=WINDOW)
            try:
                grid = body_grid(pyvista, mesh, frame)
                (grid.cell_data if paint.per_cell else grid.point_data)[paint.title] = values
                if "cell_eroded" in frame:  # eroded cells are not drawn, detached nodes are points
                    grid = grid.extract_cells(np.flatnonzero(frame["cell_eroded"] < 0.5))
                    loose = (mesh["points"] + frame["u"])[frame["detached"] > 0.5]
                    if len(loose):
                        plotter.add_points(loose, color="#404040", point_size=3.0)
                plotter.add_mesh(
                    grid,
                    scalars=paint.title,
                    clim=paint.clim,
                    cmap=paint.cmap,
                    n_colors=len(paint.names) or 256,
                    show_edges=edges,
                    edge_color="#404040",
                    line_width=0.5,
                    ambient=0.3,
                    diffuse=0.7,
                    show_scalar_bar=False,
                )
                _colour_bar(plotter, paint)
                for wall, surface in zip(walls, drawn, strict=True):
                    if view.behind(wall):
                        plotter.add_mesh(surface, color=WALL_COLOR, ambient=0.3, diffuse=0.7)
                    else:
                        plotter.add_mesh(surface, color=WALL_COLOR, opacity=0.3, silhouette=True)
                time = f"t = {float(frame['t']) / scale:.{decimals}f} {unit}"
                plotter.add_text(time, position=(12, WINDOW[1] - 32), font_size=12, color="black")
                view.apply(plotter)
                png = directory / "frames" / path.with_suffix(".png").name
                plotter.screenshot(str(png))
            finally:
                plotter.close()
        files.append(png)
    images = [imageio.imread(p) for p in files]
    imageio.mimsave(directory / "animation.gif", images, duration=0.1, loop=0)
    if _has_mp4_encoder():
        imageio.mimsave(directory / "animation.mp4", images, fps=10, macro_block_size=8)
    return files


def _stored(directory: Path):
    """The body (``mesh.npz`` as a dict), the wall shapes, and the frame files that
    ``directory`` holds with their contents; RenderError when there are none or the body
    cannot be read. A frame file that cannot be read (cut short by a kill or a full
    disk) or does not fit the body is left out, with a warning line."""
    data = directory / "frames" / "data"
    if not directory.is_dir():
        raise RenderError(f"{directory}: no such folder")
    paths = sorted(data.glob("frame_*.npz"))
    if not (data / "mesh.npz").is_file() or not paths:
        raise RenderError(f"{directory}: no frame data (run with output.frames > 0)")
    try:
        mesh = _npz(data / "mesh.npz", ("topology", "cell_types", "points", "speed", "walls"))
        walls = [shape_from_parameters(w) for w in json.loads(str(mesh["walls"]))]
        if mesh["points"].ndim != 2 or mesh["points"].shape[1:] != (3,):
            raise ValueError(f"points of shape {mesh['points'].shape}, not (n, 3)")
    except (OSError, ValueError, TypeError, KeyError) as err:
        raise RenderError(f"{data / 'mesh.npz'}: cannot be read: {_one_line(err)}") from None
    kept, frames = [], []
    for path in paths:
        try:
            frame = _npz(path, ("t", "u", "v", "offsets"))
            for name in ("u", "v"):
                if frame[name].shape != mesh["points"].shape:
                    raise ValueError(f"{name} has shape {frame[name].shape}, not that of the body")
            if frame["offsets"].shape != (len(walls), 3):
                raise ValueError(f"offsets of {len(frame['offsets'])} walls, not {len(walls)}")
        except (OSError, ValueError, TypeError, KeyError) as err:
            print(
                f"rwall-fem: warning: {path}: cannot be read, left out: {_one_line(err)}",
                file=sys.stderr,
            )
            continue
        kept.append(path)
        frames.append(frame)
    if not frames:
        raise RenderError(f"{data}: no frame file can be read")
    return mesh, walls, kept, frames


def _npz(path: Path, names: tuple[str, ...]) -> dict:
    """Every array of the ``.npz`` file ``path``, read now (a cut file fails here, not
    later), which must have ``names``; ValueError (or OSError) otherwise."""
    if not zipfile.is_zipfile(path):
        raise ValueError(f"not a whole .npz file ({path.stat().st_size} bytes, cut short?)")
    try:
        with np.load(path, allow_pickle=False) as npz:
            arrays = {name: npz[name] for name in npz.files}
    except (zipfile.BadZipFile, EOFError) as err:
        raise ValueError(f"not a whole .npz file ({err})") from None
    missing = [name for name in names if name not in arrays]
    if missing:
        raise ValueError(f"no {', '.join(missing)}")
    return arrays


def _one_line(err: Exception) -> str:
    return " ".join(str(err).split()) or type(err).__name__


def body_grid(pyvista, mesh: dict, frame: dict):
    """The body of ``frame`` as a pyvista grid, on its deformed points X + u (m): true scale."""
    return pyvista.UnstructuredGrid(
        mesh["topology"], mesh["cell_types"], mesh["points"] + frame["u"]
    )


def _cell_size(mesh: dict) -> float:
    """The median length (m) of the first edge of the cells."""
    topology = mesh["topology"].reshape(len(mesh["cell_types"]), -1)
    first, second = mesh["points"][topology[:, 1]], mesh["points"][topology[:, 2]]
    return float(np.median(np.linalg.norm(second - first, axis=1)))


def _colour_bar(plotter, paint) -> None:
    """The colour bar under the picture: the bar from VTK, its title above it and its labels
    (in one format, at round values) under it, placed here: VTK's own placement lets them
    overlap the bar and each other."""
    plotter.add_scalar_bar(
        title=" ",
        n_labels=0,
        position_x=BAR[0],
        position_y=BAR[1],
        width=BAR[2],
        height=BAR[3],
    )
    plotter.scalar_bar.SetTitle("")
    plotter.scalar_bar.SetDrawTickLabels(False)
    plotter.scalar_bar.SetBarRatio(1.0)  # the bar fills its box
    (left, bottom), width = np.multiply(BAR[:2], WINDOW), BAR[2] * WINDOW[0]
    (low, high), n = paint.clim, paint.n_labels
    if paint.names:  # categories: each name under the middle of its colour
        labels = [(name, (i + 0.5) / n) for i, name in enumerate(paint.names)]
    else:  # + 0.0: no "-0"
        labels = [(paint.fmt % (low + (high - low) * i / (n - 1) + 0.0), i / (n - 1))
                  for i in range(n)]  # fmt: skip
    for text, at in labels:
        _centred_text(plotter, text, left + width * at, bottom - 20, 10)
    _centred_text(plotter, paint.title, WINDOW[0] / 2, bottom + BAR[3] * WINDOW[1] + 6, 11)


def _centred_text(plotter, text: str, x: float, y: float, size: int) -> None:
    """``text`` centred on ``x`` with its foot at ``y`` (pixels from the lower left)."""
    actor = plotter.add_text(text, position=(x, y), font_size=size, color="black")
    actor.GetTextProperty().SetJustificationToCentered()


def _time_unit(end: float) -> tuple[float, str]:
    """The unit of the time label: µs, ms or s, the largest that ``end`` (s) reaches."""
    return next(((s, name) for s, name in reversed(TIME_UNITS) if end >= s), TIME_UNITS[0])


def _time_decimals(frames: list[dict], scale: float) -> int:
    """Decimals that tell the frames apart: one more than the spacing of the frames needs."""
    if len(frames) < 2:
        return 1
    spacing = (float(frames[-1]["t"]) - float(frames[0]["t"])) / (len(frames) - 1) / scale
    return max(0, 1 - int(np.floor(np.log10(spacing)))) if spacing > 0 else 1


def _has_mp4_encoder() -> bool:
    try:
        import imageio_ffmpeg  # noqa: F401  (imageio's ffmpeg plugin runs its binary)
    except ImportError:
        return False
    return True


def main(argv: list[str] | None = None) -> int:
    """The command line of this module (also what ``rwall-fem render`` runs)."""
    parser = argparse.ArgumentParser(
        prog="python -m rwall_fem.output.render",
        description="Draw the stored frames of a run: frames/frame_NNNN.png, animation.gif.",
    )
    parser.add_argument("directory", help="results folder of a run with output.frames > 0")
    parser.add_argument(
        "--color",
        default=COLORS[0],
        help=f"{', '.join(COLORS)}, a cell field of the body such as plastic_strain, or part "
        f"(a body of parts) (default {COLORS[0]})",
    )
    args = parser.parse_args(argv)
    with interrupts.handling() as say:
        try:
            files = render_frames(args.directory, args.color)
        except RenderError as err:
            print(f"rwall-fem: error: {err}", file=sys.stderr)
            return 2
        except interrupts.Interrupted as stop:
            say(stop.reason)
            return 3
        except OSError as err:  # a picture that cannot be written
            print(f"rwall-fem: error: outputs: {_one_line(err)}", file=sys.stderr)
            return 4
    print(f"rwall-fem: {len(files)} frames and animation.gif in {args.directory}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
