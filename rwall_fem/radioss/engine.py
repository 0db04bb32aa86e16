"""The engine's cards (in the deck's work units), each read by the function its family
declares (:mod:`rwall_fem.radioss.cards`): the end time, the time step's controls, the
animation and time-history intervals; outputs and settings are skipped with a notice."""

from __future__ import annotations

from rwall_fem.radioss.cards import ENGINE_FAMILIES, lookup, supported, table
from rwall_fem.radioss.model import Deck
from rwall_fem.radioss.reader import Card, DeckError

__all__ = ["read_engine"]

READERS = table(ENGINE_FAMILIES, "ENGINE")


def read_engine(deck: Deck, cards: list[Card], where: str) -> None:
    """Fill the run controls of ``deck`` (SI) from the engine's ``cards``, read from
    ``where`` (a file, for the message of a missing /RUN)."""
    for card in cards:
        read = lookup(READERS, card)
        if read is None:
            card.fail(f"unsupported engine card; the engine cards read are {supported(READERS)}")
        read(deck, card)
    for family in ENGINE_FAMILIES:
        finish = getattr(family, "finish", None)
        if finish is not None:
            finish(deck)
    if deck.end_time is None:
        raise DeckError(f"{where}: no /RUN card: it gives the end time (Tstop)")
