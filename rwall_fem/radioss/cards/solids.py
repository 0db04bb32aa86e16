"""Solid elements and their property: /BRICK, /TETRA4 and /PROP/SOLID (/PROP/TYPE14),
whose blank fields take /DEF_SOLID's values (read at the end, wherever the cards are)."""

from __future__ import annotations

import numpy as np

from rwall_fem.radioss.cards.base import catch_all, ident
from rwall_fem.radioss.model import GROUP_CELLS, Body, Deck
from rwall_fem.radioss.reader import Card, DeckError, fixed_table, read_fields

__all__ = ["ISOLID", "STARTER", "finish"]

# Element technologies by Isolid: the scene's [element] keys.
ISOLID = {
    24: {"integration": "reduced", "hourglass": "physical"},
    14: {"integration": "full"},
    1: {"integration": "reduced", "hourglass": "viscous"},
    2: {"integration": "reduced", "hourglass": "viscous"},
}
_ISOLID_TEXT = ("24 (HEPH: one point, physical hourglass control), 14 (fully integrated), 1 "
                "and 2 (one point, viscous hourglass control)")  # fmt: skip


def _elements(deck: Deck, card: Card) -> None:
    part = ident(card, 1, "part_ID")
    count = 8 if card.key(0) == "BRICK" else 4
    layout = "i:elem_ID " + " ".join(f"i:node{k + 1}" for k in range(count))
    columns = fixed_table(card, 0, layout)
    ids, nodes = columns[0], np.column_stack(columns[1:])
    if not len(ids):
        card.fail("no elements")
    missing = np.flatnonzero((nodes <= 0).any(axis=1))
    if len(missing):
        k = missing[0]
        given = int((nodes[k] > 0).sum())
        card.fail(
            f"truncated line: element {ids[k]} needs {count} node IDs, got {given}",
            card.lines[k],
        )
    sorted_nodes = np.sort(nodes, axis=1)
    repeated = np.flatnonzero((np.diff(sorted_nodes, axis=1) == 0).any(axis=1))
    if len(repeated):
        shown = ", ".join(map(str, ids[repeated[:10]])) + (", ..." if len(repeated) > 10 else "")
        why = ("a wedge or tetrahedron written as a brick is not: DOLFINx 0.5 mishandles "
               "such cells on several ranks; write tetrahedra as /TETRA4" if count == 8 else
               "a tetrahedron with a repeated node has no volume")  # fmt: skip
        card.fail(
            f"{len(repeated)} elements repeat a node (degenerate: {shown}): only {count}-node "
            f"elements with distinct nodes are read ({why})",
            card.lines[repeated[0]],
        )
    cell = "hexahedron" if count == 8 else "tetrahedron"
    deck.bodies.append(Body(part, cell, ids, nodes, card))


def _property(deck: Deck, card: Card) -> None:
    pid = ident(card, 2, "prop_ID")
    if pid in deck.properties:
        card.fail(f"property {pid} is defined twice")
    line = card.line(1, "Isolid Ismstr Iale Icpre Itetra10 Inpts Itetra4 Iframe dn")
    isolid, ismstr, iale, icpre, _, inpts, itetra4, _, dn = read_fields(
        card, line, "i:Isolid i:Ismstr i:Iale i:Icpre i:Itetra10 i:Inpts i:Itetra4 i:Iframe f:dn"
    )
    qa, qb, h = card.read_optional(2, "f:qa f:qb f:h")
    deck.properties[pid] = {
        "unread": "solid", "card": card, "line": line.where, "where": card.header.where,
        "given": {"isolid": isolid, "ismstr": ismstr, "icpre": icpre, "itetra4": itetra4},
        "iale": iale, "inpts": inpts, "dn": dn, "qa": qa, "qb": qb, "h": h,
    }  # fmt: skip


@catch_all
def _other_property(deck: Deck, card: Card) -> None:
    card.fail("unsupported property; supported: /PROP/SOLID (/PROP/TYPE14), /PROP/SHELL "
              "(/PROP/TYPE1), /PROP/VOID (/PROP/TYPE0)")  # fmt: skip


