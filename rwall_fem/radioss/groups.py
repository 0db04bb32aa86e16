"""What the groups and surfaces of a deck select, once every card is read.

The API for the cards that use a group (walls, conditions, loads, rigid bodies,
interfaces), all in the deck's own IDs:

- :func:`node_ids`: a /GRNOD -> the sorted node IDs it holds;
- :func:`element_ids`: a /GRBRIC, /GRSHEL or /GRSH3N -> the sorted IDs of its elements;
- :func:`surface`: a /SURF -> its segments, an (k, 4) array of node IDs, each a face
  whose nodes turn counterclockwise about its normal (a triangle repeats its third
  node: ``[n1, n2, n3, n3]``); the faces of solids point out of their element;
- :func:`part_ids`: the parts a /SUBSET, a material or a property gathers.

Each takes ``user``, the text that names the card using the group (``"file:line:
/BCS: grnd_ID"``): an ID that refers to nothing is refused as ``<user> 7 refers to no
/GRNOD``. A group holding a group holding itself is refused naming the cycle. Results
are kept on the deck (``deck.resolved``): a group is worked out once.

In groups, a negative ID removes what that item holds from what the items before it
gathered (items are taken in order, as Radioss tags them: an item listed after its
removal is in again); parts, subsets, materials and properties are gathered and removed
as parts, before their nodes or elements are taken. In surfaces, a negative ID turns
that item's segments over, as in Radioss.

Kinds (the card's second keyword): a /GRNOD lists NODE (NODENS), GRNOD, PART, SUBSET,
MAT, PROP, BOX (nodes inside or on the box), SURF (nodes of the segments), GRBRIC,
GRSHEL, GRSH3N (nodes of the elements); an element group lists its own elements (BRIC,
SHEL, SH3N), groups of its family, PART, SUBSET, MAT, PROP, BOX (the elements whose nodes
are all in the box) or BOX2 (at least one); a /SURF lists SEG (its segments), SURF,
GRSHEL, GRSH3N (the shells), PART, SUBSET, MAT, PROP (their shells; with /EXT also the
outer faces of their solids, the faces no other solid of the selection shares; with
/ALL every face of their solids), BOX and BOX2 (a box's segments, likewise).
"""

from __future__ import annotations

import numpy as np

from rwall_fem.radioss.model import GROUP_CELLS, Deck, Group
from rwall_fem.radioss.reader import DeckError

__all__ = ["element_ids", "node_ids", "part_ids", "surface"]

# The faces of the hexahedron and the tetrahedron, by local node index, each turning
# counterclockwise seen from outside a positively numbered element (Radioss's and gmsh's
# numbering).
FACES = {
    "hexahedron": np.array(
        [[0, 3, 2, 1], [0, 1, 5, 4], [0, 4, 7, 3], [1, 2, 6, 5], [2, 3, 7, 6], [4, 5, 6, 7]]
    ),
    "tetrahedron": np.array([[0, 2, 1, 1], [0, 1, 3, 3], [0, 3, 2, 2], [1, 2, 3, 3]]),
}
_FAMILY = {"BRIC": "GRBRIC", "SHEL": "GRSHEL", "SH3N": "GRSH3N"}
_SHELL_FAMILIES = ("GRSHEL", "GRSH3N")


def node_ids(deck: Deck, gid: int, user: str) -> np.ndarray:
    """The sorted node IDs of the /GRNOD ``gid`` (``user`` names the card using it)."""
    group = deck.groups.get(gid)
    if group is None:
        raise DeckError(f"{user} {gid} refers to no /GRNOD")
    return _resolved(deck, group, _node_group)


def element_ids(deck: Deck, family: str, gid: int, user: str) -> np.ndarray:
    """The sorted element IDs of the element group ``gid`` of ``family`` (GRBRIC, GRSHEL,
    GRSH3N)."""
    group = deck.element_groups.get((family, gid))
    if group is None:
        raise DeckError(f"{user} {gid} refers to no /{family}")
    return _resolved(deck, group, _element_group)


def surface(deck: Deck, sid: int, user: str) -> np.ndarray:
    """The segments (k, 4) of node IDs of the /SURF ``sid``, oriented (see the module)."""
    group = deck.surfaces.get(sid)
    if group is None:
        raise DeckError(f"{user} {sid} refers to no /SURF")
    return _resolved(deck, group, _surface)


def part_ids(deck: Deck, kind: str, items: np.ndarray, user: str) -> np.ndarray:
    """The sorted IDs of the parts that ``items`` (signed IDs, in order: a negative one
    removes) of ``kind`` PART, SUBSET, MAT or PROP gather."""
    return _in_order(items, lambda item: _parts(deck, kind, np.array([item]), user))


