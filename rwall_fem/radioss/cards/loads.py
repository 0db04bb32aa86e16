"""Loads, added masses and damping: /CLOAD (a force history on each node of a group),
/PLOAD (a pressure history on a /SURF), /ADMAS (mass added to a node group) and /DAMP
(Rayleigh damping of a node group); they become the scene's ``[[load]]``,
``[[added_mass]]`` and ``[damping]`` (:mod:`rwall_fem.radioss.loads`)."""

from __future__ import annotations

from dataclasses import dataclass

from rwall_fem.radioss.cards.base import BIG, card_units, ident
from rwall_fem.radioss.model import Deck, Prescribed
from rwall_fem.radioss.reader import Card

__all__ = ["STARTER", "AddedMass", "Damping", "Pressure"]


@dataclass
class Pressure:
    """A /PLOAD: the function ``fct`` scaled to SI (time ``t_scale``, pressure
    ``y_scale``, Pa) on the segments of the /SURF ``surface``."""

    card: str
    fct: int
    surface: int
    t_scale: float
    y_scale: float
    where: str


@dataclass
class AddedMass:
    """An /ADMAS of type 0 (``mass`` kg on each node of ``group``) or 1 (``mass`` kg spread
    equally over its nodes)."""

    card: str
    mass: float
    group: int
    per: str  # "node" or "set"
    where: str


@dataclass
class Damping:
    """A /DAMP: ``alpha`` (1/s) and ``beta`` (s) on the nodes of ``group``."""

    card: str
    alpha: float
    beta: float
    group: int
    where: str


def _function_type(card: Card, itypfun: int, line) -> None:
    if itypfun not in (0, 1):
        card.fail(f"Itypfun = {itypfun}: only functions of time (Itypfun 0 or 1) are read",
                  line)  # fmt: skip


def _scales(a_scale: float, y_scale: float) -> tuple[float, float]:
    return a_scale or 1.0, y_scale or 1.0


def _force(deck: Deck, card: Card) -> None:
    """/CLOAD: fct_IDT Dir skew sens grnd Itypfun Ascale_x Fscale_y; F(t) = Fscale_y
    f(t / Ascale_x) on each node of the group."""
    ident(card, 1, "cload_ID")
    units = card_units(deck, card, 2)
    line = card.line(1, "fct_IDT Dir skew_ID sens_ID grnd_ID Itypfun Ascale_x Fscale_y")
    layout = "i:fct_IDT s:Dir i:skew_ID i:sens_ID i:grnd_ID i:Itypfun f:Ascale_x f:Fscale_y"
    fct, direction, skew, sensor, group, itypfun, a_scale, y_scale = card.read(1, layout)
    direction = direction.upper()
    if direction not in ("X", "Y", "Z"):
        card.fail(f"Dir = {direction!r}: X, Y or Z (a force: moments need rotations, which "
                  "solid nodes do not have)", line)  # fmt: skip
    if skew or sensor:
        card.fail("skew_ID and sens_ID are not supported; leave them blank", line)
    _function_type(card, itypfun, line)
    if fct <= 0:
        card.fail("fct_IDT (the function of time) is missing", line)
    if group <= 0:
        card.fail("grnd_ID (the node group) is missing", line)
    a_scale, y_scale = _scales(a_scale, y_scale)
    deck.loads.append(Prescribed(card.name, fct, direction, group, a_scale * units.time,
                                 y_scale * units.factor("force"), line.where))  # fmt: skip


