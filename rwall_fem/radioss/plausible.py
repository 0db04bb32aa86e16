"""Whether a deck's numbers fit the units its /BEGIN declares.

A unit slip is the commonest mistake in a deck written by hand or moved between tools:
a steel density of 7.8e-6 (kg/mm^3) left in a deck declared in kg, m, s is a gas a
million times lighter than air, and the run that follows is nonsense. Radioss runs it;
rwall_fem warns once, naming the units in which the deck's numbers do fit.

The test is on what every solid has: a density between :data:`DENSITY` kg/m^3 (foams to
osmium) and a dilatational wave speed ``sqrt(E (1 - nu) / (rho (1 + nu) (1 - 2 nu)))``
between :data:`WAVE_SPEED` m/s (soft foams and rubbers to beryllium). The speed tests
the length and time units, the density the mass and length units. When a material
fails it, the unit systems in common use are tried on the deck's own numbers; those in
which every material passes are named, those that also give a body between 0.1 mm and
1 km first, then those nearest a metal's density and wave speed.
"""

from __future__ import annotations

import math

import numpy as np

from rwall_fem.radioss.model import Deck
from rwall_fem.radioss.units import UnitSystem

__all__ = ["COMMON_UNITS", "DENSITY", "WAVE_SPEED", "unit_warning"]

DENSITY = (1.0, 3.0e4)  # kg/m^3
WAVE_SPEED = (10.0, 2.0e4)  # m/s
SIZE = (1e-4, 1e3)  # m: the body's largest extent
# (mass, length, time) in SI and names of the unit systems in common use.
COMMON_UNITS = {
    "kg-m-s": (1.0, 1.0, 1.0),
    "kg-mm-ms": (1.0, 1e-3, 1e-3),
    "Mg-mm-s": (1e3, 1e-3, 1.0),
    "g-mm-ms": (1e-3, 1e-3, 1e-3),
    "kg-mm-s": (1.0, 1e-3, 1.0),
    "g-cm-s": (1e-3, 1e-2, 1.0),
    "g-cm-mus": (1e-3, 1e-2, 1e-6),
    "kg-cm-ms": (1.0, 1e-2, 1e-3),
}


def _speed(young: float, nu: float, rho: float) -> float:
    return math.sqrt(young * (1 - nu) / (rho * (1 + nu) * (1 - 2 * nu)))


def _distance(materials: list[dict], units: UnitSystem) -> float:
    """How far from a metal's the materials' densities and wave speeds are (decades)."""
    out = 0.0
    for m in materials:
        rho = m["raw_density"] * units.factor("density")
        c = _speed(m["raw_young"] * units.factor("stress"), m["poisson"], rho)
        out += abs(math.log10(rho / 5000.0)) + abs(math.log10(c / 5000.0))
    return out


def _fits(materials: list[dict], units: UnitSystem) -> bool:
    for m in materials:
        rho = m["raw_density"] * units.factor("density")
        c = _speed(m["raw_young"] * units.factor("stress"), m["poisson"], rho)
        if not (DENSITY[0] <= rho <= DENSITY[1] and WAVE_SPEED[0] <= c <= WAVE_SPEED[1]):
            return False
    return True


def unit_warning(deck: Deck) -> str | None:
    """One line if a material of the deck's parts is no solid in the declared input
    units, naming the units the numbers fit; None if they fit."""
    used = {deck.parts[b.part].mat for b in deck.bodies if b.part in deck.parts}
    materials = [deck.materials[m] for m in sorted(used) if m in deck.materials]
    materials = [m for m in materials if m.get("raw_density", 0) > 0 and m.get("raw_young", 0) > 0
                 and -1 < m["poisson"] < 0.5]  # fmt: skip
    declared = deck.input_units
    if not materials or _fits(materials, declared):
        return None
    bad = next(m for m in materials if not _fits([m], declared))
    rho = bad["density"]
    c = _speed(bad["young"], bad["poisson"], rho)
    extent = float(np.ptp(deck.coordinates, axis=0).max()) / declared.length if len(
        deck.coordinates) else 0.0  # fmt: skip
    fitting = []
    for name, sizes in COMMON_UNITS.items():
        units = UnitSystem(*sizes)
        if _fits(materials, units):
            size_ok = SIZE[0] <= extent * units.length <= SIZE[1]
            fitting.append((not size_ok, _distance(materials, units), name))
    names = [name for _, _, name in sorted(fitting)]
    likely = (f"its numbers fit {' or '.join(names[:2])}" if names else
              "no unit system in common use fits its numbers")  # fmt: skip
    return (
        f"{deck.begin_where}: /BEGIN: the input units {declared.describe()} do not fit the "
        f"deck: {bad['where']} /MAT/{bad['law']} has a density of {rho:.3g} kg/m^3 and a wave "
        f"speed of {c:.3g} m/s in them, no solid's; {likely}"
    )
