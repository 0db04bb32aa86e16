"""Unit systems of a deck (``/BEGIN``): a unit field is a code (``kg``, ``Mg``, ``g``,
``mm``, ``ms``, ``mus``: an SI prefix and the base unit g, m or s, or ``lb``, ``in``,
``ft``, ``t``) or a number, the size of the unit in SI (``1000``, ``1.D-3``), read as
Radioss reads numbers. The systems and their factors are :mod:`rwall_fem.units`'."""

from __future__ import annotations

from rwall_fem.radioss.reader import NumberError, parse_number
from rwall_fem.units import DIMENSIONS, UnitSystem, code_size, parse_system

__all__ = ["parse_unit", "units_text"]


def parse_unit(text: str, quantity: str) -> float | None:
    """The size in SI of the unit ``text`` of ``quantity`` ("mass", "length", "time"): a
    code, or a number (``1000``, ``1.D-3``); None if it is neither, or blank (the
    caller's default). ValueError (its message says why) for a number that is not a
    size: not finite, or not above 0."""
    text = text.strip()
    if not text:
        return None
    try:
        value = parse_number(text)
    except NumberError as err:
        if "finite" in str(err):
            raise ValueError(str(err)) from None
    else:
        if value <= 0:
            raise ValueError(f"{value:g} is not a size (a unit's size in SI is above 0)")
        return value
    return code_size(text, quantity)


def units_text(sizes: tuple[float, float, float], names: tuple[str, str, str]) -> str:
    """A unit system as ``output.units`` writes it: its codes (``kg-mm-ms``) when each
    names its size, else the sizes in SI separated by blanks (``1000 0.001 1``)."""
    text = "-".join(names)
    try:
        coded = parse_system(text)
    except ValueError:
        coded = None
    if coded is not None and (coded.mass, coded.length, coded.time) == tuple(sizes):
        return text
    return " ".join(f"{s:.17g}" for s in sizes)
