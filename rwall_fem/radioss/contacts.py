"""A deck's /INTER/TYPE7 interfaces as the scene's ``[[contact]]`` tables.

A scene's contact names parts: the main surface (/SURF) becomes the parts that hold its
segments, the secondary nodes (/GRNOD) the parts that hold them; a surface or group that
is only some of its parts' faces or nodes takes them whole, with a warning. Parts on both
sides are in contact with themselves (``self = true``: Radioss's single-surface use of
TYPE7, a surface and the nodes of the same parts); the secondary parts that are not main
parts meet the main ones one way (``symmetric = false``: TYPE7's nodes against segments).

The gap: Igap 0 (1000) is constant, GAPmin or Radioss's default for it, the mean
thickness of the main shells capped at half the shortest side of the main segments (0.1
x that side without shells); Igap 1 (2, 3) leaves ``gap`` out: the scene's variable gap,
half the sum of the thicknesses, at most 0.4 x the sum of the node's and the segment's
shortest sides (Igap 3 with its default %mesh_size; :mod:`rwall_fem.contact`), with Igap 2 and 3
Fscalegap ``gap_scale`` and Gap_max ``gap_max``, with Igap 3 %mesh_size
``gap_size_share`` (on shells: a solid's face adds no thickness, and a warning line says
they are left out). Stfac is ``stiffness_scale``, with Istf 2 to 5 Stmin and Stmax
``stiffness_min`` and ``stiffness_max``, Fric ``friction`` (Ifiltr, Xfreq its filter),
VIS_S ``damping``, Irem_gap 2 ``exclude_within_gap``.
"""

from __future__ import annotations

import numpy as np

from rwall_fem.radioss.groups import node_ids, surface
from rwall_fem.radioss.model import Deck
from rwall_fem.radioss.parts import DeckPart
from rwall_fem.radioss.reader import DeckError

__all__ = ["contact_tables"]

_FILTER = {1: "coefficient", 2: "steps", 3: "frequency"}


def contact_tables(deck: Deck, parts: list[DeckPart], named: bool,
                   facts: list[str]) -> list[dict]:  # fmt: skip
    """The [[contact]] tables of the deck's interfaces; ``named``: the scene has [[part]]
    tables (else its one body is every part); a line each in ``facts``."""
    tables = []
    for inter in deck.interfaces:
        where = f"{inter.where}: /INTER/TYPE7/{inter.id}"
        if inter.node_group == 0:
            raise DeckError(f"{where}: grnd_IDs = 0: give the secondary nodes (a /GRNOD)")
        segments = surface(deck, inter.surface, f"{where}: surf_IDm")
        if not len(segments):
            raise DeckError(f"{where}: surf_IDm {inter.surface} has no segment")
        nodes = node_ids(deck, inter.node_group, f"{where}: grnd_IDs")
        main = _parts_of_segments(deck, parts, segments, where, inter.surface)
        secondary = [p for p in parts if np.isin(nodes, p.nodes).any()]
        if not secondary:
            raise DeckError(f"{where}: grnd_IDs {inter.node_group} holds no node of an element")
        taken = np.concatenate([p.nodes for p in secondary])
        if not np.isin(taken, nodes).all():
            deck.warnings.append(f"{where}: grnd_IDs {inter.node_group}: takes every node "
                                 f"of {_names(secondary)} (a scene's contact names "
                                 "parts)")  # fmt: skip
        common = [p for p in main if p in secondary]
        others = [p for p in secondary if p not in main]
        common_table = _common(deck, inter, main, where)
        if common:
            table = {"self": True, **common_table}
            if named:
                table["main"] = [p.name for p in common]
            tables.append(table)
            facts.append(f"/INTER/TYPE7/{inter.id} -> self-contact of {_names(common)}"
                         + _describe(table))  # fmt: skip
        if others:
            if not named:  # pragma: no cover - one body holds every part
                raise DeckError(f"{where}: secondary nodes outside the main parts in a body "
                                "of one part")  # fmt: skip
            table = {"main": [p.name for p in main], "secondary": [p.name for p in others],
                     "symmetric": False, **common_table}  # fmt: skip
            tables.append(table)
            facts.append(f"/INTER/TYPE7/{inter.id} -> {_names(others)} on {_names(main)}"
                         + _describe(table))  # fmt: skip
    return tables


