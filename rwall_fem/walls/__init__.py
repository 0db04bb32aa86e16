"""Rigid walls with the semantics of the Radioss ``/RWALL`` option.

``shapes``: geometry (signed distance and normal of each shape); ``motion``:
fixed, main-node and prescribed walls; ``constraint``: the kinematic
condition shared by all shapes (normal stop, tied, Coulomb friction).

The names are imported lazily: the renderer reads the shapes without loading MPI
(``constraint`` imports mpi4py, 0.35 s and an MPI start in the renderer's process).
"""

import importlib

_API = {
    "CylinderWall": "rwall_fem.walls.shapes",
    "FixedMotion": "rwall_fem.walls.motion",
    "MainNodeMotion": "rwall_fem.walls.motion",
    "ParallelogramWall": "rwall_fem.walls.shapes",
    "PlaneWall": "rwall_fem.walls.shapes",
    "PrescribedMotion": "rwall_fem.walls.motion",
    "RigidWall": "rwall_fem.walls.constraint",
    "SphereWall": "rwall_fem.walls.shapes",
}

__all__ = sorted(_API)


def __getattr__(name: str):
    if name in _API:
        return getattr(importlib.import_module(_API[name]), name)
    raise AttributeError(f"module 'rwall_fem.walls' has no attribute {name!r}")
