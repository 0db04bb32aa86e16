"""The geometry of the pictures: the walls as drawn, and the camera.

Walls are drawn where the body is: a plane (or a parallelogram) as a thin slab
on its forbidden side under the body's footprint, a cylinder as a tube without
end caps along the body's extent on its axis (it is infinite), a sphere whole.

The camera is parallel (orthographic, as in FE post-processors), the same for
every frame, with ``up`` pointing up (against gravity, else along the first
flat wall's normal). It looks along the horizontal direction in which the scene
is thinnest, so that the body's longer extent and its motion in that vertical
plane lie across the picture: 30 degrees round and 20 degrees above the horizon
as a rule; from 30 degrees up at a flat body (a plate), so that its face shows;
square along the body beside a finite wall, so that what hangs over the wall's
edge shows. Flat walls are always seen from their allowed side, so that they lie
behind the body: lower elevations are tried until they are (a body between a
floor and a press is seen level). ``[output.view]`` turns that camera (azimuth,
elevation), turns it to a cut face, zooms and centres it on a point. The view is
fitted to the body's deformed extent in every frame (not the walls', which are
context) with a margin, above the colour bar and up to the top of the picture, or
below the time when the body would reach into its corner (a Taylor rod's last frame,
two thirds as long as its first, fills more than half of the height). The body is
drawn at true scale by the renderer.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

__all__ = ["Surface", "View", "choose_view", "up_direction", "wall_surface"]

# (azimuth, elevation) of the camera (degrees), see above; then the elevations LOWER.
ANGLES = {"flat": (30.0, 30.0), "edge": (0.0, 20.0), "other": (30.0, 20.0)}
LOWER = (10.0, 0.0, -10.0, -20.0)
FLAT = 0.2  # a body is flat when its height is below this fraction of its width
MARGIN = 0.15  # walls reach this fraction of the scene's size beyond the body (m / m)
SLAB = 0.02  # thickness of a flat wall as a fraction of the scene's size
ROUND = 96  # points round a cylinder or a sphere's circles
# The band of the picture that the scene fills (fractions of the height from the bottom):
# the colour bar is drawn below it; the time is written above it at the top left, in a
# corner of TIME_CORNER pixels (width, height). A body clear of that corner may reach TOP.
BAND = (0.15, 0.90)
TOP = 0.985
TIME_CORNER = (180, 40)
FIT_MARGIN = 0.04  # the body's extent and this fraction of it fill the band
# A cut by a vertical plane is seen from this many degrees round up from its normal and
# this high; a cut by a horizontal plane from this far off the vertical.
CUT_TURN, CUT_ELEVATION = 25.0, 20.0


@dataclass(frozen=True)
class View:
    """A parallel camera: it looks at ``focal`` (m) from ``direction`` (unit, from the focal
    point to the camera) with ``up`` (unit) upward; ``scale`` (m) is half the picture's
    height."""

    focal: np.ndarray
    direction: np.ndarray
    up: np.ndarray
    scale: float

    def behind(self, shape) -> bool:
        """Whether the wall ``shape`` lies behind whatever is on its allowed side: a flat wall
        seen from that side."""
        return shape.kind in ("plane", "parallelogram") and shape.normal @ self.direction >= -1e-9

    def apply(self, renderer) -> None:
        """Set the camera of ``renderer`` (VTK's) to this view."""
        camera = renderer.GetActiveCamera()
        camera.ParallelProjectionOn()
        distance = 10.0 * self.scale
        camera.SetPosition(*(self.focal + distance * self.direction))
        camera.SetFocalPoint(*self.focal)
        camera.SetViewUp(*self.up)
        camera.SetParallelScale(self.scale)
        renderer.ResetCameraClippingRange()


class Surface(NamedTuple):
    """A wall as drawn: its ``points`` ((n, 3), m) and ``faces`` (VTK's legacy cell array,
    ``[k, i0, .., ik-1, k, ...]``)."""

    points: np.ndarray
    faces: np.ndarray


def up_direction(gravity, walls) -> np.ndarray:
    """Up: against ``gravity`` (m/s^2, or None), else the normal of the first flat wall,
    else +z."""
    if gravity is not None and np.linalg.norm(gravity) > 0:
        return -np.asarray(gravity, float) / np.linalg.norm(gravity)
    flat = [w for w in walls if w.kind in ("plane", "parallelogram")]
    return flat[0].normal.copy() if flat else np.array([0.0, 0.0, 1.0])


def choose_view(
    start: np.ndarray,
    clouds: list[np.ndarray],
    walls,
    up,
    aspect: float,
    *,
    azimuth: float | None = None,
    elevation: float | None = None,
    cut_normal=None,
    zoom: float = 1.0,
    focus=None,
    corner=(TIME_CORNER[0] / 800, TIME_CORNER[1] / 600),
) -> View:
    """The view of a run whose body starts at the points ``start`` ((n, 3), m) and whose
    drawn points are ``clouds`` ((n, 3) arrays, m: the body in every frame), for a picture
    ``aspect`` times wider than high; ``walls`` are the shapes, whose flat ones the camera
    looks at from their allowed side.

    ``azimuth`` (degrees) turns the camera round up from the direction chosen here,
    ``elevation`` (degrees) sets its height above the horizontal plane; ``cut_normal``
    (unit, toward the removed half of a cut) turns it toward the cut face, unless the
    angles are given. ``zoom`` magnifies the fitted view; ``focus`` (m) is the point at
    the centre of the picture (else the centre of the clouds). ``corner``: the time's
    corner (fractions of the width and height), which the body reaches up beside, not
    into."""
    points = np.concatenate(clouds)
    up = np.asarray(up, float)
    across, along = _horizontal_axes(points, up)
    height = np.ptp(start @ up)
    flat = height < FLAT * min(np.ptp(start @ across), np.ptp(start @ along))
    edge = any(w.kind == "parallelogram" for w in walls)
    auto_azimuth, auto_elevation = np.radians(ANGLES["flat" if flat else "edge" if edge else "other"])
    normals = [w.normal for w in walls if w.kind in ("plane", "parallelogram")]
    choices = [
        np.cos(e) * (np.cos(auto_azimuth) * a + np.sin(auto_azimuth) * b) + np.sin(e) * up
        for e in (auto_elevation, *np.radians([x for x in LOWER if x < np.degrees(auto_elevation)]))
        for a in (-across, across)
        for b in (-along, along)
    ]
    direction = next((d for d in choices if all(d @ n >= -1e-9 for n in normals)), choices[0])
    heading = _horizontal(direction, up, across)
    rise = float(np.arcsin(np.clip(direction @ up, -1.0, 1.0)))
    if cut_normal is not None and azimuth is None and elevation is None:
        normal = np.asarray(cut_normal, float)
        if np.linalg.norm(normal - (normal @ up) * up) > 0.1:  # a vertical plane: look at it
            heading = _turn(_horizontal(normal, up, across), up, np.radians(CUT_TURN))
            rise = np.radians(CUT_ELEVATION)
        else:  # a horizontal plane: look at it from above (or below)
            rise = np.sign(normal @ up) * np.radians(90.0 - CUT_ELEVATION)
    if azimuth is not None:
        heading = _turn(heading, up, np.radians(azimuth))
    if elevation is not None:
        rise = np.radians(elevation)
    direction = np.cos(rise) * heading + np.sin(rise) * up
    view_up = up - (up @ direction) * direction
    if np.linalg.norm(view_up) < 1e-6:  # straight down (up): the far side is the top
        view_up = -np.sign(direction @ up) * heading
    view_up /= np.linalg.norm(view_up)
    right = np.cross(view_up, direction)
    x, y = points @ right, points @ view_up
    depth = float((points @ direction).mean())
    fit = [x, y, right, view_up, direction, depth, aspect, zoom, focus]
    view = _framed(*fit, band=(BAND[0], TOP))
    if _in_corner(view, points, aspect, corner):  # under the time, not beside it
        view = _framed(*fit, band=BAND)
    return view


def _framed(x, y, right, up, direction, depth, aspect, zoom, focus, *, band) -> View:
    """The view along ``direction`` whose band (``band``: its bottom and top, fractions of
    the height) holds the points at ``x`` along ``right`` and ``y`` along ``up`` (m), with
    a margin, magnified by ``zoom``, centred on ``focus`` (or on them)."""
    low, high = band
    fit = max(np.ptp(y) / (2 * (high - low)), np.ptp(x) / (2 * 0.96 * aspect), 1e-12)
    scale = (1.0 + FIT_MARGIN) * fit / zoom
    if focus is None:
        centre = 0.5 * (x.min() + x.max()) * right + 0.5 * (y.min() + y.max()) * up
        centre += depth * direction
    else:
        centre = np.asarray(focus, float)
    # The middle of the band is above the middle of the picture by this much (m).
    lift = (0.5 * (low + high) - 0.5) * 2 * scale
    return View(centre - lift * up, direction, up, scale)


def _in_corner(view: View, points: np.ndarray, aspect: float, corner) -> bool:
    """Whether some of ``points`` (m) lie in the picture's top left ``corner`` (fractions of
    the width and height) seen by ``view``."""
    right = np.cross(view.up, view.direction)
    across = ((points - view.focal) @ right / view.scale + aspect) / (2 * aspect)
    height = 0.5 * ((points - view.focal) @ view.up / view.scale + 1.0)
    inside = (across >= 0.0) & (across < corner[0]) & (height > 1.0 - corner[1]) & (height <= 1.0)
    return bool(inside.any())


def _horizontal(vector: np.ndarray, up: np.ndarray, fallback: np.ndarray) -> np.ndarray:
    """The unit horizontal part of ``vector`` (normal to ``up``), or ``fallback``."""
    flat = vector - (vector @ up) * up
    norm = np.linalg.norm(flat)
    return flat / norm if norm > 1e-9 else fallback


def _turn(vector: np.ndarray, up: np.ndarray, angle: float) -> np.ndarray:
    """``vector`` (normal to ``up``) turned by ``angle`` (rad) round ``up``."""
    return np.cos(angle) * vector + np.sin(angle) * np.cross(up, vector)


def wall_surface(shape, offset: np.ndarray, body: np.ndarray, size: float) -> Surface:
    """The surface of ``shape`` translated by ``offset`` (m), drawn where the ``body``
    ((n, 3) points, m: of every frame) is, in a scene of ``size`` (m)."""
    margin = MARGIN * size
    point = shape.point + offset
    if shape.kind == "cylinder":
        along = (body - point) @ shape.axis
        low, high = along.min() - margin, along.max() + margin
        ring = _circle(shape.axis, shape.radius, ROUND)
        points = np.vstack([point + low * shape.axis + ring, point + high * shape.axis + ring])
        k = np.arange(ROUND)
        quads = np.column_stack([k, (k + 1) % ROUND, ROUND + (k + 1) % ROUND, ROUND + k])
        return Surface(points, _cells(quads))  # no end caps: the cylinder is infinite
    if shape.kind == "sphere":
        polar = np.linspace(0.0, np.pi, ROUND // 2 + 1)[1:-1]
        axis = np.array([0.0, 0.0, 1.0])
        rings = [shape.radius * np.cos(a) * axis + _circle(axis, shape.radius * np.sin(a), ROUND)
                 for a in polar]  # fmt: skip
        poles = np.array([axis, -axis]) * shape.radius
        points = point + np.vstack([*rings, poles])
        k, top, bottom = np.arange(ROUND), len(points) - 2, len(points) - 1
        quads = [np.column_stack([r * ROUND + k, r * ROUND + (k + 1) % ROUND,
                                  (r + 1) * ROUND + (k + 1) % ROUND, (r + 1) * ROUND + k])
                 for r in range(len(polar) - 1)]  # fmt: skip
        last = (len(polar) - 1) * ROUND
        caps = [np.column_stack([np.full(ROUND, top), (k + 1) % ROUND, k]),
                np.column_stack([np.full(ROUND, bottom), last + k, last + (k + 1) % ROUND])]
        return Surface(points, np.concatenate([_cells(q) for q in (*quads, *caps)]))
    if shape.kind == "parallelogram":
        corners = point + np.array([[0, 0], [1, 0], [1, 1], [0, 1]]) @ shape.sides
    else:  # an infinite plane: under the body's footprint, with a margin
        e1 = np.cross(shape.normal, np.eye(3)[np.argmin(np.abs(shape.normal))])
        e1 /= np.linalg.norm(e1)
        e2 = np.cross(shape.normal, e1)
        a, b = (body - point) @ e1, (body - point) @ e2
        footprint = [[a.min(), b.min()], [a.max(), b.min()], [a.max(), b.max()], [a.min(), b.max()]]
        outward = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]])
        corners = point + (np.array(footprint) + margin * outward) @ [e1, e2]
    return _slab(corners, -SLAB * size * shape.normal)


