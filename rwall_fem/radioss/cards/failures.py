"""/FAIL: failure models of a material. /FAIL/JOHNSON (Johnson-Cook's D1-D5 damage, the
element deleted when a point fails) is read; the material's [material.failure] is made
of it by :mod:`rwall_fem.radioss.materials`."""

from __future__ import annotations

from rwall_fem.radioss.cards.base import card_units, catch_all, ident
from rwall_fem.radioss.model import Deck
from rwall_fem.radioss.reader import Card

__all__ = ["STARTER"]


def _johnson_cook(deck: Deck, card: Card) -> None:
    mid = ident(card, 2, "mat_ID")
    rate = card_units(deck, card, 3).factor("rate")
    if mid in deck.failures:
        card.fail(f"a second failure model of material {mid} (the first at "
                  f"{deck.failures[mid]['where']}): a material has one here")  # fmt: skip
    d1, d2, d3, d4, d5 = card.read(0, "f:D1 f:D2 f:D3 f:D4 f:D5", "D1 D2 D3 D4 D5")
    rate0, _, solid, eps_min, _, _ = card.read_optional(
        1, "f:EPS_DOT_0 i:Ifail_sh i:Ifail_so f:EPSF_MIN f:Dadv -:blank i:Ixfem"
    )
    (points,) = card.read_optional(2, "i:FAILIP")
    line = card.lines[1] if len(card.lines) > 1 else card.header
    if solid not in (0, 1, 4):
        card.fail(f"Ifail_so = {solid}: a failed point keeps its pressure in Radioss; here a "
                  "failed cell is eroded (Ifail_so 0, 1 or 4)", line)  # fmt: skip
    if eps_min:
        card.fail(f"EPSF_MIN = {eps_min:g}: the failure strain has no floor here; leave it blank",
                  line)  # fmt: skip
    if points > 1:
        card.fail(f"FAILIP = {points}: a cell is eroded when one point fails (FAILIP 1)",
                  card.lines[2])  # fmt: skip
    deck.failures[mid] = {
        "criterion": "johnson_cook", "d1": d1, "d2": d2, "d3": d3, "d4": d4, "d5": d5,
        "reference_strain_rate": rate0 * rate if rate0 else None,
        "where": card.header.where, "card": card.name,
    }  # fmt: skip


@catch_all
def _other(deck: Deck, card: Card) -> None:
    card.fail("unsupported failure model; supported: /FAIL/JOHNSON (and a law's own failure "
              "plastic strain, EPS_p_max of /MAT/LAW2 and LAW36)")  # fmt: skip


STARTER = {"FAIL/JOHNSON": _johnson_cook, "FAIL": _other}
