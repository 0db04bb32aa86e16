"""``energy.csv``, ``walls.csv`` and ``summary.json`` in the units of ``output.units``
(SI by default; a Radioss deck's work units with ``output.units = "deck"``, so that its
figures compare line by line with a Radioss listing).

What each column and key is comes from its name: a column of ``energy.csv`` is an energy
(J) unless it is ``time`` or ``dt`` (s), ``added_mass`` (kg), a count or a fraction
(``balance_error``, ``*_percent``, ``eroded_cells``); the columns of ``walls.csv`` are
forces, impulses, positions and velocities; the keys of ``summary.json`` are listed in
:data:`SUMMARY_KEYS` (every key under an ``energy`` table is an energy). Counts,
fractions, strains and the wall-clock ``wall_seconds`` stay as they are. The values in
memory (``History.summary``) stay in SI; only the files are converted, and
``summary.json`` says in which units (``units``).
"""

from __future__ import annotations

from collections.abc import Sequence

from rwall_fem.units import UnitSystem

__all__ = ["SUMMARY_KEYS", "column_scales", "summary_in"]

# The quantity of each key of summary.json that is not a count or a fraction.
SUMMARY_KEYS = {
    **dict.fromkeys(("time", "end_time", "dt", "dt_stable", "dt_element_estimate", "first",
                     "smallest", "largest", "first_contact", "last_contact"), "time"),
    **dict.fromkeys(("mass", "added_mass"), "mass"),
    **dict.fromkeys(("initial_momentum", "final_momentum", "momentum", "impulse",
                     "normal_impulse", "tangential_impulse", "reaction_impulse"), "impulse"),
    **dict.fromkeys(("plastic_work", "work", "normal_work", "friction_work", "driving_work",
                     "mass_scaling_work", "damping_work"), "energy"),
    **dict.fromkeys(("deformed_bounds", "position", "deepest_penetration"), "length"),
    "velocity": "velocity",
    "center": "length",
    "inertia": "inertia",
    "angular_velocity": "rate",
    "angular_momentum": "angular_momentum",
}  # fmt: skip
_UNITLESS_ENERGY = ("balance_error", "max_balance_error", "energy_error_percent", "eroded_cells")


def _energy_column(name: str) -> str | None:
    if name in ("time", "dt"):
        return "time"
    if name == "added_mass":
        return "mass"
    if name in _UNITLESS_ENERGY or name.endswith("_percent"):
        return None
    return "energy"


def _wall_column(name: str) -> str | None:
    head = name.rsplit("_", 1)[0] if name[-2:] in ("_x", "_y", "_z") else name
    return {"time": "time", "force": "force", "normal_force": "force",
            "tangential_force": "force", "impulse": "impulse", "normal_impulse": "impulse",
            "tangential_impulse": "impulse", "position": "length",
            "velocity": "velocity", "contact_energy": "energy",
            "contact_friction": "energy"}.get(head)  # fmt: skip


def column_scales(columns: Sequence[str], table: str, units: UnitSystem) -> list[float] | None:
    """What each column of ``table`` ("energy" or "walls") is multiplied by to be in
    ``units`` (1 for counts and fractions); None in SI."""
    if units.is_si:
        return None
    quantity = _energy_column if table == "energy" else _wall_column
    out = []
    for name in columns:
        q = quantity(name)
        out.append(1.0 if q is None else 1.0 / units.factor(q))
    return out


def summary_in(summary: dict, units: UnitSystem) -> dict:
    """``summary`` (SI) with its keys of a unit in ``units``, and ``units`` saying which."""
    if units.is_si:
        return summary
    converted = _convert(summary, None, units)
    converted["units"] = {"mass": units.names[0], "length": units.names[1],
                          "time": units.names[2],
                          "in_SI": [units.mass, units.length, units.time]}  # fmt: skip
    return converted


def _convert(value, quantity: str | None, units: UnitSystem, key: str = ""):
    if isinstance(value, dict):
        out = {}
        for k, v in value.items():
            q = SUMMARY_KEYS.get(k, quantity if k not in _UNITLESS_ENERGY else None)
            if key == "energy" and k not in _UNITLESS_ENERGY:
                q = "energy"
            if k == "smallest_at":
                q = None
            out[k] = _convert(v, q, units, k)
        return out
    if isinstance(value, (list, tuple)):
        return [_convert(v, quantity, units, key) for v in value]
    if quantity is not None and isinstance(value, float):
        return value / units.factor(quantity)
    return value
