"""Groups, surfaces and boxes as their cards list them: /GRNOD, /GRBRIC, /GRSHEL,
/GRSH3N, /SURF and /BOX (RECTA, SPHER, CYLIN). What a group selects is worked out by
:mod:`rwall_fem.radioss.groups` once every card is read (the groups it names, the
parts, nodes and elements may come later in the deck)."""

from __future__ import annotations

import numpy as np

from rwall_fem.radioss.cards.base import card_units, catch_all, ident
from rwall_fem.radioss.model import Box, Deck, Group
from rwall_fem.radioss.reader import Card, DeckError, fixed_table, read_fields

__all__ = ["ELEMENT_KINDS", "NODE_KINDS", "STARTER", "SURFACE_KINDS", "finish"]

# What each family's lists may hold (the card's second keyword).
NODE_KINDS = ("NODE", "NODENS", "GRNOD", "PART", "SUBSET", "MAT", "PROP", "BOX", "SURF",
              "GRBRIC", "GRSHEL", "GRSH3N")  # fmt: skip
ELEMENT_KINDS = ("GR", "PART", "SUBSET", "MAT", "PROP", "BOX", "BOX2")  # GR: its own groups
_OWN = {"GRBRIC": "BRIC", "GRSHEL": "SHEL", "GRSH3N": "SH3N"}  # a list of element IDs
SURFACE_KINDS = ("SEG", "SURF", "GRSHEL", "GRSH3N", "PART", "SUBSET", "MAT", "PROP", "BOX",
                 "BOX2")  # fmt: skip
_SOLID_FACES = ("PART", "SUBSET", "MAT", "PROP", "BOX", "BOX2")  # may add /EXT or /ALL


def id_list(card: Card, start: int = 1) -> np.ndarray:
    """The IDs listed from data line ``start``, ten 10-character fields a line, signed, in
    order, blanks and zeros left out."""
    columns = fixed_table(card, start, " ".join(f"i:id{k}" for k in range(10)))
    ids = np.column_stack(columns).ravel()
    return ids[ids != 0]


def _node_group(deck: Deck, card: Card) -> None:
    kind = card.key(1)
    if kind not in NODE_KINDS:
        card.fail(f"unsupported node group; supported: /GRNOD/{', /GRNOD/'.join(NODE_KINDS)}")
    gid = ident(card, 2, "grnd_ID")
    if gid in deck.groups:
        card.fail(f"node group {gid} is defined twice")
    kind = "NODE" if kind == "NODENS" else kind  # the same nodes, in the listed order
    deck.groups[gid] = Group("GRNOD", gid, card.title(), kind, id_list(card), card.header.where)


def _element_group(deck: Deck, card: Card) -> None:
    family, kind = card.key(0), card.key(1)
    allowed = (_OWN[family], family, *ELEMENT_KINDS[1:])
    if kind not in allowed:
        card.fail(f"unsupported element group; supported: /{family}/{', /{family}/'.join(allowed)}")
    gid = ident(card, 2, f"{family.lower()}_ID")
    if (family, gid) in deck.element_groups:
        card.fail(f"{family} group {gid} is defined twice")
    group = Group(family, gid, card.title(), kind, id_list(card), card.header.where)
    deck.element_groups[family, gid] = group


