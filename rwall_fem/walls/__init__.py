"""Rigid walls with the semantics of the Radioss ``/RWALL`` option.

``shapes`` holds the geometry (signed distance and outward normal of each
shape); ``constraint`` holds the kinematic condition shared by all shapes.
"""

from rwall_fem.walls.constraint import RigidWall
from rwall_fem.walls.shapes import PlaneWall

__all__ = ["PlaneWall", "RigidWall"]
