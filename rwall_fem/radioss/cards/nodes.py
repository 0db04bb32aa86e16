"""/NODE: node IDs and coordinates (input length unit), read once every card is read, in
one pass over every /NODE card."""

from __future__ import annotations

import numpy as np

from rwall_fem.radioss.cards.base import card_units
from rwall_fem.radioss.model import Deck
from rwall_fem.radioss.reader import Card, DeckError, fixed_table

__all__ = ["STARTER", "finish"]


def _node(deck: Deck, card: Card) -> None:
    card_units(deck, card, 1)  # checked here: the card that names it
    deck.pending.setdefault("NODE", []).append(card)


def finish(deck: Deck) -> None:
    """The node IDs and coordinates (m) of every /NODE card; a node defined twice or an
    ID that is not positive is refused."""
    ids, xyz = [], []
    cards = deck.pending.get("NODE", [])
    for card in cards:
        i, x, y, z = fixed_table(card, 0, "i:node_ID f:X f:Y f:Z")
        bad = np.flatnonzero(i <= 0)
        if len(bad):
            card.fail(f"node ID {i[bad[0]]}: node IDs are positive", card.lines[bad[0]])
        ids.append(i)
        xyz.append(np.column_stack([x, y, z]) * card_units(deck, card, 1).length)
    deck.node_ids = np.concatenate(ids) if ids else np.zeros(0, dtype=np.int64)
    deck.coordinates = np.concatenate(xyz) if xyz else np.zeros((0, 3))
    unique, counts = np.unique(deck.node_ids, return_counts=True)
    if np.any(counts > 1):
        node = unique[counts > 1][0]
        places = [where for card in cards for where in _places(card, node)]
        first, again = (places + [cards[0].header.where] * 2)[:2]
        raise DeckError(
            f"{first}: /NODE: node {node} is defined twice (again at {again}); "
            "a node ID is defined once"
        )


def _places(card: Card, node: int) -> list[str]:
    """Where in ``card`` the node ``node`` is defined (file:line of each)."""
    out = []
    for line in card.lines:
        words = line.words() if line.free else [line.text[:10]]
        if words and words[0].strip().lstrip("0") == str(node):
            out.append(line.where)
    return out


STARTER = {"NODE": _node}
