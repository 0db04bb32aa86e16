"""/RWALL: rigid walls (PLANE, CYL, SPHER, PARAL), fixed, carried by a main node or
moved by an /IMPVEL on it, in SI."""

from __future__ import annotations

import numpy as np

from rwall_fem.radioss.cards.base import card_units, catch_all, ident
from rwall_fem.radioss.model import Deck, Wall
from rwall_fem.radioss.reader import Card

__all__ = ["STARTER"]


def _wall(deck: Deck, card: Card) -> None:
    kind = card.key(1)
    wid = ident(card, 2, "rwall_ID")
    units = card_units(deck, card, 3)
    node, slide, add, exclude, iform = card.read(
        1, "i:node_ID i:Slide i:grnd_ID1 i:grnd_ID2 i:Iform", "node_ID Slide grnd_ID1 grnd_ID2"
    )
    if slide not in (0, 1, 2):
        card.fail(f"Slide = {slide}: 0 (sliding), 1 (tied) or 2 (friction)", card.lines[1])
    if iform:
        card.fail(f"Iform = {iform}: only the kinematic formulation (Iform 0) is supported",
                  card.lines[1])  # fmt: skip
    d, fric, diameter, ffac, ifq = card.read(2, "f:Dsearch f:fric f:Diameter f:ffac i:ifq",
                                             "Dsearch fric Diameter ffac ifq")  # fmt: skip
    if d < 0:
        card.fail(f"Dsearch = {d:g}: a search distance is >= 0", card.lines[2])
    if ifq not in (0, 1, 2, 3):
        card.fail(f"ifq = {ifq}: 0 (no filter), 1 (alpha), 2 (period in steps), 3 (cut-off "
                  "frequency)", card.lines[2])  # fmt: skip
    if ffac == 0.0:
        ifq = 0  # Radioss: no factor, no filter
    mass, velocity, point = 0.0, np.zeros(3), np.zeros(3)
    if node:
        m, vx, vy, vz = card.read(3, "f:Mass f:VX0 f:VY0 f:VZ0", "Mass VX0 VY0 VZ0")
        mass, velocity = m * units.mass, np.array([vx, vy, vz]) * units.factor("velocity")
    else:
        point = np.array(card.read(3, "f:XM f:YM f:ZM", "XM YM ZM")) * units.length
    points = []
    for index, name in ((4, "M1"), (5, "M2")):
        if (kind in ("PLANE", "CYL", "PARAL") and name == "M1") or (kind == "PARAL"):
            xyz = card.read(index, "f:X f:Y f:Z", f"X{name} Y{name} Z{name}")
            points.append(np.array(xyz) * units.length)
        else:
            points.append(None)
    filter_factor = ffac * (units.factor("rate") if ifq == 3 else 1.0)
    deck.walls.append(Wall(
        wid, kind, card.title(), node, slide, add, exclude, d * units.length,
        fric, diameter * units.length, ifq, filter_factor, point, mass, velocity,
        points[0], points[1], card.header.where,
    ))  # fmt: skip


@catch_all
def _other_wall(deck: Deck, card: Card) -> None:
    card.fail("unsupported rigid wall; supported: /RWALL/PLANE, /RWALL/CYL, /RWALL/SPHER, "
              "/RWALL/PARAL")  # fmt: skip


STARTER = {f"RWALL/{kind}": _wall for kind in ("PLANE", "CYL", "SPHER", "PARAL")}
STARTER["RWALL"] = _other_wall
