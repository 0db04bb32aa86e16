"""Initial and boundary conditions on node groups: /INIVEL/TRA, /BCS, /IMPVEL and /GRAV
(with a /FUNCT of time)."""

from __future__ import annotations

import numpy as np

from rwall_fem.radioss.cards.base import BIG, card_units, catch_all, ident
from rwall_fem.radioss.model import Deck, Prescribed
from rwall_fem.radioss.reader import Card, read_fields

__all__ = ["STARTER"]


def _initial_velocity(deck: Deck, card: Card) -> None:
    ident(card, 2, "inivel_ID")
    units = card_units(deck, card, 3)
    vx, vy, vz, group, skew = card.read(1, "f:Vx f:Vy f:Vz i:grnd_ID i:skew_ID",
                                        "Vx Vy Vz Gnod_id Skew_id")  # fmt: skip
    if skew:
        card.fail("a skew (Skew_id) is not supported", card.lines[1])
    tstart, sensor = card.read_optional(2, "f:Tstart i:sens_ID")
    if tstart or sensor:
        card.fail("Tstart and sens_ID are not supported: the velocity is initial", card.lines[2])
    velocity = np.array([vx, vy, vz]) * units.factor("velocity")
    deck.initial.append((velocity, group, card.lines[1].where))


@catch_all
def _other_initial_velocity(deck: Deck, card: Card) -> None:
    card.fail("unsupported initial velocity; supported: /INIVEL/TRA")


def _clamp(deck: Deck, card: Card) -> None:
    if len(card.parts) > 1 and not card.parts[1].lstrip("-").isdigit():
        card.fail("unsupported boundary condition; supported: /BCS")
    ident(card, 1, "bcs_ID")
    line = card.line(1, "Tra rot skew_ID grnd_ID")
    code, skew, group = read_fields(card, line, "s:Trarot:10 i:skew_ID i:grnd_ID")
    if line.free:
        digits = code.replace(" ", "")
        tra = digits[:3] if len(digits) in (3, 6) else ""
    else:
        tra = line.text[3:6].replace(" ", "0") if len(code) else ""
        digits = line.text[:10].replace(" ", "")
    if not tra or any(c not in "01" for c in digits):
        card.fail(f"Tra rot = {code!r}: six codes 0 or 1 (TX TY TZ, then rotations), right "
                  "aligned in the first 10 columns", line)  # fmt: skip
    if skew:
        card.fail("a skew (skew_ID) is not supported", line)
    components = "".join(axis for axis, c in zip("xyz", tra, strict=True) if c == "1")
    rotations = "".join(axis for axis, c in zip("xyz", digits[3:6]) if c == "1")
    if not components:
        if rotations:
            card.fail("rotations held without the translations (Tra 000): a boundary holds "
                      "translations, and rotations beside them", line)  # fmt: skip
        deck.warn(card, "no translation is fixed (Tra 000): nothing to do on solid nodes", line)
        return
    if rotations:  # shells hold them; the deck's solids have none (said when it is known)
        deck.held_rotations[line.where] = rotations
    deck.clamps.append((components, group, line.where))


def _prescribed(deck: Deck, card: Card, quantity: str, grav: bool = False) -> Prescribed:
    """/IMPVEL or /GRAV: fct_IDT Dir skew sens grnd (frame icoor), Ascale_x Fscale_y."""
    ident(card, 1, "ID")
    units = card_units(deck, card, 2)
    line = card.line(1, "fct_IDT Dir skew_ID sens_ID grnd_ID frame_ID icoor")
    fct, direction, skew, sensor, group, frame, icoor = read_fields(
        card, line, "i:fct_IDT s:Dir i:skew_ID i:sens_ID i:grnd_ID i:frame_ID i:icoor"
    )
    direction = direction.upper()
    if direction not in ("X", "Y", "Z"):
        card.fail(f"Dir = {direction!r}: X, Y or Z (translations)", line)
    if skew or sensor or frame or icoor:
        card.fail("skew_ID, sens_ID, frame_ID and icoor are not supported; leave them blank",
                  line)  # fmt: skip
    if fct <= 0:
        card.fail("fct_IDT (the function of time) is missing", line)
    a_scale, y_scale = 1.0, 1.0
    if len(card.lines) > 2:
        layout = "f:Ascale_x f:Fscale_y" if grav else "f:Ascale_x f:Fscale_y f:Tstart f:Tstop"
        values = card.read(2, layout, layout.replace("f:", ""))
        a_scale, y_scale = values[0] or 1.0, values[1] or 1.0
        if not grav and (values[2] or (values[3] and values[3] < BIG)):
            card.fail("Tstart and Tstop are not supported: the velocity is imposed from t = 0 to "
                      "the end", card.lines[2])  # fmt: skip
    return Prescribed(card.name, fct, direction, group, a_scale * units.time,
                      y_scale * units.factor(quantity), line.where)  # fmt: skip


def _gravity(deck: Deck, card: Card) -> None:
    deck.gravity.append(_prescribed(deck, card, "acceleration", grav=True))


def _imposed_velocity(deck: Deck, card: Card) -> None:
    deck.velocities.append(_prescribed(deck, card, "velocity"))


STARTER = {
    "INIVEL/TRA": _initial_velocity,
    "INIVEL": _other_initial_velocity,
    "BCS": _clamp,
    "GRAV": _gravity,
    "IMPVEL": _imposed_velocity,
}