def _in_order(items: np.ndarray, members) -> np.ndarray:
    """What the signed ``items`` gather in order: ``members(item)`` (sorted IDs) added for
    a positive item, taken away for a negative one."""
    out = np.zeros(0, np.int64)
    for item in np.asarray(items, dtype=np.int64).tolist():
        held = np.asarray(members(abs(item)), dtype=np.int64)
        out = np.union1d(out, held) if item > 0 else np.setdiff1d(out, held)
    return out


def _resolved(deck: Deck, group: Group, how) -> np.ndarray:
    key = (group.family, group.id)
    done = deck.resolved.setdefault("groups", {})
    if key in done:
        return done[key]
    stack = deck.resolved.setdefault("stack", [])
    if key in stack:
        cycle = " -> ".join(f"/{f}/{i}" for f, i in [*stack[stack.index(key) :], key])
        raise DeckError(f"{group.where}: {group.name}: holds itself through {cycle}")
    stack.append(key)
    try:
        done[key] = how(deck, group)
    finally:
        stack.pop()
    if group.family == "GRNOD":
        group.nodes = done[key]
    return done[key]


def _split(items: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The positive items and the removed ones (negative, made positive)."""
    items = np.asarray(items, dtype=np.int64)
    return items[items > 0], -items[items < 0]


def _user(group: Group) -> str:
    return f"{group.where}: {group.name}: {group.kind.split('/')[0].lower()}"


# --- elements of the deck ---------------------------------------------------------------


def _elements(deck: Deck, family: str) -> tuple[np.ndarray, np.ndarray, list]:
    """The elements of ``family``: IDs, part IDs, and the node IDs of each element card's."""
    bodies = [b for b in deck.bodies if b.cell in GROUP_CELLS[family]]
    if not bodies:
        return np.zeros(0, np.int64), np.zeros(0, np.int64), []
    ids = np.concatenate([b.ids for b in bodies])
    parts = np.concatenate([np.full(len(b.ids), b.part) for b in bodies])
    return ids, parts, [b.nodes for b in bodies]


def _element_nodes(deck: Deck, family: str, chosen: np.ndarray) -> np.ndarray:
    """The node IDs of the elements of ``family`` whose IDs are in ``chosen``."""
    out = [np.zeros(0, np.int64)]
    for body in deck.bodies:
        if body.cell in GROUP_CELLS[family]:
            out.append(body.nodes[np.isin(body.ids, chosen)].ravel())
    return np.unique(np.concatenate(out))


# --- parts ------------------------------------------------------------------------------


def _parts(deck: Deck, kind: str, items: np.ndarray, user: str) -> np.ndarray:
    if not len(items):
        return np.zeros(0, np.int64)
    if kind == "PART":
        missing = [p for p in items.tolist() if p not in deck.parts]
        if missing:
            raise DeckError(f"{user} {missing[0]} refers to no /PART")
        return np.unique(items)
    if kind == "SUBSET":
        held = set().union(*(_subset_parts(deck, s, user, []) for s in items.tolist()))
        return np.array(sorted(held), dtype=np.int64)
    table = deck.materials if kind == "MAT" else deck.properties
    missing = [i for i in items.tolist() if i not in table]
    if missing:
        raise DeckError(f"{user} {missing[0]} refers to no /{kind}")
    field = "mat" if kind == "MAT" else "prop"
    return np.array(sorted(p.id for p in deck.parts.values() if getattr(p, field) in items),
                    dtype=np.int64)  # fmt: skip


def _subset_parts(deck: Deck, sid: int, user: str, stack: list[int]) -> set[int]:
    """The parts of the /SUBSET ``sid``: those naming it, and its child subsets'."""
    if sid not in deck.subsets:
        raise DeckError(f"{user} {sid} refers to no /SUBSET")
    if sid in stack:
        cycle = " -> ".join(f"/SUBSET/{s}" for s in [*stack[stack.index(sid) :], sid])
        raise DeckError(f"{deck.subsets[sid][2]}: /SUBSET/{sid}: holds itself through {cycle}")
    out = {p.id for p in deck.parts.values() if p.subset == sid}
    for child in deck.subsets[sid][1].tolist():
        out |= _subset_parts(deck, child, f"{deck.subsets[sid][2]}: /SUBSET/{sid}: child",
                             [*stack, sid])  # fmt: skip
    return out


# --- node groups ------------------------------------------------------------------------


def _node_group(deck: Deck, group: Group) -> np.ndarray:
    kind, user = group.kind, _user(group)
    if kind in ("PART", "SUBSET", "MAT", "PROP"):
        parts = set(part_ids(deck, kind, group.items, user).tolist())
        return _union(b.nodes.ravel() for b in deck.bodies if b.part in parts)
    if kind == "NODE":
        missing = np.abs(group.items)[deck.node_positions(np.abs(group.items)) < 0]
        if len(missing):
            raise DeckError(f"{group.where}: {group.name}: node {missing[0]} refers to no /NODE")
    return _in_order(group.items, lambda item: _node_item(deck, group, item, user))


def _node_item(deck: Deck, group: Group, item: int, user: str) -> np.ndarray:
    """The node IDs that the item ``item`` (an ID > 0) of the node group holds."""
    kind = group.kind
    if kind == "NODE":
        return np.array([item])
    if kind == "GRNOD":
        return node_ids(deck, item, user)
    if kind == "BOX":
        return np.unique(deck.node_ids[_box(deck, item, user).inside(deck.coordinates)])
    if kind == "SURF":
        return np.unique(surface(deck, item, user))
    return _element_nodes(deck, kind, element_ids(deck, kind, item, user))  # GRBRIC, GRSHEL...


def _union(arrays) -> np.ndarray:
    arrays = [np.asarray(a, dtype=np.int64) for a in arrays]
    return np.unique(np.concatenate(arrays)) if arrays else np.zeros(0, np.int64)


def _box(deck: Deck, bid: int, user: str):
    box = deck.boxes.get(bid)
    if box is None:
        raise DeckError(f"{user} {bid} refers to no /BOX")
    return box


# --- element groups ---------------------------------------------------------------------


def _element_group(deck: Deck, group: Group) -> np.ndarray:
    family, kind, user = group.family, group.kind, _user(group)
    ids, parts, cards = _elements(deck, family)
    if kind in ("PART", "SUBSET", "MAT", "PROP"):
        return np.unique(ids[np.isin(parts, part_ids(deck, kind, group.items, user))])
    if kind in _FAMILY:  # the element IDs themselves
        missing = np.setdiff1d(np.abs(group.items), ids)
        if len(missing):
            raise DeckError(f"{group.where}: {group.name}: element {missing[0]} refers to no "
                            f"element of {family}'s kind")  # fmt: skip
        return _in_order(group.items, lambda item: np.array([item]))
    if kind == family:
        return _in_order(group.items, lambda item: element_ids(deck, family, item, user))

    def in_box(item: int) -> np.ndarray:  # BOX: every node inside; BOX2: one at least
        box, inside = _box(deck, item, user), []
        for nodes in cards:
            hit = box.inside(deck.coordinates[deck.node_positions(nodes.ravel())])
            hit = hit.reshape(nodes.shape)
            inside.append(hit.all(axis=1) if kind == "BOX" else hit.any(axis=1))
        return np.unique(ids[np.concatenate(inside)]) if inside else ids

    return _in_order(group.items, in_box)


# --- surfaces ---------------------------------------------------------------------------


def _surface(deck: Deck, group: Group) -> np.ndarray:
    kind, _, flavour = group.kind.partition("/")
    if kind == "SEG":
        missing = group.segments[deck.node_positions(group.segments) < 0]
        if len(missing):
            raise DeckError(f"{group.where}: {group.name}: node {missing[0]} refers to no /NODE")
        return group.segments
    keep, drop = _split(group.items)
    out = [_segment_items(deck, group, kind, flavour, keep)]
    out.append(flip(_segment_items(deck, group, kind, flavour, drop)))
    return np.concatenate(out)


def _segment_items(deck: Deck, group: Group, kind: str, flavour: str,
                   items: np.ndarray) -> np.ndarray:  # fmt: skip
    user = _user(group)
    empty = np.zeros((0, 4), np.int64)
    if not len(items):
        return empty
    if kind == "SURF":
        return np.concatenate([empty, *(surface(deck, s, user) for s in items.tolist())])
    if kind in _SHELL_FAMILIES:
        chosen = _union(element_ids(deck, kind, g, user) for g in items.tolist())
        return _shell_segments(deck, kind, lambda ids, parts: np.isin(ids, chosen))
    if kind in ("BOX", "BOX2"):
        box = _box(deck, int(items[0]), user)

        def in_box(x: np.ndarray) -> np.ndarray:
            hit = box.inside(x.reshape(-1, 3)).reshape(x.shape[:-1])
            return hit.all(axis=1) if kind == "BOX" else hit.any(axis=1)

        segments = [_box_segments(deck, f, in_box) for f in _SHELL_FAMILIES]
        if flavour:
            faces = _solid_faces(deck, lambda ids, parts: np.ones(len(ids), bool), flavour)
            faces = faces[in_box(_points(deck, faces))]
            segments.append(faces)
        return np.concatenate([empty, *segments])
    parts = _parts(deck, kind, items, user)
    chosen = lambda ids, part: np.isin(part, parts)  # noqa: E731
    segments = [_shell_segments(deck, f, chosen) for f in _SHELL_FAMILIES]
    if flavour:
        segments.append(_solid_faces(deck, chosen, flavour))
    return np.concatenate([empty, *segments])


def _points(deck: Deck, segments: np.ndarray) -> np.ndarray:
    """The positions (k, 4, 3), m, of the segments' nodes."""
    rows = deck.node_positions(segments.ravel())
    return deck.coordinates[rows].reshape(*segments.shape, 3)


def _shell_segments(deck: Deck, family: str, chosen) -> np.ndarray:
    """The segments of the shells of ``family`` that ``chosen(ids, parts)`` selects."""
    out = [np.zeros((0, 4), np.int64)]
    for body in deck.bodies:
        if body.cell in GROUP_CELLS[family]:
            nodes = body.nodes[chosen(body.ids, np.full(len(body.ids), body.part))]
            if nodes.shape[1] == 3:
                nodes = np.column_stack([nodes, nodes[:, 2]])
            out.append(nodes)
    return np.concatenate(out)


def _box_segments(deck: Deck, family: str, in_box) -> np.ndarray:
    segments = _shell_segments(deck, family, lambda ids, parts: np.ones(len(ids), bool))
    return segments[in_box(_points(deck, segments))] if len(segments) else segments


def _solid_faces(deck: Deck, chosen, flavour: str) -> np.ndarray:
    """The faces of the solids that ``chosen(ids, parts)`` selects, pointing out of their
    element: every face (``ALL``), or those no other selected solid shares (``EXT``)."""
    faces, centres = [], []
    for body in deck.bodies:
        if body.cell not in GROUP_CELLS["GRBRIC"]:
            continue
        nodes = body.nodes[chosen(body.ids, np.full(len(body.ids), body.part))]
        if not len(nodes):
            continue
        local = FACES[body.cell]
        faces.append(nodes[:, local].reshape(-1, 4))
        x = deck.coordinates[deck.node_positions(nodes.ravel())].reshape(*nodes.shape, 3)
        centres.append(np.repeat(x.mean(axis=1), len(local), axis=0))
    if not faces:
        return np.zeros((0, 4), np.int64)
    faces, centres = np.concatenate(faces), np.concatenate(centres)
    faces, centres = _proper(faces, centres)
    if flavour == "EXT":
        key = np.sort(faces, axis=1)
        key[:, 3] = np.where(key[:, 2] == key[:, 3], -1, key[:, 3])  # a triangle's key
        _, inverse, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
        once = counts[inverse.ravel()] == 1
        faces, centres = faces[once], centres[once]
    x = _points(deck, faces)
    normal = np.cross(x[:, 2] - x[:, 0], x[:, 3] - x[:, 1])  # a triangle's too (x3 = x2)
    inward = np.einsum("ij,ij->i", normal, x.mean(axis=1) - centres) < 0
    faces[inward] = flip(faces[inward])
    return faces


def _proper(faces: np.ndarray, centres: np.ndarray):
    """Faces of degenerate solids (repeated nodes) without their repeats: a face of three
    distinct nodes is a triangle ``[n1, n2, n3, n3]``, one of fewer is dropped."""
    ordered = np.sort(faces, axis=1)
    distinct = 1 + (np.diff(ordered, axis=1) != 0).sum(axis=1)
    triangle = (distinct == 3) & (faces[:, 2] == faces[:, 3])
    odd = np.flatnonzero((distinct < 4) & ~triangle)
    if not len(odd):
        return faces, centres
    repeated = faces == np.roll(faces, -1, axis=1)  # a node equal to the next one around
    out, keep = faces.copy(), np.ones(len(faces), dtype=bool)
    for k in odd:
        ring = [n for n, r in zip(faces[k], repeated[k], strict=True) if not r]
        ring = [n for i, n in enumerate(ring) if n not in ring[:i]]
        if len(ring) < 3:
            keep[k] = False
        else:
            out[k] = ring + [ring[-1]] * (4 - len(ring))
    return out[keep], centres[keep]


def flip(segments: np.ndarray) -> np.ndarray:
    """The segments turned over: ``[n1, n4, n3, n2]``, a triangle ``[n1, n3, n2, n2]``."""
    segments = np.asarray(segments, dtype=np.int64).reshape(-1, 4)
    triangle = segments[:, 2] == segments[:, 3]
    quad = segments[:, [0, 3, 2, 1]]
    tri = segments[:, [0, 2, 1, 1]]
    return np.where(triangle[:, None], tri, quad)
