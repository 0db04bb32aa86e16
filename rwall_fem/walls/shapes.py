"""Wall shapes: signed distance to the surface and the normal pointing to the allowed side.

A shape answers for many nodes at once: ``x`` has shape (n, 3) in metres.
``offset`` (m) is the wall's translation from its initial position (moving walls).
"""

from __future__ import annotations

import numpy as np

__all__ = ["PlaneWall", "shape_from_parameters"]


class PlaneWall:
    """Infinite plane through ``point`` (M) with normal along ``normal_point - point`` (M1 - M).

    The allowed side is d = (x - M) . n >= 0.
    """

    kind = "plane"
    radial = False  # the normal does not depend on the node position

    def __init__(self, point, normal_point):
        self.point = np.asarray(point, dtype=float)
        normal = np.asarray(normal_point, dtype=float) - self.point
        length = np.linalg.norm(normal)
        if not length > 0:
            raise ValueError("normal_point must differ from point")
        self.normal = normal / length

    def parameters(self) -> dict:
        """The defining points, as plain lists (for files and for :func:`shape_from_parameters`)."""
        return {"point": self.point.tolist(), "normal_point": (self.point + self.normal).tolist()}

    def distance(self, x: np.ndarray, offset=0.0) -> np.ndarray:
        """Signed distance (m) of the points ``x`` (n, 3) to the plane; negative behind it."""
        return (x - (self.point + offset)) @ self.normal

    def normals(self, x: np.ndarray, offset=0.0) -> np.ndarray:
        """Unit normal (3,) toward the allowed side, the same for every point."""
        return self.normal


def shape_from_parameters(parameters: dict):
    """The shape described by ``{"kind": ..., **shape.parameters()}``."""
    shapes = {"plane": PlaneWall}
    arguments = dict(parameters)
    return shapes[arguments.pop("kind")](**arguments)