def _pressure(deck: Deck, card: Card) -> None:
    """/PLOAD: surf_ID fct_IDT sens Ipinch Idel Itypfun Ascale_x Fscale_y; p(t) = Fscale_y
    f(t / Ascale_x), positive along each segment's normal (N1N3 x N2N4), as Radioss
    applies it."""
    ident(card, 1, "pload_ID")
    units = card_units(deck, card, 2)
    line = card.line(1, "surf_ID fct_IDT sens_ID Ipinch Idel Itypfun Ascale_x Fscale_y")
    layout = "i:surf_ID i:fct_IDT i:sens_ID i:Ipinch i:Idel i:Itypfun f:Ascale_x f:Fscale_y"
    surface, fct, sensor, pinch, _, itypfun, a_scale, y_scale = card.read(1, layout)
    if sensor or pinch:
        card.fail("sens_ID and Ipinch are not supported; leave them blank", line)
    _function_type(card, itypfun, line)
    if fct <= 0:
        card.fail("fct_IDT (the function of time) is missing", line)
    if surface <= 0:
        card.fail("surf_ID (the surface) is missing", line)
    a_scale, y_scale = _scales(a_scale, y_scale)
    deck.pressures.append(Pressure(card.name, fct, surface, a_scale * units.time,
                                   y_scale * units.factor("stress"), line.where))  # fmt: skip


_ADMAS_TYPES = {0: "node", 1: "set"}


def _added_mass(deck: Deck, card: Card) -> None:
    """/ADMAS/type: Mass grnd_ID; type 0 on each node, type 1 spread over the group."""
    kind = ident(card, 1, "type")
    if kind not in _ADMAS_TYPES:
        card.fail(f"type {kind}: rwall_fem reads types 0 (Mass on each node of a node group) "
                  "and 1 (Mass spread over its nodes)")  # fmt: skip
    ident(card, 2, "admas_ID")
    units = card_units(deck, card, 3)
    line = card.line(1, "Mass grnd_ID")
    mass, group = card.read(1, "f:Mass i:grnd_ID")
    if not mass > 0.0:
        card.fail(f"Mass = {mass:g}: an added mass is above 0", line)
    if group <= 0:
        card.fail("grnd_ID (the node group) is missing", line)
    deck.added_masses.append(AddedMass(card.name, mass * units.factor("mass"), group,
                                       _ADMAS_TYPES[kind], line.where))  # fmt: skip


def _damping(deck: Deck, card: Card) -> None:
    """/DAMP: Alpha Beta grnd_ID skew_ID Tstart Tstop, then (the full format) the
    coefficients of each direction, Alpha_y Beta_y, Alpha_z Beta_z, and of the rotations."""
    if len(card.parts) > 1 and not card.parts[1].lstrip("-").isdigit():
        card.fail("unsupported damping; supported: /DAMP (Rayleigh damping of a node group)")
    ident(card, 1, "damp_ID")
    units = card_units(deck, card, 2)
    line = card.line(1, "Alpha Beta grnd_ID skew_ID Tstart Tstop")
    layout = "f:Alpha f:Beta i:grnd_ID i:skew_ID f:Tstart f:Tstop"
    alpha, beta, group, skew, start, stop = card.read(1, layout)
    if skew:
        card.fail("a skew (skew_ID) is not supported", line)
    if start or (stop and stop < BIG):
        card.fail("Tstart and Tstop are not supported: the damping acts over the whole run",
                  line)  # fmt: skip
    if group <= 0:
        card.fail("grnd_ID (the node group) is missing", line)
    if alpha < 0 or beta < 0 or not (alpha or beta):
        card.fail(f"Alpha = {alpha:g}, Beta = {beta:g}: both at least 0, one above 0", line)
    for k, axis in ((2, "y"), (3, "z")):  # the full format
        if k < len(card.lines):
            other = card.read(k, f"f:Alpha_{axis} f:Beta_{axis}")
            if other != [alpha, beta]:
                card.fail(f"Alpha_{axis}, Beta_{axis} = {other[0]:g}, {other[1]:g} differ from "
                          "Alpha, Beta: damping that depends on the direction is not "
                          "supported", card.lines[k])  # fmt: skip
    if len(card.lines) > 4:
        deck.notice(card, "the rotational coefficients (Alpha_xx ... Beta_zz) are not used: "
                    "solid nodes have no rotations")  # fmt: skip
    deck.dampings.append(Damping(card.name, alpha / units.time, beta * units.time, group,
                                 line.where))  # fmt: skip


STARTER = {
    "CLOAD": _force,
    "PLOAD": _pressure,
    "ADMAS": _added_mass,
    "DAMP": _damping,
}
