"""rwall_fem: explicit elastodynamics on DOLFINx meshes with Radioss-style rigid walls."""

from rwall_fem import _compat  # noqa: F401  (orders dolfinx_solver before dolfinx)
from rwall_fem.model import build_simulation, run_scene
from rwall_fem.scene import Scene, SceneError, load_scene, parse_scene
from rwall_fem.walls import PlaneWall, RigidWall

__version__ = "0.1.0"

__all__ = [
    "PlaneWall",
    "RigidWall",
    "Scene",
    "SceneError",
    "build_simulation",
    "load_scene",
    "parse_scene",
    "run_scene",
]