def _surface(deck: Deck, card: Card) -> None:
    kind = card.key(1)
    flavour = card.key(2) if card.key(2) in ("EXT", "ALL") else ""
    if kind not in SURFACE_KINDS or (flavour and kind not in _SOLID_FACES):
        card.fail("unsupported surface; supported: /SURF/SEG, /SURF/SURF, /SURF/GRSHEL, "
                  "/SURF/GRSH3N, and /SURF/PART, SUBSET, MAT, PROP, BOX, BOX2 (with /EXT: the "
                  "outer faces of their solids, /ALL: every face)")  # fmt: skip
    sid = ident(card, 3 if flavour else 2, "surf_ID")
    if sid in deck.surfaces:
        card.fail(f"surface {sid} is defined twice")
    name = f"{kind}/{flavour}" if flavour else kind
    group = Group("SURF", sid, card.title(), name, np.zeros(0, np.int64), card.header.where)
    if kind == "SEG":
        seg, n1, n2, n3, n4 = fixed_table(card, 1, "i:seg_ID i:N1 i:N2 i:N3 i:N4")
        nodes = np.column_stack([n1, n2, n3, np.where(n4 > 0, n4, n3)])
        bad = np.flatnonzero((nodes[:, :3] <= 0).any(axis=1))
        if len(bad):
            card.fail(f"segment {seg[bad[0]]}: a segment has 3 or 4 node IDs (N4 blank: a "
                      "triangle)", card.lines[1 + bad[0]])  # fmt: skip
        group.segments = nodes
    elif kind in ("BOX", "BOX2"):
        (box,) = card.read(1, "i:box_ID", "box_ID")
        group.items = np.array([box])
    else:
        group.items = id_list(card)
    deck.surfaces[sid] = group


def _box(deck: Deck, card: Card) -> None:
    shape = card.key(1)
    bid = ident(card, 2, "box_ID")
    if bid in deck.boxes:
        card.fail(f"box {bid} is defined twice")
    length = card_units(deck, card, 3).length
    box = Box(bid, shape, card.header.where)
    if shape == "RECTA":
        n1, n2, skew = card.read(1, "i:N1 i:N2 i:skew_ID", "N1 N2 skew_ID")
        if skew:
            card.fail("a box in a skew (skew_ID) is not supported", card.lines[1])
        box.low = np.array(card.read(2, "f:X f:Y f:Z", "Xp1 Yp1 Zp1")) * length
        box.high = np.array(card.read(3, "f:X f:Y f:Z", "Xp2 Yp2 Zp2")) * length
        box.node_refs = {"low": n1, "high": n2}
    elif shape == "SPHER":
        line = card.line(1, "N1 Diameter")
        n1, diameter = read_fields(card, line, "i:N1 -:blank:20 f:Diameter")
        box.center = np.array(card.read(2, "f:X f:Y f:Z", "Xp1 Yp1 Zp1")) * length
        box.radius = diameter * length / 2
        box.node_refs = {"center": n1}
    else:
        line = card.line(1, "Base_N Dir_N Diameter")
        n1, n2, diameter = read_fields(card, line, "i:Base_N i:Dir_N -:blank f:Diameter")
        box.center = np.array(card.read(2, "f:X f:Y f:Z", "Xp1 Yp1 Zp1")) * length
        box.end = np.array(card.read(3, "f:X f:Y f:Z", "Xp2 Yp2 Zp2")) * length
        box.radius = diameter * length / 2
        box.node_refs = {"center": n1, "end": n2}
    deck.boxes[bid] = box


@catch_all
def _other_box(deck: Deck, card: Card) -> None:
    card.fail("unsupported box; supported: /BOX/RECTA, /BOX/SPHER, /BOX/CYLIN")


def finish(deck: Deck) -> None:
    """Boxes given by nodes take their nodes' positions; a box is not empty."""
    for box in deck.boxes.values():
        for name, node in box.node_refs.items():
            if node:
                row = deck.node_positions(np.array([node]))[0]
                if row < 0:
                    _refuse(box, f"node {node} refers to no /NODE")
                setattr(box, name, deck.coordinates[row].copy())
        if box.shape == "RECTA":
            box.low, box.high = np.minimum(box.low, box.high), np.maximum(box.low, box.high)
        elif box.radius <= 0:
            _refuse(box, "Diameter: a box's diameter is > 0")
        elif box.shape == "CYLIN" and np.linalg.norm(box.end - box.center) == 0:
            _refuse(box, "the axis points are the same point")


def _refuse(box: Box, what: str):
    raise DeckError(f"{box.where}: /BOX/{box.shape}/{box.id}: {what}")


STARTER = {
    "GRNOD": _node_group,
    "GRBRIC": _element_group,
    "GRSHEL": _element_group,
    "GRSH3N": _element_group,
    "SURF": _surface,
    "BOX/RECTA": _box,
    "BOX/SPHER": _box,
    "BOX/CYLIN": _box,
    "BOX": _other_box,
}