def _circle(axis: np.ndarray, radius: float, n: int) -> np.ndarray:
    """``n`` points (m) of the circle of ``radius`` round the origin, normal to ``axis``."""
    first = np.cross(axis, np.eye(3)[np.argmin(np.abs(axis))])
    first /= np.linalg.norm(first)
    second = np.cross(axis, first)
    angle = np.linspace(0.0, 2 * np.pi, n, endpoint=False)[:, None]
    return radius * (np.cos(angle) * first + np.sin(angle) * second)


def _cells(faces: np.ndarray) -> np.ndarray:
    """VTK's legacy cell array of ``faces`` ((m, k) point indices)."""
    faces = np.asarray(faces)
    return np.column_stack([np.full(len(faces), faces.shape[1]), faces]).ravel()


def _slab(corners: np.ndarray, depth: np.ndarray) -> Surface:
    """The closed box whose top face is the quadrilateral ``corners`` (4, 3) and whose
    bottom face is that face moved by ``depth`` (m)."""
    points = np.vstack([corners, corners + depth])
    faces = [[0, 1, 2, 3], [7, 6, 5, 4], [0, 4, 5, 1], [1, 5, 6, 2], [2, 6, 7, 3], [3, 7, 4, 0]]
    return Surface(points, _cells(np.array(faces)))


def _horizontal_axes(points: np.ndarray, up: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two unit vectors normal to ``up``: the one along which ``points`` extend less (the
    camera looks along it), then the other."""
    first = np.eye(3)[np.argmin(np.abs(up))]
    first = first - (first @ up) * up
    first /= np.linalg.norm(first)
    second = np.cross(up, first)
    if np.ptp(points @ first) < np.ptp(points @ second):
        return first, second
    return second, first
