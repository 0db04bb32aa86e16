"""Unit systems of a deck (``/BEGIN``) and their conversion to SI (kg, m, s).

A unit is a code (``kg``, ``Mg``, ``g``, ``mm``, ``ms``, ``mus``: an SI prefix and the
base unit g, m or s, or ``lb``, ``in``, ``ft``, ``t``) or a number, the size of the unit
in SI (``1000``, ``1.D-3``).
A quantity's dimension is the exponents of mass, length and time: a stress is
(1, -1, -2), so in kg-mm-ms its unit is 1 kg / (1e-3 m (1e-3 s)^2) = 1e9 Pa.
"""

from __future__ import annotations

from dataclasses import dataclass

from rwall_fem.radioss.reader import NumberError, parse_number

__all__ = ["DIMENSIONS", "UnitSystem", "parse_unit", "units_text"]

_PREFIXES = {
    "y": 1e-24, "z": 1e-21, "a": 1e-18, "f": 1e-15, "p": 1e-12, "n": 1e-9, "mu": 1e-6,
    "u": 1e-6, "µ": 1e-6, "μ": 1e-6, "m": 1e-3, "c": 1e-2, "d": 1e-1, "": 1.0, "da": 1e1,
    "h": 1e2, "k": 1e3, "M": 1e6, "G": 1e9, "T": 1e12, "P": 1e15, "E": 1e18,
}  # fmt: skip
_BASE = {"mass": ("g", 1e-3), "length": ("m", 1.0), "time": ("s", 1.0)}
_OTHER = {"mass": {"lb": 0.45359237, "t": 1e3}, "length": {"in": 0.0254, "ft": 0.3048}}

# Exponents of (mass, length, time) of the quantities a deck gives.
DIMENSIONS = {
    "length": (0, 1, 0),
    "time": (0, 0, 1),
    "mass": (1, 0, 0),
    "velocity": (0, 1, -1),
    "acceleration": (0, 1, -2),
    "density": (1, -3, 0),
    "stress": (1, -1, -2),
    "rate": (0, 0, -1),
    "heat_capacity_per_volume": (1, -1, -2),  # J / (m^3 K): energy per volume, per kelvin
}


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
    base, size = _BASE[quantity]
    if text in _OTHER.get(quantity, {}):
        return _OTHER[quantity][text]
    if text.endswith(base) and text[: -len(base)] in _PREFIXES:
        return _PREFIXES[text[: -len(base)]] * size
    return None


@dataclass(frozen=True)
class UnitSystem:
    """Sizes in SI of a deck's units of mass (kg), length (m) and time (s)."""

    mass: float = 1.0
    length: float = 1.0
    time: float = 1.0
    names: tuple[str, str, str] = ("kg", "m", "s")

    def factor(self, quantity: str) -> float:
        """What a value of ``quantity`` in these units is multiplied by to be in SI."""
        a, b, c = DIMENSIONS[quantity]
        return self.mass**a * self.length**b * self.time**c

    def describe(self) -> str:
        return "-".join(self.names)


def units_text(sizes: tuple[float, float, float], names: tuple[str, str, str]) -> str:
    """A unit system as ``output.units`` writes it: its codes (``kg-mm-ms``) when each
    names its size, else the sizes in SI separated by blanks (``1000 0.001 1``)."""
    coded = all(parse_unit(n, q) == s for n, q, s in zip(names, ("mass", "length", "time"),
                                                           sizes, strict=True))  # fmt: skip
    if coded and all(n.isalpha() for n in names):
        return "-".join(names)
    return " ".join(f"{s:g}" for s in sizes)
