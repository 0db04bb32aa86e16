"""The starter's cards, each read by the function its family declares
(:mod:`rwall_fem.radioss.cards`), into a :class:`~rwall_fem.radioss.model.Deck` in SI.

Column layouts are those of OpenRadioss's 2026 block format; older versions (input
version >= 100) use the same columns, where a field added later is blank (its default).
A card that is not supported is refused in one line naming it and what is supported;
control and output cards with no counterpart here are skipped with one notice each.
"""

from __future__ import annotations

from rwall_fem.radioss.cards import STARTER_FAMILIES, lookup, supported, table
from rwall_fem.radioss.cards.base import keyword
from rwall_fem.radioss.cards.unknown import refusal
from rwall_fem.radioss.model import Deck
from rwall_fem.radioss.reader import Card, DeckError

__all__ = ["read_starter"]

READERS = table(STARTER_FAMILIES, "STARTER")
# The cards read before the others (a /UNIT may come after the cards that name it).
FIRST = [tuple(path.split("/")) for family in STARTER_FAMILIES
         for path in getattr(family, "FIRST", ())]  # fmt: skip


def _first(card: Card) -> bool:
    keys = tuple(keyword(p) for p in card.parts)
    return any(keys[: len(path)] == path for path in FIRST)


def read_starter(deck: Deck, cards: list[Card]) -> None:
    """Fill ``deck`` from the starter's ``cards`` (the first one must be /BEGIN)."""
    if not cards or cards[0].key(0) != "BEGIN":
        where = cards[0].header.where if cards else str(deck.starter)
        raise DeckError(
            f"{where}: the starter file must begin with /BEGIN (run name, input version, "
            "input and work units)"
        )
    first = [c for c in cards[1:] if _first(c)]
    chosen = {id(c) for c in first}
    for card in [cards[0], *first, *(c for c in cards[1:] if id(c) not in chosen)]:
        read = lookup(READERS, card)
        if read is None:
            why = refusal(card)
            if why:
                card.fail(f"{why}; the cards read: docs/radioss.md")
            card.fail(f"unsupported card; the starter cards read are {supported(READERS)}")
        read(deck, card)
    for family in STARTER_FAMILIES:
        finish = getattr(family, "finish", None)
        if finish is not None:
            finish(deck)
