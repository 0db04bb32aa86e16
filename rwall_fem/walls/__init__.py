"""Rigid walls with the semantics of the Radioss ``/RWALL`` option.

``shapes``: geometry (signed distance and normal of each shape); ``motion``:
fixed, main-node and prescribed walls; ``constraint``: the kinematic
condition shared by all shapes (normal stop, tied, Coulomb friction).
"""

from rwall_fem.walls.constraint import RigidWall
from rwall_fem.walls.motion import FixedMotion, MainNodeMotion, PrescribedMotion
from rwall_fem.walls.shapes import CylinderWall, ParallelogramWall, PlaneWall, SphereWall

__all__ = [
    "CylinderWall",
    "FixedMotion",
    "MainNodeMotion",
    "ParallelogramWall",
    "PlaneWall",
    "PrescribedMotion",
    "RigidWall",
    "SphereWall",
]
