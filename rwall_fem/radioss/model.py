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
    "Box",
    "Deck",
    "Function",
    "Group",
    "Part",
    "Prescribed",
    "Wall",
]


@dataclass
class Part:
    """A /PART: its property and material IDs, and the /SUBSET it belongs to (0: none)."""

    id: int
    title: str
    prop: int
    mat: int
    where: str
    subset: int = 0


@dataclass
class Group:
    """A group or a surface as its card lists it: a /GRNOD, /GRBRIC, /GRSHEL, /GRSH3N
    (``family``) or /SURF; :mod:`~rwall_fem.radioss.groups` resolves it.

    ``kind`` names what ``items`` are (the card's second keyword and the ones after it:
    ``NODE``, ``PART``, ``BOX``, ``GRNOD``, ``PART/EXT``, ...); ``items`` are the listed IDs
    in order, signed: a negative ID removes that item from a group, and turns the
    segments of that item over in a surface, as in Radioss. A /SURF/SEG's segments are
    ``segments``, (k, 4) node IDs (a triangle repeats its third node)."""

    family: str
    id: int
    title: str
    kind: str
    items: np.ndarray
    where: str
    segments: np.ndarray | None = None
    nodes: np.ndarray | None = None  # a node group's node IDs, once resolved

    @property
    def name(self) -> str:
        return f"/{self.family}/{self.kind}/{self.id}"


@dataclass
class Box:
    """A /BOX: ``shape`` RECTA (corners ``low``, ``high``), SPHER (``center``, ``radius``) or
    CYLIN (axis ``center`` to ``end``, ``radius``), in m."""

    id: int
    shape: str
    where: str
    low: np.ndarray | None = None
    high: np.ndarray | None = None
    center: np.ndarray | None = None
    end: np.ndarray | None = None
    radius: float = 0.0
    node_refs: dict[str, int] = field(default_factory=dict)  # points given by a node ID

    def inside(self, x: np.ndarray) -> np.ndarray:
        """Whether each point of ``x`` (n, 3), m, is inside the box or on its surface."""
        if self.shape == "RECTA":
            return np.all((x >= self.low) & (x <= self.high), axis=1)
        if self.shape == "SPHER":
            return np.linalg.norm(x - self.center, axis=1) <= self.radius
        axis = self.end - self.center
        length = np.linalg.norm(axis)
        s = (x - self.center) @ (axis / length)
        radial = np.linalg.norm(x - self.center - np.outer(s, axis / length), axis=1)
        return (s >= 0) & (s <= length) & (radial <= self.radius)


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
    """The elements of one element card (one part): ``cell`` ("hexahedron" or
    "tetrahedron"; shells will add "quadrilateral" and "triangle"), their IDs and their
    node IDs (M, 8 or 4), in Radioss's order (which is gmsh's)."""

    part: int
    cell: str
    ids: np.ndarray
    nodes: np.ndarray
    card: object  # the reader's Card, to name the line of an element


# The element families of Radioss's element groups: the cells each one holds.
GROUP_CELLS = {
    "GRBRIC": ("hexahedron", "tetrahedron"),  # /BRICK, /TETRA4: Radioss's solids
    "GRSHEL": ("quadrilateral",),  # /SHELL
    "GRSH3N": ("triangle",),  # /SH3N
}


