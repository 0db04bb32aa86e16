"""Off-screen pictures of a run: ``python -m rwall_fem.output.render DIR [--color COLOR]
[--view VIEW]``.

Reads the frame data that :class:`rwall_fem.output.frames.Frames` stored in
``DIR/frames/data`` and writes ``DIR/frames/frame_NNNN.png`` and
``DIR/animation.gif``, and ``DIR/animation.mp4`` when the ``imageio-ffmpeg``
encoder is installed (``pip install rwall_fem[mp4]``). The body is drawn on
its deformed geometry at true scale (no magnification), without its eroded cells (the
nodes no live cell holds are drawn as points), coloured as
:mod:`rwall_fem.output.coloring` says, with the walls as
:mod:`rwall_fem.output.view` draws them: flat walls opaque (the camera sees
them from their allowed side, behind the body), curved walls translucent with
their outline, seen as the run's ``[output.view]`` (or ``--view``) says
(:mod:`rwall_fem.scene.view`: a cut, the camera, the size, the colour range). The camera
and the colour range are fixed once for all frames, which one scene
(:mod:`rwall_fem.output.picture`) draws in turn. This module must not import DOLFINx (see
:mod:`rwall_fem.output.frames`). With ``--follow PID`` it is the renderer beside a running
run (:mod:`rwall_fem.output.worker`).
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import signal
import sys
import threading
import time
import zipfile
from pathlib import Path

import numpy as np

from rwall_fem import interrupts
from rwall_fem.output.atomic import whole
from rwall_fem.output.coloring import COLORS, coloring, fixed_range
from rwall_fem.output.view import TIME_CORNER, choose_view, up_direction, wall_surface
from rwall_fem.scene.view import ViewSpec, parse_view_text, view_from_json
from rwall_fem.scene.keys import SceneError
from rwall_fem.walls.shapes import shape_from_parameters

__all__ = ["COLORS", "RenderError", "main", "render_frames"]

EDGES = 10  # pixels: the cell edges are drawn when cells are at least this large
PNG_COMPRESSION = 3  # zlib level of the PNGs: nearly the size of 9 in a fraction of the time
TIME_UNITS = ((1e-6, "µs"), (1e-3, "ms"), (1.0, "s"))  # the largest below the end time


class RenderError(ValueError):
    """The pictures cannot be drawn from what the folder holds (one line)."""


def render_frames(
    directory: str | Path,
    color: str = "normal_velocity",
    view: ViewSpec | None = None,
    read: dict[str, dict] | None = None,
) -> list[Path]:
    """Render every stored frame of the run in ``directory``, coloured by ``color`` (one of
    :data:`COLORS` or a cell field the run stored), seen as ``view`` says (None: the view
    the run stored, else the automatic one); returns the PNG paths. ``read``: the arrays
    of frame files already read, by file name.

    Raises RenderError for a folder without frame data, an unknown colouring or a view
    the body cannot give (a part it does not have).
    """
    from rwall_fem.output.picture import Picture  # VTK: imported when drawing only

    directory = Path(directory)
    mesh, walls, paths, frames = _stored(directory, read or {})
    view = _stored_view(mesh) if view is None else view
    points = mesh["points"]
    up = up_direction(mesh.get("gravity"), walls)
    parts = tuple(json.loads(str(mesh["parts"]))) if "parts" in mesh else ()
    try:
        paint = coloring(color, frames, points, walls, up, float(mesh["speed"]), parts)
    except ValueError as err:
        raise RenderError(str(err)) from None
    if view.range != "auto":
        paint = fixed_range(paint, *view.range)
    body = np.concatenate([points + f["u"] for f in frames])
    size = float(np.ptp(body, axis=0).max())
    cut = _cut_plane(view.cut, points)
    window = tuple(view.size)
    camera = choose_view(
        points + frames[0]["u"], [body], walls, up, window[0] / window[1],
        azimuth=view.azimuth, elevation=view.elevation, zoom=view.zoom,
        cut_normal=None if cut is None else cut[1], focus=_focus(view.focus, mesh, frames, parts),
        corner=(TIME_CORNER[0] / window[0], TIME_CORNER[1] / window[1]),
    )  # fmt: skip
    if cut is not None and isinstance(view.cut, str) and cut[1] @ camera.direction < 0:
        cut = (cut[0], -cut[1])  # an axis cut removes the half nearer the camera
    edges = bool(_cell_size(mesh) >= EDGES * 2 * camera.scale / window[1])
    scale, unit = _time_unit(float(frames[-1]["t"]))
    decimals = _time_decimals(frames, scale)
    surfaces: dict = {}  # the walls as drawn, by their offsets (most walls do not move)
    files, images = [], []
    # The scene is made once; a frame is not cut by a stop signal (interrupts.deferred:
    # it is raised after the frame), and the window is closed however the frames end: a
    # VTK window left half made or half closed fails in its destructor at exit.
    with interrupts.deferred():
        picture = Picture(
            mesh, paint, camera, window, erodes="cell_eroded" in frames[0],
            cut=cut, ghost=view.ghost, edges=edges,
        )  # fmt: skip
    try:
        for path, frame, values in zip(paths, frames, paint.values, strict=True):
            with interrupts.deferred():
                offsets = frame["offsets"]
                drawn = surfaces.get(offsets.tobytes())
                if drawn is None:
                    drawn = [wall_surface(w, o, body, size)
                             for w, o in zip(walls, offsets, strict=True)]  # fmt: skip
                    surfaces[offsets.tobytes()] = drawn
                picture.set_walls(walls, drawn)
                time = f"t = {float(frame['t']) / scale:.{decimals}f} {unit}"
                image = picture.draw(
                    frame["u"], values, frame.get("cell_eroded"), frame.get("detached"), time
                )
                png = directory / "frames" / path.with_suffix(".png").name
                _write_png(image, png)
            files.append(png)
            images.append(image)
    finally:
        picture.close()
    _animate(directory, images)
    return files


def _write_png(image: np.ndarray, path: Path) -> None:
    from PIL import Image

    with whole(path) as partial:
        Image.fromarray(image).save(partial, compress_level=PNG_COMPRESSION)


def _animate(directory: Path, images: list[np.ndarray]) -> None:
    """``animation.gif`` (one palette for every frame: no flicker, one quantization) and
    ``animation.mp4`` when the encoder is installed, each encoded once."""
    from PIL import Image

    frames = [Image.fromarray(image) for image in images]
    palette = frames[len(frames) // 2].quantize(colors=255, method=Image.Quantize.FASTOCTREE)
    gif = [f.quantize(palette=palette, dither=Image.Dither.NONE) for f in frames]
    with whole(directory / "animation.gif") as partial:
        gif[0].save(partial, save_all=True, append_images=gif[1:], duration=100, loop=0)
    if _has_mp4_encoder():
        import imageio.v2 as imageio

        with whole(directory / "animation.mp4") as partial:
            imageio.mimsave(partial, images, fps=10, macro_block_size=8)


def _stored_view(mesh: dict) -> ViewSpec:
    """The view the run stored with its frame data (the scene's [output.view])."""
    if "view" not in mesh:
        return ViewSpec()
    try:
        return view_from_json(json.loads(str(mesh["view"])), "frames/data/mesh.npz")
    except (ValueError, SceneError) as err:
        raise RenderError(f"{_one_line(err)}") from None


def _cut_plane(cut, points: np.ndarray):
    """(point, unit normal) of the clipping plane ``cut`` ("x", "y", "z" through the centre
    of the body's box ``points``, or {point, normal}), or None; RenderError for a plane
    that misses the body."""
    if cut is None:
        return None
    if isinstance(cut, str):
        centre = 0.5 * (points.min(axis=0) + points.max(axis=0))
        return centre, np.eye(3)["xyz".index(cut)]
    point, normal = np.asarray(cut["point"], float), np.asarray(cut["normal"], float)
    normal /= np.linalg.norm(normal)
    side = (points - point) @ normal
    if not side.min() < 0.0 < side.max():
        raise RenderError(f"view.cut: the plane through {list(cut['point'])} normal to "
                          f"{list(cut['normal'])} does not cut the body (all its nodes lie on "
                          "one side at the start); give a plane through it")  # fmt: skip
    return point, normal


def _focus(focus, mesh: dict, frames: list[dict], parts: tuple[str, ...]):
    """The point (m) at the picture's centre: ``focus`` itself, or the centre of the box of
    the part it names at the start; None for the automatic centre."""
    if focus is None or not isinstance(focus, str):
        return focus
    if focus not in parts or "cell_part" not in frames[0]:
        have = f"its parts: {', '.join(parts)}" if parts else "a body without [[part]]"
        raise RenderError(f"view.focus: {focus!r} is not a part of this body ({have})")
    topology = mesh["topology"].reshape(len(mesh["cell_types"]), -1)[:, 1:]
    cells = topology[frames[0]["cell_part"] == parts.index(focus)]
    x = (mesh["points"] + frames[0]["u"])[np.unique(cells)]
    return 0.5 * (x.min(axis=0) + x.max(axis=0))


def _stored(directory: Path, read: dict[str, dict]):
    """The body (``mesh.npz`` as a dict), the wall shapes, and the frame files that
    ``directory`` holds with their contents (those in ``read``, by name, are not read
    again); RenderError when there are none or the body cannot be read. A frame file that
    cannot be read (cut short by a kill or a full disk) or does not fit the body is left
    out, with a warning line."""
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
            frame = read.get(path.name) or _npz(path, ("t", "u", "v", "offsets"))
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


def _cell_size(mesh: dict) -> float:
    """The median length (m) of the first edge of the cells."""
    topology = mesh["topology"].reshape(len(mesh["cell_types"]), -1)
    first, second = mesh["points"][topology[:, 1]], mesh["points"][topology[:, 2]]
    return float(np.median(np.linalg.norm(second - first, axis=1)))


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


def _follow(directory: Path, parent: int) -> dict[str, dict] | None:
    """Beside a running run (:mod:`rwall_fem.output.worker`): import what draws, then read
    each frame file whose name arrives on stdin until ``end``; returns what was read, or
    None when stdin ends first (the run is gone or does not want the pictures). When
    the process ``parent`` ends, this one is sent SIGTERM: it never draws on after it."""
    threading.Thread(target=_watch_parent, args=(parent,), daemon=True).start()
    from PIL import Image  # noqa: F401  (imported now, while the loop runs)

    from rwall_fem.output import picture  # noqa: F401
    read = {}
    for line in sys.stdin:
        name = line.strip()
        if name == "end":
            return read
        with contextlib.suppress(OSError, ValueError):  # read again, and judged, at the end
            read[name] = _npz(directory / "frames" / "data" / name, ("t", "u", "v", "offsets"))
    return None


def _watch_parent(parent: int) -> None:
    while os.getppid() == parent:
        time.sleep(0.1)
    os.kill(os.getpid(), signal.SIGTERM)


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
    parser.add_argument(
        "--view",
        help="the keys of [output.view] as a TOML inline table's inside, e.g. "
        "'cut = \"y\", zoom = 1.5' (default: the run's view)",
    )
    parser.add_argument("--follow", metavar="PID", type=int, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    with interrupts.handling() as say:
        try:
            view = None if args.view is None else parse_view_text(args.view)
            read = None
            if args.follow is not None:  # beside the run of process PID (output.worker)
                read = _follow(Path(args.directory), args.follow)
                if read is None:
                    return 0  # the run ended without asking for the pictures
            files = render_frames(args.directory, args.color, view, read)
        except (RenderError, SceneError) as err:
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
