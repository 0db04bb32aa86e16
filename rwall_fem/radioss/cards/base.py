"""What the card families share: the ID in a card's name, marks for the registry, and
Radioss's "no limit" values."""

from __future__ import annotations

import re

from rwall_fem.radioss.reader import Card

__all__ = ["BIG", "catch_all", "ident", "inactive", "keyword", "notice_only"]

BIG = 1e19  # Radioss writes "no limit" as 1e20 or 1e30; a blank or 0 field means it too


def ident(card: Card, index: int, what: str = "ID") -> int:
    """The integer keyword part ``index`` (an ID); a unit_ID after it must be absent."""
    if index >= len(card.parts) or not card.parts[index]:
        card.fail(f"missing {what} in the card's name")
    try:
        value = int(card.parts[index])
    except ValueError:
        card.fail(f"{what} {card.parts[index]!r} is not an integer")
    if index + 1 < len(card.parts) and card.parts[index + 1] not in ("", "0"):
        card.fail(
            f"unit_ID {card.parts[index + 1]}: local unit systems (/UNIT) are not supported; "
            "give the values in the input units of /BEGIN"
        )
    return value


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
