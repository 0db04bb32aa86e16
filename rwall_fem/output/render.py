"""Off-screen pictures of a run: ``python -m rwall_fem.output.render DIR [COLOR]``.

Reads the frame data that :class:`rwall_fem.output.frames.Frames` stored in
``DIR/frames/data`` and writes ``DIR/frames/frame_NNNN.png`` and
``DIR/animation.gif``, and ``DIR/animation.mp4`` when the ``imageio-ffmpeg``
encoder is installed (``pip install rwall_fem[mp4]``). The body is drawn on
its deformed geometry, coloured by one of :data:`COLORS`, with the walls.
The camera and the colour range are fixed once for all frames. This module
must not import DOLFINx (see :mod:`rwall_fem.output.frames`).
"""

from __future__ import annotations

import json
import os
import sys
from pathlib import Path

import numpy as np

from rwall_fem.walls.shapes import shape_from_parameters

__all__ = ["COLORS", "render_frames"]

# What the body can be coloured by: the velocity along the first wall's normal (m/s),
# the speed (m/s) or the magnitude of the displacement (m).
COLORS = ("normal_velocity", "speed", "displacement")


def render_frames(directory: str | Path, color: str = "normal_velocity") -> list[Path]:
    """Render every stored frame of the run in ``directory``, coloured by ``color`` (one of
    :data:`COLORS`); returns the PNG paths."""
    os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    import imageio.v2 as imageio
    import pyvista

    directory = Path(directory)
    data = directory / "frames" / "data"
    mesh = np.load(data / "mesh.npz")
    points, speed = mesh["points"], float(mesh["speed"])
    walls = [shape_from_parameters(w) for w in json.loads(str(mesh["walls"]))]
    frames = [dict(np.load(path)) for path in sorted(data.glob("frame_*.npz"))]
    values = [_color_values(color, f, walls, points) for f in frames]
    label = _color_label(color, walls)
    top = max(float(np.abs(v).max(initial=0.0)) for v in values) or 1.0
    clim = (
        (-1.2 * max(speed, top), 1.2 * max(speed, top))
        if color == "normal_velocity"
        else (0.0, top)
    )
    # One box for the whole run: it fixes the camera and the size of the walls drawn.
    moved = np.concatenate([points + f["u"] for f in frames])
    low, high = moved.min(axis=0), moved.max(axis=0)
    centre, size = 0.5 * (low + high), float((high - low).max())
    end = float(frames[-1]["t"]) if frames else 0.0
    unit, scale = ("us", 1e6) if end < 1e-3 else ("ms", 1e3) if end < 1.0 else ("s", 1.0)
    camera, files = None, []
    for path, frame, value in zip(sorted(data.glob("frame_*.npz")), frames, values, strict=True):
        grid = pyvista.UnstructuredGrid(mesh["topology"], mesh["cell_types"], points + frame["u"])
        grid.point_data[label] = value
        plotter = pyvista.Plotter(off_screen=True, window_size=(800, 600))
        plotter.add_mesh(
            grid, show_edges=len(points) < 1000, edge_color="dimgray", clim=clim, cmap="coolwarm"
        )
        for wall, offset in zip(walls, frame["offsets"], strict=True):
            surface = _wall_surface(pyvista, wall, offset, centre, size)
            plotter.add_mesh(surface, color="lightgray", opacity=0.6)
        plotter.add_text(f"t = {float(frame['t']) * scale:9.3f} {unit}", font_size=12)
        if camera is None:
            plotter.camera_position = "iso"
            margin = 0.15 * size
            plotter.reset_camera(bounds=np.ravel([low - margin, high + margin], order="F"))
            camera = plotter.camera_position
        plotter.camera_position = camera
        png = directory / "frames" / path.with_suffix(".png").name
        plotter.screenshot(str(png))
        plotter.close()
        files.append(png)
    if files:
        images = [imageio.imread(p) for p in files]
        imageio.mimsave(directory / "animation.gif", images, duration=0.1, loop=0)
        if _has_mp4_encoder():
            imageio.mimsave(directory / "animation.mp4", images, fps=10, macro_block_size=8)
    return files


def _has_mp4_encoder() -> bool:
    try:
        import imageio_ffmpeg  # noqa: F401  (imageio's ffmpeg plugin runs its binary)
    except ImportError:
        return False
    return True


def _color_label(color: str, walls) -> str:
    if color == "normal_velocity":
        return "velocity along the wall normal (m/s)" if walls else "velocity z (m/s)"
    return {"speed": "speed (m/s)", "displacement": "displacement (m)"}[color]


def _color_values(color: str, frame: dict, walls, points: np.ndarray) -> np.ndarray:
    if color == "normal_velocity":
        normal = walls[0].normals(points[:1]) if walls else np.array([0.0, 0.0, 1.0])
        return frame["v"] @ np.broadcast_to(normal, (1, 3))[0]
    field = frame["v"] if color == "speed" else frame["u"]
    return np.linalg.norm(field, axis=1)


def _wall_surface(pyvista, shape, offset: np.ndarray, centre: np.ndarray, size: float):
    """A pyvista surface for ``shape`` translated by ``offset`` (m): an infinite plane as a
    square of side 1.5 ``size`` under ``centre``, a cylinder 1.5 ``size`` long."""
    point = shape.point + offset
    if shape.kind == "plane":
        foot = centre - shape.distance(centre[None, :], offset)[0] * shape.normal
        return pyvista.Plane(
            center=foot, direction=shape.normal, i_size=1.5 * size, j_size=1.5 * size
        )
    if shape.kind == "parallelogram":
        corners = point + np.array(
            [0 * shape.sides[0], shape.sides[0], shape.sides[0] + shape.sides[1], shape.sides[1]]
        )
        return pyvista.PolyData(corners, faces=[4, 0, 1, 2, 3])
    if shape.kind == "cylinder":
        foot = point + ((centre - point) @ shape.axis) * shape.axis
        length = max(1.5 * size, 2.5 * shape.radius)
        return pyvista.Cylinder(
            center=foot, direction=shape.axis, radius=shape.radius, height=length, resolution=96
        )
    return pyvista.Sphere(radius=shape.radius, center=point, theta_resolution=64, phi_resolution=64)


if __name__ == "__main__":
    if len(sys.argv) not in (2, 3) or sys.argv[2:] and sys.argv[2] not in COLORS:
        sys.exit(f"usage: python -m rwall_fem.output.render RESULTS_DIR [{'|'.join(COLORS)}]")
    render_frames(*sys.argv[1:])
