"""What colours the body in the frames: the values, their colour range, unit and labels.

The body is coloured by a nodal quantity (:data:`COLORS`), by a cell field
the run stored (e.g. ``plastic_strain``), or by part (``part``: one colour per
part of a body of ``[[part]]``, labelled with their names). One range serves every frame and
fits the scene: a nodal quantity spans the 95th percentile of its magnitude
over all nodes and frames (the spikes at a wave front or under a ball
saturate, the bulk of the motion spans the range; the contact pressure: of the nodes in
contact), velocities at least the initial speed; a cell field spans its maximum (plastic
strain is often zero but in a few cells, which are the point), up to its physical bound (damage
ends at 1: :data:`BOUNDS`). The range is rounded up to a round number, in a
unit with a prefix that keeps the labels short (``µm``, ``MPa``), and its labels
fall on round values written with one format. This module needs neither DOLFINx nor
VTK; its colour maps (:data:`MAPS`) are matplotlib's, without importing it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

__all__ = ["COLORS", "Coloring", "colour_table", "coloring", "fixed_range", "rgb", "round_range"]

# Nodal colourings: the velocity along the first wall's normal at each node (m/s, signed;
# without walls, the upward velocity), the speed (m/s), the magnitude of the displacement
# (m), the contact pressure (Pa: rwall_fem.output.contact_loads; stored by a run with
# contact whose frames show it).
COLORS = ("normal_velocity", "speed", "displacement", "contact_pressure")
UNITS = {"displacement": "m", "contact_pressure": "Pa"}  # of the nodal colourings; else m/s

# Names and units of the cell fields this module knows; others are shown by their name.
CELL_FIELDS = {
    "plastic_strain": ("equivalent plastic strain", ""),
    "von_mises_stress": ("von Mises stress", "Pa"),
    "damage": ("damage D", ""),
}
# Physical bounds of the cell fields that have one: an automatic range stops there (a
# damage of 1 is failure: the values a failed cell accumulates beyond it saturate).
BOUNDS = {"damage": 1.0, "eroded": 1.0}
# The colours of the parts (matplotlib's "tab10"), in the order of the parts, cycled.
PART_COLORS = (
    "#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd",
    "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf",
)  # fmt: skip
# The colour maps, matplotlib's at 65 evenly spaced values (#rrggbb each), interpolated
# linearly: within 3 of 255 levels of matplotlib's 256 (viridis; coolwarm: 4), without
# importing matplotlib (0.1-0.7 s) in the renderer.
MAPS = {
    "viridis": "44015446075a470d6047136548186a481d6f482374482878472d7b46327e453781443b844240864045"
    "883e49893d4e8a3b528b39568c375b8d355f8d33638d31678e2f6b8e2e6f8e2c728e2a768e297a8e277e8e26828e"
    "25858e23898e228d8d21918c1f948c1f988b1e9c891fa08820a38622a78525ab8228ae802db27d32b67a38b9773f"
    "bc7346c06f4ec36b56c6675ec96267cc5c70cf577ad15184d44b8ed64598d83ea2da37addc30b8de29c2df23cde1"
    "1dd8e219e2e418ece51bf6e620fde725",
    "coolwarm": "3b4cc03f53c6445acc4961d24e68d8536edd5875e15d7ce66282ea6788ee6c8ff17295f4779af77da0"
    "f982a6fb88abfd8db0fe93b5fe98b9ff9ebeffa3c2fea9c6fdaec9fcb3cdfbb9d0f9bed2f6c3d5f4c7d7f0ccd9ed"
    "d1dae9d5dbe5d9dce1dddcdce1dad6e5d8d1e9d5cbecd3c5efcfbff1ccb8f3c8b2f5c4acf6bfa6f7ba9ff7b599f7"
    "b093f7aa8cf6a586f59f80f4987af29274f08b6eee8468eb7d62e8765ce46e56e16751dd5f4bd85646d44e41cf45"
    "3cca3b37c43032be242eb8122ab40426",
}
# Unit prefixes: (size of the unit in SI, name), largest first.
PREFIXES = {
    "m": ((1.0, "m"), (1e-3, "mm"), (1e-6, "µm")),
    "m/s": ((1.0, "m/s"), (1e-3, "mm/s")),
    "Pa": ((1e9, "GPa"), (1e6, "MPa"), (1e3, "kPa"), (1.0, "Pa")),
}
# Round tops of a range (times a power of ten) and the label intervals that give round
# label values: over [0, top], and over each half of [-top, top].
INTERVALS = {1.0: 5, 1.2: 4, 1.5: 3, 2.0: 4, 2.5: 5, 3.0: 3, 4.0: 4, 5.0: 5, 6.0: 3, 8.0: 4}
HALF_INTERVALS = {1.0: 2, 1.2: 2, 1.5: 3, 2.0: 2, 3.0: 3, 4.0: 2, 5.0: 2, 6.0: 3, 8.0: 2}


@dataclass(frozen=True)
class Coloring:
    """How the body is coloured: ``values`` per frame (in ``title``'s unit) on the points or
    (``per_cell``) the cells, the colour range ``clim`` and map ``cmap`` (a name, or the
    list of the colours of categories), and the colour bar's ``n_labels`` labels written
    with ``fmt``, or for categories their ``names``, one under each colour."""

    title: str
    per_cell: bool
    values: list[np.ndarray]
    clim: tuple[float, float]
    cmap: str | list[str]
    n_labels: int
    fmt: str
    names: tuple[str, ...] = ()


def coloring(
    color: str, frames: list[dict], points, walls, up, speed: float, parts: tuple[str, ...] = ()
) -> Coloring:
    """The colouring ``color`` (one of :data:`COLORS`, a stored cell field, or ``part``) of
    the ``frames`` (dicts with ``u``, ``v`` (m, m/s), ``offsets`` and ``cell_<name>``) of a
    body at ``points`` (m), with its ``walls`` (shapes), ``up``, initial ``speed`` (m/s)
    and the names of its ``parts`` (a body of ``[[part]]``).

    Raises ValueError (one line) for a colouring that the frames cannot give.
    """
    if color == "part" and parts and "cell_part" in frames[0]:
        count = len(parts)
        return Coloring(
            title="part",
            per_cell=True,
            values=[f["cell_part"] for f in frames],
            clim=(-0.5, count - 0.5),
            cmap=[PART_COLORS[k % len(PART_COLORS)] for k in range(count)],
            n_labels=count,
            fmt="",
            names=tuple(parts),
        )
    if color == "contact_pressure" and color not in frames[0]:
        raise ValueError(f"color {color!r}: the run stored no contact pressure (it needs "
                         "[[contact]] and output.color = 'contact_pressure')")  # fmt: skip
    if color in COLORS:
        values = [_nodal(color, f, points, walls, up) for f in frames]
        if color == "normal_velocity":
            name = "velocity along the wall normal" if walls else "upward velocity"
        else:
            name = color.replace("_", " ")
        unit = UNITS.get(color, "m/s")
    else:
        stored = sorted(k.removeprefix("cell_") for k in frames[0] if k.startswith("cell_"))
        if color not in stored:
            fields = f"its cell fields: {', '.join(stored)}" if stored else "no cell fields"
            nodal = [c for c in COLORS if c != "contact_pressure" or c in frames[0]]
            raise ValueError(
                f"color {color!r}: not a field of this body; choose one of {', '.join(nodal)} "
                f"({fields})"
            )
        values = [f[f"cell_{color}"] for f in frames]
        name, unit = CELL_FIELDS.get(color, (color.replace("_", " "), ""))
    everything = np.abs(np.concatenate(values))
    if color not in COLORS:
        top = min(float(everything.max(initial=0.0)), BOUNDS.get(color, math.inf))
    else:
        if color == "contact_pressure":  # the nodes in contact, a few of all
            everything = everything[everything > 0.0]
        top = float(np.percentile(everything, 95)) if everything.size else 0.0
        if unit == "m/s":
            top = max(top, speed)
    signed = color == "normal_velocity" or min(v.min(initial=0.0) for v in values) < 0.0
    scale, unit = _prefixed(unit, top)
    low, high, n_labels, decimals = round_range(top / scale, signed)
    return Coloring(
        title=f"{name} ({unit})" if unit else name,
        per_cell=color not in COLORS,
        values=[v / scale for v in values],
        clim=(low, high),
        cmap="coolwarm" if signed else "viridis",
        n_labels=n_labels,
        fmt=f"%.{decimals}f",
    )


def fixed_range(paint: Coloring, low: float, high: float) -> Coloring:
    """``paint`` with the colour range [``low``, ``high``] (in its colour bar's unit, low <
    high) in every frame, labelled at 5 values written with the decimals that tell them
    apart. Categories (parts) keep theirs."""
    if paint.names:
        return paint
    step = (high - low) / 4
    decimals = next((d for d in range(12) if abs(round(step, d) - step) <= 1e-9 * step), 3)
    return replace(paint, clim=(float(low), float(high)), n_labels=5, fmt=f"%.{decimals}f")


def rgb(colour: str) -> tuple[float, float, float]:
    """The red, green and blue (0-1) of ``colour`` (``#rrggbb``)."""
    return tuple(int(colour[k : k + 2], 16) / 255 for k in (1, 3, 5))


def colour_table(cmap: str | list[str], n: int) -> np.ndarray:
    """``n`` colours ((n, 3), 0-1) evenly spread over the map ``cmap`` (a name of
    :data:`MAPS`), or the colours of categories (a list of ``#rrggbb``) as they are."""
    if not isinstance(cmap, str):
        return np.array([rgb(c) for c in cmap])
    text = MAPS[cmap]
    known = np.array([rgb("#" + text[k : k + 6]) for k in range(0, len(text), 6)])
    at = np.linspace(0.0, 1.0, len(known))
    where = np.linspace(0.0, 1.0, n)
    return np.column_stack([np.interp(where, at, known[:, c]) for c in range(3)])


def round_range(top: float, signed: bool) -> tuple[float, float, int, int]:
    """The round range that holds [0, ``top``] (or [-``top``, ``top``] when ``signed``):
    ``(low, high, number of labels, decimals of the labels)``; a unit range for 0."""
    intervals = HALF_INTERVALS if signed else INTERVALS
    if not top > 0.0:
        top = 1.0
    power = 10.0 ** math.floor(math.log10(top))
    mantissa = next((m for m in intervals if m * power >= top * (1 - 1e-9)), None)
    if mantissa is None:  # above the largest round top of this power of ten
        mantissa, power = 1.0, 10 * power
    high = mantissa * power
    step = high / intervals[mantissa]
    decimals = next(d for d in range(12) if abs(round(step, d) - step) <= 1e-9 * step)
    n_labels = 2 * intervals[mantissa] + 1 if signed else intervals[mantissa] + 1
    return (-high if signed else 0.0), high, n_labels, decimals


def _prefixed(unit: str, top: float) -> tuple[float, str]:
    """The size (in SI) and name of the prefixed ``unit`` in which ``top`` is >= 1."""
    choices = PREFIXES.get(unit, ((1.0, unit),))
    return next(((s, name) for s, name in choices if top >= s), choices[-1])


def _nodal(color: str, frame: dict, points: np.ndarray, walls, up: np.ndarray) -> np.ndarray:
    """The nodal values of ``color`` in ``frame`` (SI units)."""
    if color == "normal_velocity":
        if not walls:
            return frame["v"] @ up
        normals = walls[0].normals(points + frame["u"], frame["offsets"][0])
        return np.sum(frame["v"] * normals, axis=-1)
    if color == "contact_pressure":
        return np.asarray(frame[color], dtype=float)
    field = frame["v"] if color == "speed" else frame["u"]
    return np.linalg.norm(field, axis=1)
