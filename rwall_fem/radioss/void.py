"""Void elements (/MAT/VOID, /MAT/LAW0): no stiffness and, as in Radioss, no mass. They
are left out of the mesh: a body without them moves as the body with them. Nodes that
only void elements hold are Radioss's free nodes, with no mass and nothing acting on
them: they are not in the mesh either, and a group or surface is what remains of it
without them (a wall, a condition or a load on such nodes alone is refused where it is
used)."""

from __future__ import annotations

import numpy as np

from rwall_fem.radioss.model import Deck
from rwall_fem.radioss.reader import DeckError

__all__ = ["drop_void_elements"]


def _is_void(deck: Deck, pid: int) -> bool:
    part = deck.parts.get(pid)
    return part is not None and deck.materials.get(part.mat, {}).get("law") == "LAW0"


def drop_void_elements(deck: Deck) -> list[str]:
    """Remove the elements of void parts from ``deck.bodies``; a line per void part, and a
    refusal when nothing else is left or a part with stiffness has a void property."""
    void = sorted({b.part for b in deck.bodies if _is_void(deck, b.part)})
    kept = [b for b in deck.bodies if b.part not in void]
    for pid in sorted({b.part for b in kept}):
        part = deck.parts.get(pid)
        if part is not None and deck.properties.get(part.prop, {}).get("void"):
            raise DeckError(f"{part.where}: /PART/{pid}: prop_ID {part.prop} is a /PROP/VOID, "
                            f"and its material {part.mat} is not void: give it a /PROP/SOLID")
    if not void:
        return []
    facts = []
    for pid in void:
        count = sum(len(b.ids) for b in deck.bodies if b.part == pid)
        part = deck.parts[pid]
        facts.append(f"part {pid} ({part.where}): {count} elements of a void material (/MAT "
                     f"{part.mat}, law 0): no stiffness, no mass: left out of the mesh")
    if not kept:
        raise DeckError(f"{deck.starter}: every element is of a void material (/MAT/VOID, "
                        "LAW0): there is no body to run")  # fmt: skip
    before = np.unique(np.concatenate([b.nodes.ravel() for b in deck.bodies]))
    after = np.unique(np.concatenate([b.nodes.ravel() for b in kept]))
    free = len(before) - len(after)
    if free:
        facts.append(f"{free} nodes only void elements hold: free nodes (no mass), left out")
    deck.bodies[:] = kept
    return facts