def _common(deck: Deck, inter, main: list[DeckPart], where: str) -> dict:
    table: dict = {"stiffness_scale": inter.stiffness_scale, "damping": inter.damping}
    if inter.friction:
        table["friction"] = inter.friction
        if inter.filter_flag:
            table["friction_filter"] = {_FILTER[inter.filter_flag]: inter.filter_factor}
    if inter.stiffness_min:
        table["stiffness_min"] = inter.stiffness_min
    if inter.stiffness_max:
        table["stiffness_max"] = inter.stiffness_max
    if inter.exclude_within_gap:
        table["exclude_within_gap"] = True
    if inter.igap == 0:
        table["gap"] = inter.gap_min or _default_gap(deck, main)
        return table
    if inter.gap_min:
        deck.warnings.append(f"{where}: GAPmin = {inter.gap_min:g} m: not honoured with a "
                             "variable gap (Igap 1): its floor is Radioss's default")  # fmt: skip
    shaping = {"gap_scale": ("Fscalegap", inter.gap_scale, 1.0),
               "gap_max": ("Gap_max", inter.gap_max, 0.0),
               "gap_size_share": ("%mesh_size", inter.size_share, 0.4)}  # fmt: skip
    given = {key: value for key, (_, value, default) in shaping.items() if value != default}
    if given and not any(_is_shell(deck, p) for p in main):
        # A solid's face adds no thickness: its variable gap is the floor alone
        deck.warnings.append(f"{where}: {', '.join(shaping[k][0] for k in given)}: left out: "
                             "they shape the gap of shells, and the segments are solids' "
                             "faces")  # fmt: skip
        return table
    return table | given


def _default_gap(deck: Deck, main: list[DeckPart]) -> float:
    """Radioss's constant gap without GAPmin (m): the mean thickness of the main shells,
    at most half the shortest side of the main segments; 0.1 x that side without shells."""
    side = min(_shortest_side(deck, p.cells) for p in main)
    shells = [(deck.properties[p.part.prop]["element"]["thickness"], len(p.cells))
              for p in main if p.cells.shape[1] in (3, 4) and _is_shell(deck, p)]  # fmt: skip
    if not shells:
        return 0.1 * side
    mean = sum(t * n for t, n in shells) / sum(n for _, n in shells)
    return min(mean, 0.5 * side)


def _is_shell(deck: Deck, part: DeckPart) -> bool:
    return deck.properties.get(part.part.prop, {}).get("kind") == "shell"


def _shortest_side(deck: Deck, cells: np.ndarray) -> float:
    """The shortest edge (m) between consecutive nodes of the cells (a hexahedron's in
    Radioss's order: its faces' sides)."""
    x = deck.coordinates[deck.node_positions(cells.ravel())].reshape(*cells.shape, 3)
    n = cells.shape[1]
    pairs = ([(k, (k + 1) % n) for k in range(n)] if n in (3, 4) else
             [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4), (0, 4), (1, 5),
              (2, 6), (3, 7)])  # fmt: skip
    lengths = [np.linalg.norm(x[:, b] - x[:, a], axis=1) for a, b in pairs]
    lengths = np.concatenate(lengths)
    return float(lengths[lengths > 0].min())


def _parts_of_segments(deck: Deck, parts: list[DeckPart], segments: np.ndarray, where: str,
                       sid: int) -> list[DeckPart]:  # fmt: skip
    """The parts whose nodes hold whole segments (a warning when they are only some of
    those parts' faces); a segment of no part is refused."""
    held = np.zeros(len(segments), dtype=bool)
    out = []
    for p in parts:
        inside = np.isin(segments, p.nodes).all(axis=1)
        if inside.any():
            out.append(p)
            held |= inside
    if not held.all():
        bad = segments[np.flatnonzero(~held)[0]]
        raise DeckError(f"{where}: surf_IDm {sid}: segment {' '.join(map(str, bad))} is no "
                        "face of an element of one part")  # fmt: skip
    faces = sum(len(p.cells) for p in out if _is_shell(deck, p))
    if faces and len(segments) < faces and all(_is_shell(deck, p) for p in out):
        deck.warnings.append(f"{where}: surf_IDm {sid}: {len(segments)} segments: takes "
                             f"every shell of {_names(out)} ({faces}; a scene's contact "
                             "names parts)")  # fmt: skip
    return out


def _names(parts: list[DeckPart]) -> str:
    return ("part " if len(parts) == 1 else "parts ") + ", ".join(p.name for p in parts)


def _describe(table: dict) -> str:
    gap = f"gap {table['gap']:g} m" if "gap" in table else "variable gap"
    if "gap_max" in table:
        gap += f" at most {table['gap_max']:g} m"
    return (f": {gap}, stiffness scale {table['stiffness_scale']:g}, damping "
            f"{table['damping']:g}, friction {table.get('friction', 0.0):g}")
