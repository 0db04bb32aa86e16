"""A deck's /PARTs as the scene's parts: their names, cells and nodes, and the initial
velocity each one starts at (/INIVEL).

Each /PART with elements becomes a part named after its title (made an identifier:
a letter, then up to 63 letters, digits, ``_`` or ``-``), or ``part_<ID>``; names are
unique. An
/INIVEL gives its velocity to the parts whose nodes its group holds whole (a
/GRNOD/PART, or a node list of exactly those parts' nodes); a group that holds some
nodes of a part and not others, a second velocity of a part, or parts that share nodes
(bonded) starting at different velocities are refused in one line naming the card.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

from rwall_fem.radioss.groups import node_ids
from rwall_fem.radioss.model import Deck, Part
from rwall_fem.radioss.reader import DeckError

__all__ = ["DeckPart", "deck_parts", "initial_velocities", "uniform_velocity"]

_NAME_LENGTH = 64  # a scene's identifiers: a letter, then up to 63 more characters


@dataclass(eq=False)  # parts are compared by identity
class DeckPart:
    """A /PART with elements: its card, scene ``name``, ``cells`` (node IDs, (M, 8 or 4),
    in the order of its elements), its sorted ``nodes`` (IDs), and the initial
    ``velocity`` (m/s) an /INIVEL gave it with that card's place (``given``, file:line)."""

    part: Part
    name: str
    cells: np.ndarray
    nodes: np.ndarray
    velocity: np.ndarray | None = None
    given: str = ""
    order: int = -1  # the index of that /INIVEL among the deck's

    @property
    def start(self) -> np.ndarray:
        """The initial velocity (m/s): the /INIVEL's, or rest."""
        return np.zeros(3) if self.velocity is None else self.velocity


def deck_parts(deck: Deck) -> list[DeckPart]:
    """The parts that have elements, by ID, named (every element's part is a /PART)."""
    ids = sorted({b.part for b in deck.bodies})
    taken: set[str] = set()
    parts = []
    for pid in ids:
        cells = np.concatenate([b.nodes for b in deck.bodies if b.part == pid])
        name = _name(deck.parts[pid], taken)
        taken.add(name)
        parts.append(DeckPart(deck.parts[pid], name, cells, np.unique(cells)))
    return parts


def _name(part: Part, taken: set[str]) -> str:
    """The part's title as an identifier (``part_`` before one that does not start with a
    letter), else ``part_<ID>``; with ``_<ID>`` (or a count) appended when another part
    has it."""
    base = re.sub(r"[^A-Za-z0-9_-]+", "_", part.title).strip("_-")
    if base and not re.match("[A-Za-z]", base):
        base = f"part_{base}"
    base = base[:_NAME_LENGTH] or f"part_{part.id}"
    name, count = base, 1
    while name in taken:
        suffix = f"_{part.id}" if count == 1 else f"_{part.id}_{count}"
        name = base[: _NAME_LENGTH - len(suffix)] + suffix
        count += 1
    return name


def initial_velocities(deck: Deck, parts: list[DeckPart], mains: set[int]) -> None:
    """Give each part the velocity of the /INIVEL whose group holds it whole; refuse a
    group that splits a part, holds a wall's main node or no node of an element, a second
    velocity of a part, and bonded parts that would start at different velocities."""
    body = np.unique(np.concatenate([p.nodes for p in parts]))
    for order, (velocity, gid, where) in enumerate(deck.initial):
        group_nodes = node_ids(deck, gid, f"{where}: /INIVEL/TRA: Gnod_id")
        if set(group_nodes.tolist()) & mains:
            raise DeckError(f"{where}: /INIVEL/TRA: group {gid} holds the main node of a "
                            "/RWALL: its velocity is the wall's VX0 VY0 VZ0")  # fmt: skip
        nodes = np.intersect1d(group_nodes, body)
        if not len(nodes):
            raise DeckError(f"{where}: /INIVEL/TRA: group {gid} holds no node of an element")
        whole = [p for p in parts if np.isin(p.nodes, nodes).all()]
        _splits_no_part(where, gid, nodes, whole, parts)
        for p in whole:
            if p.velocity is not None and not np.array_equal(p.velocity, velocity):
                raise DeckError(
                    f"{where}: /INIVEL/TRA: a second initial velocity of /PART/{p.part.id} "
                    f"({p.name}): {_vec(velocity)} m/s after {_vec(p.velocity)} m/s at "
                    f"{p.given}"
                )
            p.velocity, p.given, p.order = velocity, where, order
    _bonded_start_together(parts)


def _splits_no_part(where, gid, nodes, whole, parts) -> None:
    """Refuse a group whose nodes are not exactly the nodes of the parts it holds whole."""
    reached = np.unique(np.concatenate([p.nodes for p in whole])) if whole else nodes[:0]
    stray = np.setdiff1d(nodes, reached)
    if not len(stray):
        return
    p = next(p for p in parts if p not in whole and stray[0] in p.nodes)
    inside = np.isin(p.nodes, nodes)
    raise DeckError(
        f"{where}: /INIVEL/TRA: group {gid} holds {int(inside.sum())} of the {len(p.nodes)} "
        f"nodes of /PART/{p.part.id} ({p.name}; node {p.nodes[~inside][0]} is not in it): an "
        "initial velocity is given to whole parts; give the group the part's nodes "
        "(/GRNOD/PART) or make the nodes a part of their own"
    )


def _bonded_start_together(parts: list[DeckPart]) -> None:
    """Refuse two parts that share nodes but would start at different velocities, naming
    the later /INIVEL of the two (bonded parts' nodes are the body's: one velocity)."""
    for k, first in enumerate(parts):
        for second in parts[k + 1 :]:
            if np.array_equal(first.start, second.start):
                continue
            shared = np.intersect1d(first.nodes, second.nodes)
            if not len(shared):
                continue
            card = max(first, second, key=lambda p: p.order)
            raise DeckError(
                f"{card.given}: /INIVEL/TRA: /PART/{first.part.id} ({first.name}) and "
                f"/PART/{second.part.id} ({second.name}) share {len(shared)} nodes (node "
                f"{shared[0]}: they are bonded) but would start at {_vec(first.start)} and "
                f"{_vec(second.start)} m/s: bonded parts start together; give them one "
                "initial velocity"
            )


def uniform_velocity(parts: list[DeckPart]) -> bool:
    """Whether every part starts at the same velocity."""
    return all(np.array_equal(p.start, parts[0].start) for p in parts)


def _vec(v) -> str:
    return "[" + ", ".join(f"{c:g}" for c in v) + "]"