@dataclass
class Deck:
    """A deck read whole: the model in SI, the engine's run controls, the warnings, and
    what was understood (lines for ``rwall-fem check``)."""

    starter: Path
    engine: Path | None = None
    run_name: str = ""
    version: int = 0
    begin_where: str = ""  # file:line of /BEGIN
    input_units: UnitSystem = field(default_factory=UnitSystem)
    unit_systems: dict[int, UnitSystem] = field(default_factory=dict)  # /UNIT by ID
    work_units: UnitSystem = field(default_factory=UnitSystem)
    node_ids: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    coordinates: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))  # m
    bodies: list[Body] = field(default_factory=list)
    parts: dict[int, Part] = field(default_factory=dict)
    materials: dict[int, dict] = field(default_factory=dict)  # ID -> material facts
    failures: dict[int, dict] = field(default_factory=dict)  # mat_ID -> /FAIL facts
    properties: dict[int, dict] = field(default_factory=dict)  # ID -> property facts
    groups: dict[int, Group] = field(default_factory=dict)  # /GRNOD by ID
    element_groups: dict[tuple[str, int], Group] = field(default_factory=dict)  # (family, ID)
    surfaces: dict[int, Group] = field(default_factory=dict)  # /SURF by ID
    subsets: dict[int, tuple[str, np.ndarray, str]] = field(default_factory=dict)  # children
    boxes: dict[int, Box] = field(default_factory=dict)
    functions: dict[int, Function] = field(default_factory=dict)
    initial: list[tuple[np.ndarray, int, str]] = field(default_factory=list)  # v, group
    clamps: list[tuple[str, int, str]] = field(default_factory=list)  # components, group
    # /BCS rotation codes by the file:line of their /BCS: the global axes held ("xyz")
    held_rotations: dict[str, str] = field(default_factory=dict)
    velocities: list[Prescribed] = field(default_factory=list)  # /IMPVEL
    gravity: list[Prescribed] = field(default_factory=list)  # /GRAV
    loads: list[Prescribed] = field(default_factory=list)  # /CLOAD (y_scale in N)
    pressures: list = field(default_factory=list)  # /PLOAD (cards.loads.Pressure)
    added_masses: list = field(default_factory=list)  # /ADMAS (cards.loads.AddedMass)
    dampings: list = field(default_factory=list)  # /DAMP (cards.loads.Damping)
    walls: list[Wall] = field(default_factory=list)
    rigid_bodies: list = field(default_factory=list)  # /RBODY (cards/rigid_bodies.py)
    interfaces: list = field(default_factory=list)  # /INTER/TYPE7 (cards/interfaces.py)
    end_time: float | None = None  # s
    dt_scale: float | None = None
    dt_min: float | None = None  # s
    dt_min_action: str | None = None  # stop, mass_scaling or erode (/DT/BRICK/..., /DT/NODA/...)
    animation: tuple[float, float] | None = None  # start, interval (s)
    history_interval: float | None = None  # s
    noise: tuple[float, int] | None = None  # /RANDOM: amplitude (m), seed
    solid_defaults: dict[str, int] = field(default_factory=dict)  # /DEF_SOLID's fields
    shell_defaults: dict[str, int] = field(default_factory=dict)  # /DEF_SHELL's fields
    pending: dict[str, list] = field(default_factory=dict)  # cards a family reads at the end
    warnings: list[str] = field(default_factory=list)  # where the deck and rwall_fem differ
    notices: list[str] = field(default_factory=list)  # what was skipped or read so
    resolved: dict = field(default_factory=dict)  # groups.py's resolved groups, by key

    def notice(self, card, what: str) -> None:
        """One notice line about ``card``: ``file:line: /CARD: what``."""
        self.notices.append(f"{card.header.where}: {card.name}: {what}")

    def warn(self, card, what: str, line=None) -> None:
        """One warning line about ``card`` (at ``line``, else its header)."""
        self.warnings.append(f"{(line or card.header).where}: {card.name}: {what}")

    def node_positions(self, ids: np.ndarray) -> np.ndarray:
        """Rows of :attr:`node_ids` holding ``ids``; -1 where an ID is not a node."""
        order = np.argsort(self.node_ids, kind="stable")
        sorted_ids = self.node_ids[order]
        at = np.searchsorted(sorted_ids, ids)
        at = np.clip(at, 0, max(len(sorted_ids) - 1, 0))
        found = len(sorted_ids) > 0
        ok = found & (sorted_ids[at] == ids) if found else np.zeros(len(ids), dtype=bool)
        return np.where(ok, order[at] if found else -1, -1)