def _void_property(deck: Deck, card: Card) -> None:
    """/PROP/VOID (/PROP/TYPE0): the property of void elements, which are left out."""
    pid = ident(card, 2, "prop_ID")
    if pid in deck.properties:
        card.fail(f"property {pid} is defined twice")
    deck.properties[pid] = {"void": True, "where": card.header.where}


def finish(deck: Deck) -> None:
    """Every /PROP/SOLID with /DEF_SOLID's values in its blank fields, checked; every
    solid element ID used once."""
    for pid, raw in deck.properties.items():
        if raw.get("unread") == "solid":
            deck.properties[pid] = _solid_property(deck, raw)
    _element_ids_once(deck)


def _solid_property(deck: Deck, raw: dict) -> dict:
    """The facts of a /PROP/SOLID: Isolid, Icpre, the [element] keys; refusals of what
    has no counterpart name its line."""
    card: Card = raw["card"]
    line = next(li for li in card.lines if li.where == raw["line"])
    value = {k: v or deck.solid_defaults.get(k, 0) for k, v in raw["given"].items()}
    isolid = value["isolid"] or 1  # Radioss's default without /DEF_SOLID
    why = " (from /DEF_SOLID)" if not raw["given"]["isolid"] and value["isolid"] else ""
    if isolid not in ISOLID:
        card.fail(f"Isolid = {isolid}{why}: supported: {_ISOLID_TEXT}", line)
    if value["ismstr"] not in (0, 2, 4):
        card.fail(f"Ismstr = {value['ismstr']}: small-strain formulations are not supported; "
                  "leave Ismstr blank (full geometric non-linearity)", line)  # fmt: skip
    if raw["iale"]:
        card.fail(f"Iale = {raw['iale']}: ALE and Euler elements are not supported", line)
    if isolid == 14 and raw["inpts"] not in (0, 222):
        card.fail(f"Inpts = {raw['inpts']}: Isolid 14 is read with 2 x 2 x 2 points (Inpts 222)",
                  line)  # fmt: skip
    facts = {"isolid": isolid, "icpre": value["icpre"], "element": dict(ISOLID[isolid]),
             "where": card.header.where, "line": line.where,
             "itetra4": value["itetra4"]}  # fmt: skip
    h = raw["h"]
    if isolid in (1, 2):
        facts["element"]["hourglass_coefficient"] = h if h else 0.1
    elif h:
        deck.warn(card, f"h = {h:g} is not used with Isolid {isolid}", line)
    if raw["qa"] or raw["qb"]:
        deck.warn(card, "qa, qb (bulk viscosity) are not used: rwall_fem has no bulk viscosity",
                  line)  # fmt: skip
    if raw["dn"]:
        deck.warn(card, "dn (numerical damping) is not used", line)
    return facts


def _element_ids_once(deck: Deck) -> None:
    """Refuse an element ID used by two solid elements, naming both lines (Radioss
    refuses it: an element ID names one element of its kind)."""
    solids = [b for b in deck.bodies if b.cell in GROUP_CELLS["GRBRIC"]]
    if not solids:
        return
    ids = np.concatenate([b.ids for b in solids])
    unique, first, counts = np.unique(ids, return_index=True, return_counts=True)
    if not np.any(counts > 1):
        return
    twice = unique[counts > 1]
    where = [(body.card.lines[k].where, body.card.name) for body in solids
             for k in np.flatnonzero(body.ids == twice[0])]  # fmt: skip
    more = f"; {len(twice)} IDs are used more than once" if len(twice) > 1 else ""
    (first, card), (again, other) = where[:2]
    raise DeckError(f"{first}: {card}: element ID {twice[0]} is used twice (again at {again}, "
                    f"{other}){more}: an element ID names one element")  # fmt: skip


STARTER = {
    "BRICK": _elements,
    "TETRA4": _elements,
    "PROP/SOLID": _property,
    "PROP/TYPE14": _property,
    "PROP/VOID": _void_property,
    "PROP/TYPE0": _void_property,
    "PROP": _other_property,
}
