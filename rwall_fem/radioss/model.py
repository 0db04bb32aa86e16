"""What a deck says, in SI units and Radioss's own terms: the result of reading its cards
(:mod:`~rwall_fem.radioss.starter`, :mod:`~rwall_fem.radioss.engine`), before it becomes
a scene (:mod:`~rwall_fem.radioss.to_scene`).

IDs stay Radioss's (node, part, group, function IDs); ``where`` is ``file:line`` of the
card that defined a thing, for the messages that name it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from rwall_fem.radioss.units import UnitSystem

__all__ = [
    "Body",
    "Deck",
    "Function",
    "NodeGroup",
    "Part",
    "Prescribed",
    "Wall",
]


@dataclass
class Part:
    """A /PART: its property and material IDs."""

    id: int
    title: str
    prop: int
    mat: int
    where: str


@dataclass
class NodeGroup:
    """A /GRNOD: the node IDs it selects (resolved once every card is read)."""

    id: int
    title: str
    kind: str  # NODE, PART or BOX
    items: np.ndarray  # the listed IDs (nodes, parts or boxes); negative ones removed
    where: str
    nodes: np.ndarray | None = None


@dataclass
class Function:
    """A /FUNCT: y(x), piecewise linear, as the deck gives it (no units: the scale factors
    of the card that uses it carry them)."""

    id: int
    x: np.ndarray
    y: np.ndarray
    where: str


@dataclass
class Prescribed:
    """An /IMPVEL or /GRAV: the function of time ``fct`` scaled to SI (time ``t_scale``,
    value ``y_scale``) along ``direction`` (X, Y or Z) on the node group ``group``."""

    card: str
    fct: int
    direction: str
    group: int
    t_scale: float
    y_scale: float
    where: str


@dataclass
class Wall:
    """A /RWALL, in SI: its shape points, sliding, secondary-node selection and motion."""

    id: int
    kind: str  # PLANE, CYL, SPHER or PARAL
    title: str
    main_node: int
    slide: int
    add_group: int
    exclude_group: int
    search_distance: float  # m; 0: no search by distance
    friction: float
    diameter: float  # m
    filter_flag: int
    filter_factor: float  # alpha, steps, or Hz (filter_flag 1, 2, 3)
    point: np.ndarray  # M (m): given, or the main node's position
    mass: float  # kg (moving wall)
    velocity: np.ndarray  # m/s, initial velocity of the main node
    point1: np.ndarray | None  # M1 (m)
    point2: np.ndarray | None  # M2 (m)
    where: str


@dataclass
class Body:
    """The elements of one part: ``cell`` ("hexahedron" or "tetrahedron"), their IDs and
    their node IDs (M, 8 or 4), in Radioss's order (which is gmsh's)."""

    part: int
    cell: str
    ids: np.ndarray
    nodes: np.ndarray
    card: object  # the reader's Card, to name the line of an element


@dataclass
class Deck:
    """A deck read whole: the model in SI, the engine's run controls, the warnings, and
    what was understood (lines for ``rwall-fem check``)."""

    starter: Path
    engine: Path | None = None
    run_name: str = ""
    version: int = 0
    input_units: UnitSystem = field(default_factory=UnitSystem)
    work_units: UnitSystem = field(default_factory=UnitSystem)
    node_ids: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    coordinates: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))  # m
    bodies: list[Body] = field(default_factory=list)
    parts: dict[int, Part] = field(default_factory=dict)
    materials: dict[int, dict] = field(default_factory=dict)  # ID -> material facts
    properties: dict[int, dict] = field(default_factory=dict)  # ID -> property facts
    groups: dict[int, NodeGroup] = field(default_factory=dict)
    boxes: dict[int, tuple[np.ndarray, np.ndarray, str]] = field(default_factory=dict)
    functions: dict[int, Function] = field(default_factory=dict)
    initial: list[tuple[np.ndarray, int, str]] = field(default_factory=list)  # v, group
    clamps: list[tuple[str, int, str]] = field(default_factory=list)  # components, group
    velocities: list[Prescribed] = field(default_factory=list)  # /IMPVEL
    gravity: list[Prescribed] = field(default_factory=list)  # /GRAV
    walls: list[Wall] = field(default_factory=list)
    end_time: float | None = None  # s
    dt_scale: float | None = None
    dt_min: float | None = None  # s
    animation: tuple[float, float] | None = None  # start, interval (s)
    history_interval: float | None = None  # s
    warnings: list[str] = field(default_factory=list)

    def node_positions(self, ids: np.ndarray) -> np.ndarray:
        """Rows of :attr:`node_ids` holding ``ids``; -1 where an ID is not a node."""
        order = np.argsort(self.node_ids, kind="stable")
        sorted_ids = self.node_ids[order]
        at = np.searchsorted(sorted_ids, ids)
        at = np.clip(at, 0, max(len(sorted_ids) - 1, 0))
        found = len(sorted_ids) > 0
        ok = found & (sorted_ids[at] == ids) if found else np.zeros(len(ids), dtype=bool)
        return np.where(ok, order[at] if found else -1, -1)
