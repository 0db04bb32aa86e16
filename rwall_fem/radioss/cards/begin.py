"""/BEGIN: the run name, the input version and the unit systems (input units for the
starter's values, work units for the engine's)."""

from __future__ import annotations

from rwall_fem.radioss.cards.base import ident
from rwall_fem.radioss.model import Deck
from rwall_fem.radioss.reader import Card, read_fields
from rwall_fem.radioss.units import UnitSystem, parse_unit

__all__ = ["STARTER"]


def _begin(deck: Deck, card: Card) -> None:
    if deck.version:
        _again(deck, card)
        return
    deck.run_name = card.line(0, "Runname").text.strip()
    version, _ = card.read(1, "i:Invers i:Irun", "Invers Irun")
    if version < 51:
        card.fail(
            f"input version {version}: the block format of version 5.1 and later (Invers >= "
            "51: fields of 10 and 20 characters) is read; older ones have fields of 8 and 16",
            card.lines[1],
        )
    deck.version = version
    if len(card.lines) < 3 and version < 100:
        card.fail(
            f"input version {version}: no line of input units: the units of decks "
            f"before version 10 (/UNIT/MASS, LENGTH, TIME) are not read; {_GIVE}"
        )
    systems = []
    for index, what in ((3, "Work_mass_unit Work_length_unit Work_time_unit"),
                        (2, "Input_mass_unit Input_length_unit Input_time_unit")):  # fmt: skip
        # A blank line of work units is a blank card's end, which the reader drops.
        if index == 3 and index >= len(card.lines):
            line, texts = card.header, ["", "", ""]
        else:
            line = card.line(index, what)
            texts = read_fields(card, line, "s:mass:20 s:length:20 s:time:20")
        default = systems[0] if systems else UnitSystem()
        sizes, names = [], []
        for text, quantity, fallback, name in zip(
            texts, ("mass", "length", "time"),
            (default.mass, default.length, default.time), default.names, strict=True,
        ):  # fmt: skip
            try:
                size = parse_unit(text, quantity)
            except ValueError as err:
                card.fail(f"{quantity} unit {text!r}: {err}", line)
            if size is None and text:
                card.fail(
                    f"{quantity} unit {text!r}: give a code (an SI prefix and g, m or s, such "
                    "as kg, Mg, mm, ms, mus; or lb, in, ft, t) or the unit's size in SI",
                    line,
                )
            sizes.append(fallback if size is None else size)
            names.append(text or name)
        systems.append(UnitSystem(*sizes, names=tuple(names)))
    deck.work_units, deck.input_units = systems
    deck.begin_where = card.header.where


_GIVE = "give /BEGIN's lines of input and work units (kg mm ms, ...), as version 10 and later"


def _again(deck: Deck, card: Card) -> None:
    """A second /BEGIN (an included file written as a deck of its own): skipped if its
    units are the deck's, refused otherwise (its values would be in other units)."""
    first = (deck.input_units, deck.work_units, deck.begin_where, deck.version, deck.run_name)
    deck.version = 0
    try:
        _begin(deck, card)
        units = [_sizes(deck.input_units), _sizes(deck.work_units)]
    finally:
        deck.input_units, deck.work_units, deck.begin_where, deck.version, deck.run_name = first
    if units != [_sizes(deck.input_units), _sizes(deck.work_units)]:
        card.fail(f"a second /BEGIN, in other units than the first ({deck.begin_where}): a deck "
                  "has one input and one work unit system")  # fmt: skip
    deck.notice(card, f"a second /BEGIN, in the units of the first ({deck.begin_where}): skipped")


def _sizes(units: UnitSystem) -> tuple[float, float, float]:
    return (units.mass, units.length, units.time)


def _unit(deck: Deck, card: Card) -> None:
    """/UNIT: a local unit system, in which a card that names its ID gives its values."""
    if card.key(1) in ("MASS", "LENGTH", "TIME"):
        card.fail(f"the units of decks before version 10 are not read; {_GIVE}")
    uid = ident(card, 1, "unit_ID")
    if uid in deck.unit_systems:
        card.fail(f"unit system {uid} is defined twice")
    line = card.line(1, "mass_unit length_unit time_unit")
    texts = read_fields(card, line, "s:mass:20 s:length:20 s:time:20")
    sizes = []
    for text, quantity in zip(texts, ("mass", "length", "time"), strict=True):
        try:
            size = parse_unit(text, quantity)
        except ValueError as err:
            card.fail(f"{quantity} unit {text!r}: {err}", line)
        if size is None:
            card.fail(f"{quantity} unit {text!r}: a /UNIT gives its three units, codes (kg, "
                      "mm, ms, ...) or sizes in SI", line)  # fmt: skip
        sizes.append(size)
    deck.unit_systems[uid] = UnitSystem(*sizes, names=tuple(texts))


STARTER = {"BEGIN": _begin, "UNIT": _unit}
# Read before the other cards: the /UNIT of a card may come after it.
FIRST = ("UNIT",)
