"""/FUNCT: a function y(x), piecewise linear, as the deck gives it (no units: the scale
factors of the card that uses it carry them)."""

from __future__ import annotations

import numpy as np

from rwall_fem.radioss.cards.base import ident
from rwall_fem.radioss.model import Deck, Function
from rwall_fem.radioss.reader import Card, fixed_table

__all__ = ["STARTER"]


def _function(deck: Deck, card: Card) -> None:
    fid = ident(card, 1, "fct_ID")
    if fid in deck.functions:
        card.fail(f"function {fid} is defined twice")
    x, y = fixed_table(card, 1, "f:X f:Y")
    if len(x) < 2 or np.any(np.diff(x) <= 0):
        card.fail("a function needs at least two points with increasing X")
    deck.functions[fid] = Function(fid, x, y, card.header.where)


STARTER = {"FUNCT": _function}
