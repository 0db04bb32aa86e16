"""/PART (a property and a material for elements) and /SUBSET (parts and subsets
gathered: a part names its subset, a subset its child subsets). A part without a
material or property is refused once it has elements (a spring's part has none)."""

from __future__ import annotations

import numpy as np

from rwall_fem.radioss.cards.base import ident
from rwall_fem.radioss.model import Deck, Part
from rwall_fem.radioss.reader import Card, fixed_table

__all__ = ["STARTER"]


def _part(deck: Deck, card: Card) -> None:
    pid = ident(card, 1, "part_ID")
    prop, mat, subset = card.read(1, "i:prop_ID i:mat_ID i:subset_ID", "prop_ID mat_ID subset_ID")
    if pid in deck.parts:
        card.fail(f"part {pid} is defined twice")
    deck.parts[pid] = Part(pid, card.title(), prop, mat, card.lines[1].where, subset)


def _subset(deck: Deck, card: Card) -> None:
    sid = ident(card, 1, "subset_ID")
    if sid in deck.subsets:
        card.fail(f"subset {sid} is defined twice")
    columns = fixed_table(card, 1, " ".join(f"i:sub{k}" for k in range(10)))
    children = np.column_stack(columns).ravel()
    deck.subsets[sid] = (card.title(), children[children != 0], card.header.where)


STARTER = {"PART": _part, "SUBSET": _subset}
