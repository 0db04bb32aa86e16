"""The cards of a deck, one module per family of cards.

Each module declares the cards it reads: ``STARTER`` and ``ENGINE``, dicts from a
keyword path (``"NODE"``, ``"MAT/LAW2"``, ``"RWALL/PLANE"``) to a function
``read(deck, card)`` that reads such a :class:`~rwall_fem.radioss.reader.Card` into the
:class:`~rwall_fem.radioss.model.Deck` (in SI) or refuses it in one line. A card is read
by the function of the longest path that its first keywords match (``/MAT/LAW2/7``:
``MAT/LAW2``); a path of one keyword catches the card's other variants, to refuse them
naming what is read. A module may also define ``FIRST``, the paths of its cards read
before all others (/UNIT, which the cards before it may name), and ``finish(deck)``,
called once every card of its file (starter or engine) is read, in the order of
:data:`STARTER_FAMILIES` (nodes are read before the groups that refer to them are
resolved, /DEF_SOLID's defaults apply to every /PROP).

A card's values are in the input units of /BEGIN, or in those of the /UNIT it names
after its ID (:func:`~rwall_fem.radioss.cards.base.card_units`).

A new family of cards (shells, interfaces, loads, rigid bodies) is a module here and one
entry in the tuple of its file; the reader and its refusals of unknown cards need
nothing else.
"""

from __future__ import annotations

from collections.abc import Callable

from rwall_fem.radioss.cards import (
    begin,
    conditions,
    control,
    failures,
    functions,
    groups,
    interfaces,
    loads,
    materials,
    nodes,
    parts,
    rigid_bodies,
    run,
    shells,
    solids,
    walls,
)
from rwall_fem.radioss.cards.base import keyword

__all__ = ["ENGINE_FAMILIES", "STARTER_FAMILIES", "keyword", "lookup", "supported", "table"]

STARTER_FAMILIES = (
    begin, nodes, solids, shells, parts, materials, failures, groups, functions, conditions,
    walls, control, loads, rigid_bodies, interfaces,
)  # fmt: skip
ENGINE_FAMILIES = (run, control)

Reader = Callable[..., None]


def table(families, which: str) -> dict[tuple[str, ...], Reader]:
    """The readers of ``which`` ("STARTER" or "ENGINE") cards of ``families``, by path."""
    out: dict[tuple[str, ...], Reader] = {}
    for module in families:
        for path, read in getattr(module, which, {}).items():
            key = tuple(path.upper().split("/"))
            if key in out:
                raise RuntimeError(f"the card {path} is read by two families")  # a coding error
            out[key] = read
    return out


def lookup(readers: dict[tuple[str, ...], Reader], card) -> Reader | None:
    """The reader of the longest path that the card's first keywords match, or None
    (``LAW01`` is ``LAW1``, as Radioss reads it)."""
    keys = tuple(keyword(p) for p in card.parts)
    for length in range(min(len(keys), 4), 0, -1):
        read = readers.get(keys[:length])
        if read is not None:
            return read
    return None


def supported(readers: dict[tuple[str, ...], Reader]) -> str:
    """The cards of the model that ``readers`` read, in the order of their families (not
    those only noticed, nor the catch-alls that refuse), as a list for messages."""
    paths = ["/" + "/".join(k) for k, read in readers.items()
             if not getattr(read, "notice_only", False)
             and not getattr(read, "catch_all", False)]  # fmt: skip
    return ", ".join(paths)
