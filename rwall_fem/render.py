"""Off-screen pictures of a run: ``python -m rwall_fem.render DIR``.

Reads the frame data that :class:`rwall_fem.frames.Frames` stored in
``DIR/frames/data`` and writes ``DIR/frames/frame_NNNN.png`` and
``DIR/animation.gif``. The body is drawn on its deformed geometry, coloured
by the velocity component along the first wall's normal, with the walls.
The camera and the colour range are fixed once for all frames. This module
must not import DOLFINx (see :mod:`rwall_fem.frames`).
"""

from __future__ import annotations

import json
import os
import sys
from pathlib import Path

import numpy as np

from rwall_fem.walls.shapes import shape_from_parameters

__all__ = ["render_frames"]


def render_frames(directory: str | Path) -> list[Path]:
    """Render every stored frame of the run in ``directory``; returns the PNG paths."""
    os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
    import imageio.v2 as imageio
    import pyvista

    directory = Path(directory)
    data = directory / "frames" / "data"
    mesh = np.load(data / "mesh.npz")
    points, speed = mesh["points"], float(mesh["speed"])
    walls = [shape_from_parameters(w) for w in json.loads(str(mesh["walls"]))]
    direction = walls[0].normals(points[:1]) if walls else np.array([0.0, 0.0, 1.0])
    label = "velocity along the wall normal (m/s)" if walls else "velocity z (m/s)"
    clim = (-1.2 * speed, 1.2 * speed) if speed > 0 else (-1.0, 1.0)
    size = float(np.ptp(points, axis=0).max())
    centre = points.mean(axis=0)
    camera, files = None, []
    for path in sorted(data.glob("frame_*.npz")):
        frame = np.load(path)
        grid = pyvista.UnstructuredGrid(mesh["topology"], mesh["cell_types"], points + frame["u"])
        grid.point_data[label] = frame["v"] @ direction
        plotter = pyvista.Plotter(off_screen=True, window_size=(800, 600))
        plotter.add_mesh(grid, show_edges=len(points) < 5000, clim=clim, cmap="coolwarm")
        for wall, offset in zip(walls, frame["offsets"], strict=True):
            surface = _wall_surface(pyvista, wall, offset, centre, size)
            plotter.add_mesh(surface, color="lightgray", opacity=0.6)
        plotter.add_text(f"t = {float(frame['t']) * 1e6:9.2f} us", font_size=12)
        if camera is None:
            plotter.camera_position = "iso"
            plotter.camera.zoom(1.6)
            camera = plotter.camera_position
        plotter.camera_position = camera
        png = directory / "frames" / path.with_suffix(".png").name
        plotter.screenshot(str(png))
        plotter.close()
        files.append(png)
    if files:
        images = [imageio.imread(p) for p in files]
        imageio.mimsave(directory / "animation.gif", images, duration=0.1, loop=0)
    return files


def _wall_surface(pyvista, shape, offset: np.ndarray, centre: np.ndarray, size: float):
    """A pyvista surface for ``shape`` translated by ``offset`` (m): an infinite plane as a
    square of side 1.5 x the body size below the body, a cylinder 1.5 x the body size long."""
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
    if len(sys.argv) != 2:
        sys.exit("usage: python -m rwall_fem.render RESULTS_DIR")
    render_frames(sys.argv[1])
