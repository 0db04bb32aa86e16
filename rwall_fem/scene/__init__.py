"""Scenes: a TOML file read into validated dataclasses.

A scene is checked whole before anything heavy starts. Every problem is a
:class:`SceneError` whose message is one line naming the file, the key path
(``wall[0].normal_point``) and what is allowed. Nothing downstream of this
package reads the raw TOML.

The format is written once, in :mod:`rwall_fem.scene.schema`; the checks
(:mod:`~rwall_fem.scene.keys`), the reference page ``docs/reference/scene.md``
and the JSON Schema ``scene.schema.json`` beside this file
(:mod:`~rwall_fem.scene.reference`) come from it.
"""

from rwall_fem.scene.keys import SceneError
from rwall_fem.scene.overrides import apply_override
from rwall_fem.scene.read import load_scene, parse_scene
from rwall_fem.scene.rigid_bodies import RigidBodySpec
from rwall_fem.scene.schema import (
    MATERIAL_MODELS,
    MESH_SHAPES,
    PLASTIC_MODELS,
    SHAPE_KEYS,
    SHAPE_REGIONS,
    BoundarySpec,
    Element,
    Initial,
    Material,
    MeshSpec,
    Motion,
    Output,
    PartSpec,
    PieceSpec,
    RunSettings,
    Scene,
    Secondary,
    WallSpec,
    ContactSpec,
)

__all__ = [
    "MATERIAL_MODELS",
    "PLASTIC_MODELS",
    "MESH_SHAPES",
    "SHAPE_KEYS",
    "SHAPE_REGIONS",
    "BoundarySpec",
    "Element",
    "Initial",
    "Material",
    "MeshSpec",
    "Motion",
    "Output",
    "PartSpec",
    "PieceSpec",
    "RigidBodySpec",
    "RunSettings",
    "Scene",
    "SceneError",
    "Secondary",
    "WallSpec",
    "ContactSpec",
    "apply_override",
    "load_scene",
    "parse_scene",
]
