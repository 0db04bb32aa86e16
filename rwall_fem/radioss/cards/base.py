"""What the card families share: the ID in a card's name, marks for the registry, and
Radioss's "no limit" values."""

from __future__ import annotations

import re

from rwall_fem.radioss.reader import Card
from rwall_fem.radioss.units import UnitSystem

__all__ = ["BIG", "card_units", "catch_all", "ident", "inactive", "keyword", "notice_only"]

BIG = 1e19  # Radioss writes "no limit" as 1e20 or 1e30; a blank or 0 field means it too


def ident(card: Card, index: int, what: str = "ID") -> int:
    """The integer keyword part ``index`` (an ID); the part after it, if any, is the
    card's unit_ID (see :func:`card_units`)."""
    if index >= len(card.parts) or not card.parts[index]:
        card.fail(f"missing {what} in the card's name")
    try:
        return int(card.parts[index])
    except ValueError:
        card.fail(f"{what} {card.parts[index]!r} is not an integer")


def card_units(deck, card: Card, index: int) -> UnitSystem:
    """The units of the card's values: those of the /UNIT whose ID is the keyword part
    ``index`` (after the card's ID), else the input units of /BEGIN."""
    if index >= len(card.parts) or card.parts[index] in ("", "0"):
        return deck.input_units
    try:
        uid = int(card.parts[index])
    except ValueError:
        card.fail(f"unit_ID {card.parts[index]!r} is not an integer")
    if uid not in deck.unit_systems:
        card.fail(f"unit_ID {uid} refers to no /UNIT")
    return deck.unit_systems[uid]


def keyword(part: str) -> str:
    """A keyword of a card's name as the tables hold it: capitals, a law's number without
    leading zeros (``/MAT/LAW02`` is ``/MAT/LAW2``)."""
    return re.sub(r"^LAW0+(?=\d)", "LAW", part.upper())


def inactive(value: float) -> bool:
    """A Radioss limit left at its default: blank (0) or 1e20-like."""
    return value == 0.0 or abs(value) >= BIG


def notice_only(read):
    """Mark ``read`` as reading cards that have no counterpart here (a notice line each)."""
    read.notice_only = True
    return read


def catch_all(read):
    """Mark ``read`` as catching the variants of a keyword that are not read (to refuse
    them naming those that are)."""
    read.catch_all = True
    return read
