"""Wall shapes: signed distance to the surface and the normal toward the allowed side.

A shape answers for many nodes at once: ``x`` has shape (n, 3) in metres and
``offset`` (3,) is the wall's translation from its initial position (moving
walls translate, never rotate). Distances are in metres, negative on the
forbidden side.

``clearance`` is what the wall constraint uses to skip nodes far from the wall:
a lower bound (m) on how far a point must move, relative to the wall, before
the wall can treat it (zero or negative if it may treat it now). It changes by
at most |dx| when the point moves by dx.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "SHAPES",
    "CylinderWall",
    "ParallelogramWall",
    "PlaneWall",
    "SphereWall",
    "shape_from_parameters",
]

_TINY = 1e-300


def _unit(vector, what: str) -> np.ndarray:
    """``vector`` of length 1; ValueError (one line) when it has no direction or overflowed."""
    vector = np.asarray(vector, dtype=float)
    if not np.isfinite(vector).all():
        raise ValueError(
            f"{what} overflows a double (points about 1e308 m apart); keep the points within "
            "1e300 m"
        )
    largest = np.abs(vector).max()
    if largest == 0:
        raise ValueError(f"{what} has no direction")
    vector = vector / largest  # the norm of components near 1e308 would overflow
    return vector / np.linalg.norm(vector)


class PlaneWall:
    """Infinite plane through ``point`` (M) with normal along ``normal_point - point`` (M1 - M).

    The allowed side is d = (x - M) . n >= 0.
    """

    kind = "plane"

    def __init__(self, point, normal_point):
        self.point = np.asarray(point, dtype=float)
        self.normal = _unit(
            np.asarray(normal_point, dtype=float) - self.point, "normal_point - point"
        )

    def parameters(self) -> dict:
        """The defining points as lists (for files and :func:`shape_from_parameters`)."""
        return {"point": self.point.tolist(), "normal_point": (self.point + self.normal).tolist()}

    def distance(self, x: np.ndarray, offset=0.0) -> np.ndarray:
        """Signed distance (m) of the points ``x`` (n, 3) to the plane."""
        return (x - (self.point + offset)) @ self.normal

    def clearance(self, x: np.ndarray, offset=0.0) -> np.ndarray:
        """Signed distance (m): a node can be treated only once it is behind the plane."""
        return self.distance(x, offset)

    def normals(self, x: np.ndarray, offset=0.0) -> np.ndarray:
        """Unit normal (3,) toward the allowed side, the same for every point."""
        return self.normal

    def inside_patch(self, x: np.ndarray, offset=0.0):
        """Every point of an infinite plane can touch it."""
        return True


class ParallelogramWall(PlaneWall):
    """Finite plane: the parallelogram M + a L1 + b L2, 0 <= a, b <= 1, L1 = M1 - M, L2 = M2 - M.

    n = unit(L1 x L2); the allowed side is d >= 0. Only points whose projection
    falls inside the parallelogram can touch it.
    """

    kind = "parallelogram"

    def __init__(self, point, corner1, corner2):
        self.point = np.asarray(point, dtype=float)
        self.sides = np.array([corner1, corner2], dtype=float) - self.point  # L1, L2
        self.normal = _unit(np.cross(*self.sides), "(M1 - M) x (M2 - M)")
        # (a, b) = dual @ r for r in the plane (the inverse Gram matrix @ (L1 . r, L2 . r)).
        self.dual = np.linalg.solve(self.sides @ self.sides.T, self.sides)
        # Width (m) of the parallelogram across each pair of sides: a moves by at most
        # |dx| / width_a when x moves by dx.
        self.widths = 1.0 / np.linalg.norm(self.dual, axis=1)

    def parameters(self) -> dict:
        return {
            "point": self.point.tolist(),
            "corner1": (self.point + self.sides[0]).tolist(),
            "corner2": (self.point + self.sides[1]).tolist(),
        }

    def inside_patch(self, x: np.ndarray, offset=0.0) -> np.ndarray:
        """Whether the projections of ``x`` on the plane fall inside the parallelogram."""
        ab = (x - (self.point + offset)) @ self.dual.T
        return np.all((ab >= 0.0) & (ab <= 1.0), axis=1)

    def clearance(self, x: np.ndarray, offset=0.0) -> np.ndarray:
        """The larger of the signed distance to the plane and a lower bound on the distance
        to the prism over the parallelogram (m): a node is treated only inside the prism
        and behind the plane."""
        ab = (x - (self.point + offset)) @ self.dual.T
        beside = np.maximum(-ab, ab - 1.0) * self.widths
        return np.maximum(self.distance(x, offset), beside.max(axis=1))


class _RoundWall:
    """Shared by the cylinder and the sphere: distance and normal from a radial vector;
    the normal follows the node (taken at its current position)."""

    def distance(self, x: np.ndarray, offset=0.0) -> np.ndarray:
        return np.linalg.norm(self._radial(x, offset), axis=1) - self.radius

    def clearance(self, x: np.ndarray, offset=0.0) -> np.ndarray:
        """Signed distance (m): a node can be treated only once it is inside."""
        return self.distance(x, offset)

    def normals(self, x: np.ndarray, offset=0.0) -> np.ndarray:
        """Unit radial normals (n, 3); a point on the axis or at the centre gets ``fallback``."""
        r = self._radial(x, offset)
        length = np.linalg.norm(r, axis=1, keepdims=True)
        degenerate = length[:, 0] <= 1e-12 * self.radius
        n = r / np.maximum(length, _TINY)
        n[degenerate] = self.fallback
        return n

    def inside_patch(self, x: np.ndarray, offset=0.0):
        return True


class CylinderWall(_RoundWall):
    """Infinite cylinder of ``diameter`` (m) about the axis through ``point`` and ``axis_point``.

    Contact from outside only (radial distance >= D/2), no end caps.
    """

    kind = "cylinder"

    def __init__(self, point, axis_point, diameter: float):
        self.point = np.asarray(point, dtype=float)
        self.axis = _unit(np.asarray(axis_point, dtype=float) - self.point, "axis_point - point")
        if not diameter > 0:
            raise ValueError("diameter must be > 0")
        self.radius = 0.5 * float(diameter)
        # Any unit vector normal to the axis, for nodes exactly on it.
        helper = np.eye(3)[np.argmin(np.abs(self.axis))]
        self.fallback = _unit(np.cross(self.axis, helper), "fallback")

    def parameters(self) -> dict:
        return {
            "point": self.point.tolist(),
            "axis_point": (self.point + self.axis).tolist(),
            "diameter": 2 * self.radius,
        }

    def _radial(self, x, offset):
        r = x - (self.point + offset)
        return r - np.outer(r @ self.axis, self.axis)


class SphereWall(_RoundWall):
    """Sphere of ``diameter`` (m) centred at ``point``; the allowed side is outside."""

    kind = "sphere"
    fallback = np.array([0.0, 0.0, 1.0])

    def __init__(self, point, diameter: float):
        self.point = np.asarray(point, dtype=float)
        if not diameter > 0:
            raise ValueError("diameter must be > 0")
        self.radius = 0.5 * float(diameter)

    def parameters(self) -> dict:
        return {"point": self.point.tolist(), "diameter": 2 * self.radius}

    def _radial(self, x, offset):
        return x - (self.point + offset)


SHAPES = {
    "plane": PlaneWall,
    "parallelogram": ParallelogramWall,
    "cylinder": CylinderWall,
    "sphere": SphereWall,
}


def shape_from_parameters(parameters: dict):
    """The shape described by ``{"kind": ..., **shape.parameters()}``."""
    arguments = dict(parameters)
    return SHAPES[arguments.pop("kind")](**arguments)
