"""Off-screen pictures of a run: PNG frames and an animated GIF, drawn on rank 0.

Each rank sends its cells, points and nodal values to rank 0 (connectivity
offset by the points already received); rank 0 draws the body on the
deformed geometry, coloured by the velocity component along the first
wall's normal, with the walls at their current positions. The camera and the
colour range are fixed from the first frame so that frames compare.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
from dolfinx import fem

from rwall_fem import _compat

__all__ = ["Frames"]


class Frames:
    """Recorder that renders ``count`` frames evenly over the run into ``directory/frames``."""

    def __init__(self, directory: Path, count: int, num_steps: int, V, walls, speed: float):
        self.every = max(1, num_steps // max(count - 1, 1))
        self.directory = Path(directory) / "frames"
        self.V, self.walls = V, walls
        self.comm = V.mesh.comm
        self.direction = walls[0].shape.normals(np.zeros((1, 3))) if walls else None
        self.clim = (-1.2 * speed or -1.0, 1.2 * speed or 1.0)
        self._field = fem.Function(V)
        topology, cell_types, points = _compat.vtk_mesh(V)
        self._mesh = self._gather((np.asarray(topology), np.asarray(cell_types), points))
        self._camera = None
        self.files: list[Path] = []

    def _gather(self, local):
        pieces = self.comm.gather(local, root=0)
        if self.comm.rank != 0:
            return None
        topologies, types, points, offset = [], [], [], 0
        for topology, cell_types, x in pieces:
            # VTK's cell array is [n, i0, .., in-1, n, ...]: shift the indices only.
            topology = topology.reshape(len(cell_types), -1).copy()
            topology[:, 1:] += offset
            topologies.append(topology.ravel())
            types.append(cell_types)
            points.append(x)
            offset += len(x)
        return np.concatenate(topologies), np.concatenate(types), np.concatenate(points)

    def _nodal(self, values: np.ndarray) -> np.ndarray | None:
        f = self._field
        n = values.size
        f.x.array[:n] = values.ravel()
        f.x.scatter_forward()
        gathered = self.comm.gather(f.x.array.reshape(-1, 3).copy(), root=0)
        return None if gathered is None else np.concatenate(gathered)

    def record(self, sim, s) -> None:
        u, v = self._nodal(s.u), self._nodal(s.v)
        if self.comm.rank == 0:
            self._draw(s.t, u, v)

    def _draw(self, t: float, u: np.ndarray, v: np.ndarray) -> None:
        os.environ.setdefault("VTK_DEFAULT_OPENGL_WINDOW", "vtkEGLRenderWindow")
        import pyvista

        topology, cell_types, points = self._mesh
        grid = pyvista.UnstructuredGrid(topology, cell_types, points + u)
        direction = self.direction if self.direction is not None else np.array([0, 0, 1.0])
        grid.point_data["velocity along wall normal (m/s)"] = v @ direction
        plotter = pyvista.Plotter(off_screen=True, window_size=(800, 600))
        plotter.add_mesh(grid, show_edges=True, clim=self.clim, cmap="coolwarm")
        size = float(np.ptp(points, axis=0).max())
        centre = points.mean(axis=0)
        for wall in self.walls:
            plotter.add_mesh(_wall_surface(wall.shape, centre, size), color="lightgray", opacity=0.6)
        plotter.add_text(f"t = {t * 1e6:9.2f} us", font_size=12)
        if self._camera is None:
            plotter.camera_position = "iso"
            plotter.camera.zoom(1.2)
            self._camera = plotter.camera_position
        plotter.camera_position = self._camera
        path = self.directory / f"frame_{len(self.files):04d}.png"
        path.parent.mkdir(parents=True, exist_ok=True)
        plotter.screenshot(str(path))
        plotter.close()
        self.files.append(path)

    def close(self, sim) -> None:
        """Assemble the frames into ``animation.gif`` next to the frame folder."""
        if self.comm.rank != 0 or not self.files:
            return
        import imageio.v2 as imageio

        images = [imageio.imread(p) for p in self.files]
        imageio.mimsave(self.directory.parent / "animation.gif", images, duration=0.1, loop=0)


def _wall_surface(shape, centre: np.ndarray, size: float):
    """A pyvista surface for ``shape``: the plane as a square of side 1.5 x body size."""
    import pyvista

    normal = shape.normals(centre[None, :])
    foot = centre - shape.distance(centre[None, :])[0] * normal
    return pyvista.Plane(center=foot, direction=normal, i_size=1.5 * size, j_size=1.5 * size)
