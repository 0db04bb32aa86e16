"""A deck's /CLOAD, /PLOAD, /ADMAS and /DAMP as the scene's ``[[load]]``,
``[[added_mass]]`` and ``[damping]`` (the cards are read by
:mod:`rwall_fem.radioss.cards.loads`).

The groups they use become face groups of the mesh like every other
(:mod:`rwall_fem.radioss.mesh`): :func:`load_groups` gives their nodes, a /PLOAD's
surface as the nodes of its segments under the key ``surf<ID>``. A /PLOAD's segments
must be outer faces of the body's elements, and the outer faces whose nodes are all on
the surface must be its segments (a face group is a node set): otherwise it is refused.
Radioss pushes a positive pressure along each segment's normal N1N3 x N2N4; a scene's
pressure pushes into the body, so the sign follows the segments' side (all on one).
"""

from __future__ import annotations

import numpy as np

from rwall_fem.radioss.groups import node_ids, surface
from rwall_fem.radioss.mesh import FaceGroups
from rwall_fem.radioss.model import Deck
from rwall_fem.radioss.reader import DeckError

__all__ = ["load_groups", "load_tables"]

# The faces of a Radioss (gmsh) hexahedron and tetrahedron, by local node index.
_FACES = {
    "hexahedron": np.array(
        [[0, 3, 2, 1], [0, 1, 5, 4], [0, 4, 7, 3], [1, 2, 6, 5], [2, 3, 7, 6], [4, 5, 6, 7]]
    ),
    "tetrahedron": np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]),
}


def _surface_key(sid: int) -> str:
    return f"surf{sid}"


def _damped_groups(deck: Deck, body_nodes: np.ndarray) -> list[int]:
    """The /DAMP groups that hold only some of the body's nodes (a group of all of them
    needs no face group: the scene's damping then has no group)."""
    out = []
    for d in deck.dampings:
        nodes = node_ids(deck, d.group, f"{d.where}: {d.card}: grnd_ID")
        if not np.isin(body_nodes, nodes).all():
            out.append(d.group)
    return out


def load_groups(deck: Deck, cell: str, cells: np.ndarray, body_nodes) -> dict:
    """The node groups the loads, added masses and damping use (group ID, or
    ``surf<ID>`` for a /PLOAD's surface -> node IDs), the surfaces checked."""
    out = {}
    for c in deck.loads:
        out[c.group] = node_ids(deck, c.group, f"{c.where}: {c.card}: grnd_ID")
    for m in deck.added_masses:
        out[m.group] = node_ids(deck, m.group, f"{m.where}: {m.card}: grnd_ID")
    for gid in _damped_groups(deck, body_nodes):
        out[gid] = deck.groups[gid].nodes
    for p in deck.pressures:
        segments = _segments(deck, p, cell, cells)[0]
        out[_surface_key(p.surface)] = np.unique(segments)
    return out


def _face_keys(faces: np.ndarray, width: int) -> np.ndarray:
    """Sorted node IDs of faces, (k, width): a triangle written [n1, n2, n3, n3] has 3."""
    ordered = np.sort(faces, axis=1)
    if width == 3 and faces.shape[1] == 4:
        distinct = np.column_stack([ordered[:, :1], np.where(
            ordered[:, 1:] != ordered[:, :-1], ordered[:, 1:], -1)])  # fmt: skip
        ordered = np.sort(np.where(distinct < 0, np.iinfo(np.int64).max, distinct), axis=1)
        return ordered[:, :3]
    return ordered


def _outer_faces(cell: str, cells: np.ndarray):
    """The element faces that one element only has: their keys, and that element's row."""
    local = _FACES[cell]
    faces = cells[:, local].reshape(-1, local.shape[1])
    owner = np.repeat(np.arange(len(cells)), len(local))
    keys = _face_keys(faces, local.shape[1])
    _, inverse, counts = np.unique(keys, axis=0, return_inverse=True, return_counts=True)
    once = counts[inverse.ravel()] == 1
    return keys[once], owner[once]


def _segments(deck: Deck, p, cell: str, cells: np.ndarray):
    """The segments of the /PLOAD ``p``'s surface, each an outer face of the body, and
    whether they point out of the body (all of them) or into it (refused when mixed)."""
    user = f"{p.where}: {p.card}: surf_ID"
    segments = surface(deck, p.surface, user)
    if not len(segments):
        raise DeckError(f"{user} {p.surface}: the surface has no segment")
    width = _FACES[cell].shape[1]
    triangles = segments[:, 2] == segments[:, 3]
    if (width == 4 and triangles.any()) or (width == 3 and not triangles.all()):
        kind = "triangles" if width == 4 else "quadrilaterals"
        raise DeckError(f"{user} {p.surface}: the surface has {kind}, and the body's faces "
                        f"are {'quadrilaterals' if width == 4 else 'triangles'}")  # fmt: skip
    keys, owner = _outer_faces(cell, cells)
    mine = _face_keys(segments, width)
    _, inverse = np.unique(np.concatenate([keys, mine]), axis=0, return_inverse=True)
    inverse = inverse.ravel()
    where = np.full(inverse.max() + 1, -1)
    where[inverse[: len(keys)]] = np.arange(len(keys))
    found = where[inverse[len(keys):]]
    if (found < 0).any():
        bad = segments[np.flatnonzero(found < 0)[0]]
        raise DeckError(
            f"{user} {p.surface}: the segment {list(dict.fromkeys(bad.tolist()))} is not an "
            f"outer face of the body's elements ({int((found < 0).sum())} such segments): a "
            "pressure acts on the outside of the body"
        )
    x = deck.coordinates[deck.node_positions(segments.ravel())].reshape(-1, 4, 3)
    normal = np.cross(x[:, 2] - x[:, 0], x[:, 3] - x[:, 1])
    element = cells[owner[found]]
    centre = deck.coordinates[deck.node_positions(element.ravel())].reshape(
        *element.shape, 3).mean(axis=1)  # fmt: skip
    outward = np.einsum("ij,ij->i", normal, x.mean(axis=1) - centre) > 0
    if outward.any() and not outward.all():
        raise DeckError(
            f"{user} {p.surface}: {int(outward.sum())} segments point out of the body and "
            f"{int((~outward).sum())} into it: rwall_fem's pressure acts on faces of one "
            "side; turn the segments one way (a negative ID in the /SURF turns an item over)"
        )
    return segments, bool(outward.all())


