"""Unit systems: the sizes in SI of a unit of mass, length and time, and the factors of
the quantities made of them.

A unit is a code (``kg``, ``Mg``, ``g``, ``mm``, ``ms``, ``mus``: an SI prefix and the
base unit g, m or s; or ``lb``, ``in``, ``ft``, ``t``) or the size of the unit in SI. A
quantity's dimension is the exponents of mass, length and time: a stress is (1, -1, -2),
so in kg-mm-ms its unit is 1 kg / (1e-3 m (1e-3 s)^2) = 1e9 Pa.

The scene's ``output.units`` is a system written ``"SI"``, as three codes
(``"kg-mm-ms"``, ``"g mm ms"``) or three sizes (``"1000 0.001 1"``): see
:func:`parse_system`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["DIMENSIONS", "SI", "UnitSystem", "code_size", "parse_system"]

PREFIXES = {
    "y": 1e-24, "z": 1e-21, "a": 1e-18, "f": 1e-15, "p": 1e-12, "n": 1e-9, "mu": 1e-6,
    "u": 1e-6, "µ": 1e-6, "μ": 1e-6, "m": 1e-3, "c": 1e-2, "d": 1e-1, "": 1.0, "da": 1e1,
    "h": 1e2, "k": 1e3, "M": 1e6, "G": 1e9, "T": 1e12, "P": 1e15, "E": 1e18,
}  # fmt: skip
_BASE = {"mass": ("g", 1e-3), "length": ("m", 1.0), "time": ("s", 1.0)}
_OTHER = {"mass": {"lb": 0.45359237, "t": 1e3}, "length": {"in": 0.0254, "ft": 0.3048}}
QUANTITIES = ("mass", "length", "time")

# Exponents of (mass, length, time) of the quantities a deck or an output gives.
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
    "force": (1, 1, -2),
    "impulse": (1, 1, -1),  # and momentum
    "energy": (1, 2, -2),
    "inertia": (1, 2, 0),  # kg m^2
    "angular_momentum": (1, 2, -1),  # kg m^2/s
}


def code_size(text: str, quantity: str) -> float | None:
    """The size in SI of the unit code ``text`` of ``quantity`` ("mass", "length",
    "time"); None if it is no such code."""
    base, size = _BASE[quantity]
    if text in _OTHER.get(quantity, {}):
        return _OTHER[quantity][text]
    if text.endswith(base) and text[: -len(base)] in PREFIXES:
        return PREFIXES[text[: -len(base)]] * size
    return None


@dataclass(frozen=True)
class UnitSystem:
    """Sizes in SI of a system's units of mass (kg), length (m) and time (s)."""

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

    @property
    def is_si(self) -> bool:
        return (self.mass, self.length, self.time) == (1.0, 1.0, 1.0)


SI = UnitSystem()


def parse_system(text: str) -> UnitSystem:
    """The unit system ``text``: ``"SI"``, three codes separated by ``-`` or blanks
    (``"kg-mm-ms"``), or three sizes in SI separated by blanks (``"1000 0.001 1"``).
    ValueError, its message saying what is allowed, if it is none of them."""
    if text.strip().upper() == "SI":
        return SI
    words = text.split() if len(text.split()) == 3 else text.strip().split("-")
    if len(words) != 3:
        raise ValueError(_ALLOWED)
    sizes = []
    for word, quantity in zip(words, QUANTITIES, strict=True):
        size = code_size(word, quantity)
        if size is None:
            try:
                size = float(word)
            except ValueError:
                raise ValueError(f"{word[:20]!r} is no {quantity} unit; {_ALLOWED}") from None
            if not (math.isfinite(size) and size > 0):
                raise ValueError(f"{word[:20]!r} is no {quantity} unit's size; {_ALLOWED}")
        sizes.append(size)
    return UnitSystem(*sizes, names=tuple(words))


_ALLOWED = ('give "SI", three codes of mass, length and time ("kg-mm-ms", "Mg-mm-s", "g mm '
            'ms") or their sizes in SI ("1000 0.001 1")')  # fmt: skip
