"""rwall_fem: explicit elastodynamics on DOLFINx meshes with Radioss-style rigid walls.

The public names are imported lazily, so that ``python -m rwall_fem.output.render``
(off-screen pictures) runs without DOLFINx in the process: VTK's wheels and
DOLFINx's C++ libraries must not share a process that renders.
"""

import importlib

__version__ = "0.1.0"

_API = {
    "BodyMesh": "rwall_fem.meshing",
    "CylinderWall": "rwall_fem.walls",
    "ParallelogramWall": "rwall_fem.walls",
    "PlaneWall": "rwall_fem.walls",
    "RigidWall": "rwall_fem.walls",
    "SphereWall": "rwall_fem.walls",
    "Scene": "rwall_fem.scene",
    "SceneError": "rwall_fem.scene",
    "load_scene": "rwall_fem.scene",
    "parse_scene": "rwall_fem.scene",
    "build_simulation": "rwall_fem.build",
    "run_scene": "rwall_fem.build",
}

__all__ = sorted(_API)


def __getattr__(name: str):
    if name in _API:
        return getattr(importlib.import_module(_API[name]), name)
    raise AttributeError(f"module 'rwall_fem' has no attribute {name!r}")