def _rows_in(rows: np.ndarray, table: np.ndarray) -> np.ndarray:
    """Whether each row of ``rows`` is a row of ``table``."""
    _, inverse = np.unique(np.concatenate([table, rows]), axis=0, return_inverse=True)
    inverse = inverse.ravel()
    return np.isin(inverse[len(table):], inverse[: len(table)])


def _names(names: list[str]):
    return names[0] if len(names) == 1 else names


def load_tables(deck: Deck, cell: str, cells: np.ndarray, atoms: FaceGroups,
                body_nodes) -> tuple[dict, list[str]]:  # fmt: skip
    """The scene's ``load``, ``added_mass`` and ``damping`` tables of the deck, and a line
    on each for ``rwall-fem check``."""
    from rwall_fem.radioss.to_scene import _function_on_run

    raw: dict = {}
    facts = []
    loads = []
    for c in deck.loads:
        t, y = _function_on_run(deck, c)
        force = [float(c.direction == axis) for axis in "XYZ"]
        loads.append({"kind": "force", "group": _names(atoms.of[c.group]), "force": force,
                      "history": np.column_stack([t, y]).tolist()})  # fmt: skip
        facts.append(f"load: {c.card} ({c.where}): force along {c.direction} on each node of "
                     f"group {c.group}, /FUNCT {c.fct} (up to {np.abs(y).max():g} N)")
    for p in deck.pressures:
        segments, outward = _segments(deck, p, cell, cells)
        key = _surface_key(p.surface)
        _faces_are_the_segments(deck, p, atoms, key, segments, cell, cells)
        t, y = _function_on_run(deck, p)
        sign = -1.0 if outward else 1.0  # Radioss pushes along the segments' normal
        loads.append({"kind": "pressure", "group": _names(atoms.of[key]), "pressure": sign,
                      "history": np.column_stack([t, y]).tolist()})  # fmt: skip
        side = "out of" if outward else "into"
        facts.append(f"load: {p.card} ({p.where}): pressure on the {len(segments)} segments of "
                     f"/SURF {p.surface} (normals {side} the body), /FUNCT {p.fct} (up to "
                     f"{np.abs(y).max():g} Pa)")  # fmt: skip
    if loads:
        raw["load"] = loads
    masses = []
    for m in deck.added_masses:
        masses.append({"group": _names(atoms.of[m.group]), "mass": m.mass, "per": m.per})
        how = "on each node" if m.per == "node" else "spread over the nodes"
        facts.append(f"added mass: {m.card} ({m.where}): {m.mass:g} kg {how} of group {m.group}")
    if masses:
        raw["added_mass"] = masses
    if deck.dampings:
        raw["damping"], fact = _damping(deck, atoms, body_nodes)
        facts.append(fact)
    return raw, facts


def _faces_are_the_segments(deck, p, atoms, key, segments, cell, cells) -> None:
    """The outer faces whose nodes are all on the surface (the face group the mesh gets)
    are its segments; a refusal naming how many others there are."""
    width = _FACES[cell].shape[1]
    faces = np.concatenate([atoms.atoms[name] for name in atoms.of[key]])
    keys, _ = _outer_faces(cell, cells)
    derived = _face_keys(faces, width)
    outer = np.unique(derived[_rows_in(derived, keys)], axis=0)
    extra = len(outer) - len(np.unique(_face_keys(segments, width), axis=0))
    if extra > 0:
        raise DeckError(
            f"{p.where}: {p.card}: surf_ID {p.surface}: {extra} outer faces of the body have "
            "all their nodes on the surface but are not its segments: rwall_fem's face groups "
            "are node sets, so the pressure would act on them too"
        )


def _damping(deck: Deck, atoms: FaceGroups, body_nodes) -> tuple[dict, str]:
    """The one [damping] of the /DAMP cards: their coefficients agree; their groups are
    joined (none: every node)."""
    first = deck.dampings[0]
    for d in deck.dampings[1:]:
        if (d.alpha, d.beta) != (first.alpha, first.beta):
            raise DeckError(
                f"{d.where}: {d.card}: Alpha, Beta differ from those of {first.card} "
                f"({first.where}): rwall_fem's [damping] has one alpha and one beta"
            )
    table = {"alpha": first.alpha, "beta": first.beta}
    partial = _damped_groups(deck, body_nodes)
    everywhere = len(partial) < len(deck.dampings)
    if not everywhere:
        table["group"] = [name for gid in dict.fromkeys(partial) for name in atoms.of[gid]]
    on = "every node" if everywhere else "groups " + ", ".join(map(str, dict.fromkeys(partial)))
    fact = (f"damping: {', '.join(d.card for d in deck.dampings)}: alpha {first.alpha:g} 1/s, "
            f"beta {first.beta:g} s on {on}")  # fmt: skip
    return table, fact
