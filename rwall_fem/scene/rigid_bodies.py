"""The ``[[rigid_body]]`` tables of a scene: node sets that move as one rigid body
(Radioss ``/RBODY``; ``docs/theory.md``, "Rigid bodies")."""

from __future__ import annotations

from dataclasses import dataclass

from rwall_fem.scene.keys import Choice, Flag, Names, Real, Sub, Vector, key, rule, table

__all__ = ["NodeBox", "RigidBodySpec"]


@table("The nodes inside an axis-aligned box at the start (faces included).")
@dataclass(frozen=True)
class NodeBox:
    low: tuple[float, float, float] = key(Vector(), unit="m", doc="the lowest corner")
    high: tuple[float, float, float] = key(Vector(), unit="m", doc="the highest corner")


@rule(NodeBox)
def _box_is_a_box(v, raw, fail):
    """high is above low along every axis."""
    if any(h < lo for lo, h in zip(v["low"], v["high"], strict=True)):
        fail("high", f"{list(v['high'])} is below low = {list(v['low'])} along some axis")


@table(
    "A rigid body (Radioss /RBODY): the nodes of named sets, parts or a box move as one body"
    " of their lumped masses, plus a mass and inertia added at a main node."
)
@dataclass(frozen=True)
class RigidBodySpec:
    sets: tuple[str, ...] = key(Names(), (), doc="named node sets (gmsh physical groups)")
    parts: tuple[str, ...] = key(Names(), (), doc="every node of these parts")
    box: NodeBox | None = key(Sub(NodeBox), None, doc="the nodes inside a box at the start",
                              default_doc="none")  # fmt: skip
    main_node: tuple[float, float, float] | None = key(
        Vector(),
        None,
        unit="m",
        doc="where mass and inertia are added (Radioss's main node)",
        default_doc="the centre of mass of the nodes",
    )
    mass: float = key(Real(low=0.0, low_open=False), 0.0, unit="kg", doc="added at the main node")
    inertia: tuple[float, ...] = key(
        Vector(size=6),
        (0.0,) * 6,
        unit="kg m^2",
        doc="added about the main node: [Jxx, Jyy, Jzz, Jxy, Jyz, Jxz]",
    )
    center: str = key(
        Choice(("with_main_node", "nodes")),
        "with_main_node",
        doc="the centre of mass: of the nodes and the main node's mass (ICoG 1), or of the "
        "nodes alone, the main node's mass put there (ICoG 2)",
    )
    node_masses: bool = key(
        Flag(),
        True,
        doc="false: the body's mass and inertia are mass and inertia alone, at main_node "
        "(ICoG 4)",
    )
    angular_velocity: tuple[float, float, float] = key(
        Vector(), (0.0, 0.0, 0.0), unit="rad/s", doc="initial, about the centre of mass"
    )


@rule(
    RigidBodySpec,
    json=[
        {"anyOf": [{"required": ["sets"]}, {"required": ["parts"]}, {"required": ["box"]}]},
        {
            "if": {"properties": {"node_masses": {"const": False}}, "required": ["node_masses"]},
            "then": {"required": ["main_node"]},
        },
    ],
)
def _some_nodes(v, raw, fail):
    """At least one of sets, parts and box; node_masses = false needs main_node."""
    if not v["sets"] and not v["parts"] and v["box"] is None:
        fail("sets", "missing: give the body's nodes as sets, parts or a box")
    if not v["node_masses"] and v["main_node"] is None:
        fail("main_node", "missing: node_masses = false puts the body's mass at main_node")
