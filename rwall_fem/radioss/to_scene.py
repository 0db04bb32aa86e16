"""A deck read whole becomes the raw table of a scene, the same keys a TOML file holds,
and its mesh a gmsh file: from here on everything is shared with TOML scenes.

Parts that share /MAT and /PROP and start at one velocity are one body, the scene's
``[material]``, ``[element]`` and ``[initial]``; otherwise every /PART is a ``[[part]]``
(:mod:`~rwall_fem.radioss.parts`), a region of the mesh of its name, and what all the
parts share is still the scene's table, what differs each part's own.
"""

from __future__ import annotations

import hashlib
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from rwall_fem.radioss.cards.rigid_bodies import scene_tables as rigid_body_tables
from rwall_fem.radioss.contacts import contact_tables
from rwall_fem.radioss.groups import node_ids, part_ids
from rwall_fem.radioss.loads import load_groups, load_tables
from rwall_fem.radioss.materials import element_table, material_table
from rwall_fem.cell_shapes import bad_cells
from rwall_fem.radioss.mesh import WRITER, FaceGroups, face_groups, write_msh
from rwall_fem.radioss.model import Deck, Prescribed, Wall
from rwall_fem.radioss.parts import DeckPart, deck_parts, initial_velocities, uniform_velocity
from rwall_fem.radioss.plausible import unit_warning
from rwall_fem.radioss.reader import DeckError
from rwall_fem.radioss.void import drop_void_elements

__all__ = ["SceneParts", "scene_of"]

_SLIDE = {0: "free", 1: "tied", 2: "friction"}
_FILTER = {1: "coefficient", 2: "steps", 3: "frequency"}
_SHAPE = {"PLANE": "plane", "CYL": "cylinder", "SPHER": "sphere", "PARAL": "parallelogram"}


@dataclass
class SceneParts:
    """The raw scene table, the mesh to write (cell type, regions: name -> cells, face
    groups), and lines saying what the deck became (for ``rwall-fem check``)."""

    raw: dict
    cell: str
    regions: dict[str, np.ndarray]
    groups: FaceGroups
    facts: list[str]

    def mesh_key(self, deck: Deck) -> str:
        """A digest of everything the mesh file holds (its name in the cache)."""
        digest = hashlib.sha256(WRITER.encode())
        for array in (deck.node_ids, deck.coordinates):
            digest.update(np.ascontiguousarray(array).tobytes())
        for dim, named in ((3, self.regions), (2, self.groups.atoms)):
            for name, cells in named.items():
                digest.update(f"{dim} {name}".encode() + np.ascontiguousarray(cells).tobytes())
        return digest.hexdigest()[:24]

    def write_mesh(self, deck: Deck, path: Path) -> None:
        write_msh(path, deck.node_ids, deck.coordinates, self.cell, self.regions, self.groups)


def scene_of(deck: Deck) -> SceneParts:
    """The scene the deck describes (mesh file key left for the caller to fill)."""
    voids = drop_void_elements(deck)
    _check_references(deck)
    slip = unit_warning(deck)
    if slip is not None:
        deck.warnings.append(slip)
    cells_by_kind = {b.cell for b in deck.bodies}
    if len(cells_by_kind) > 1:
        surfaces = cells_by_kind & {"quadrilateral", "triangle"}
        why = ("a scene mixes no shells and solids in one mesh"
               if surfaces and surfaces != cells_by_kind else "DOLFINx holds one cell type per mesh")  # fmt: skip
        raise DeckError(
            f"{deck.starter}: elements of {' and '.join(sorted(cells_by_kind))} cells: {why}"
        )
    cell = cells_by_kind.pop()
    cells = np.concatenate([b.nodes for b in deck.bodies])
    parts = deck_parts(deck)
    used = {p.part.id for p in parts}
    for part in deck.parts.values():
        void = deck.materials.get(part.mat, {}).get("law") == "LAW0"  # left out, said so
        if part.id not in used and not void:
            deck.warnings.append(f"{part.where}: /PART/{part.id}: has no elements")
    body_nodes = np.unique(cells)
    mains = {w.main_node for w in deck.walls if w.main_node}
    initial_velocities(deck, parts, mains)
    separate = len({(p.part.mat, p.part.prop) for p in parts}) > 1 or not uniform_velocity(parts)
    separate = separate or (bool(deck.interfaces) and len(parts) > 1)  # contacts name parts

    facts = [
        f"units: input {deck.input_units.describe()}, work {deck.work_units.describe()} "
        "(converted to SI)",
        *voids,
    ]
    if separate:
        body = _parts(deck, parts, cell, facts)
        regions = {p.name: p.cells for p in parts}
    else:
        body = _one_body(deck, parts, cell, cells, facts)
        regions = {"body": cells}
    raw: dict = {
        "run": {"end_time": deck.end_time},
        "mesh": {},
        **body,
        "output": {"directory": f"results/{_slug(deck.run_name)}", "history_interval": 1},
    }
    if deck.dt_scale is not None:
        raw["run"]["dt_scale"] = deck.dt_scale
    if deck.dt_min is not None:
        raw["run"]["dt_min"] = deck.dt_min
        if deck.dt_min_action not in (None, "stop"):
            raw["run"]["dt_min_action"] = deck.dt_min_action
    if deck.noise is not None:
        raw["mesh"]["noise"] = {"amplitude": deck.noise[0], "seed": deck.noise[1]}
    if deck.animation is not None:
        start, interval = deck.animation
        raw["output"]["frames"] = int(np.floor((deck.end_time - start) / interval + 1e-9)) + 1
        if start > 0:
            deck.warnings.append(
                f"/ANIM/DT: Tstart = {start:g} s: the {raw['output']['frames']} frames are "
                "spread over the whole run"
            )
    if deck.history_interval is not None:
        del raw["output"]["history_interval"]
        raw["output"]["history_time"] = deck.history_interval
        facts.append(
            f"/TFILE {deck.history_interval:g} s: output.history_time, a row of energy.csv, "
            "walls.csv (and contacts.csv) at the first step at or after each multiple"
        )

    by_parts = _groups_as_parts(deck, parts) if separate else {}
    group_nodes = {gid: deck.groups[gid].nodes for gid in _used_groups(deck, by_parts)}
    group_nodes |= load_groups(deck, cell, cells, body_nodes)  # and surfaces' nodes
    atoms, unreached = face_groups(cell, cells, {
        gid: np.intersect1d(nodes, body_nodes) for gid, nodes in group_nodes.items()
    })  # fmt: skip
    for gid, missing in unreached.items():
        if len(missing):
            g = deck.groups[gid]
            shown = ", ".join(map(str, missing[:5])) + (", ..." if len(missing) > 5 else "")
            raise DeckError(
                f"{g.where}: {g.name}: nodes {shown} lie on no element face whose nodes are all "
                "in the group: rwall_fem's node sets are unions of element faces"
            )
    gravity = _gravity(deck, body_nodes)
    if gravity is not None:
        raw["gravity"] = {"acceleration": list(gravity)}
        facts.append(f"gravity: {_vec(gravity)} m/s^2")
    boundaries, wall_velocity, wall_held = _boundaries(deck, atoms, mains)
    _held_rotations(deck, boundaries, cell)
    if boundaries:
        raw["boundary"] = boundaries
        facts += [f"boundary on {b['group']}: components {b.get('components', 'xyz')}"
                  + (f", rotations {b['rotations']}" if "rotations" in b else "")
                  for b in boundaries]  # fmt: skip
    tables, lines = load_tables(deck, cell, cells, atoms, body_nodes)
    raw |= tables
    facts += lines
    walls = [_wall(deck, w, atoms, by_parts, wall_velocity.get(w.main_node),
                   wall_held.get(w.main_node, "")) for w in deck.walls]  # fmt: skip
    if walls:
        raw["wall"] = walls
        for w, table in zip(deck.walls, walls, strict=True):
            facts.append(_wall_fact(w, table))
    if deck.interfaces:
        raw["contact"] = contact_tables(deck, parts, separate, facts)
    if deck.rigid_bodies:
        raw["rigid_body"] = rigid_body_tables(deck, atoms, by_parts, body_nodes, facts)
    facts.append(
        f"run: end time {deck.end_time:g} s"
        + (f", dt scale {deck.dt_scale:g}" if deck.dt_scale is not None else "")
        + (f", below {deck.dt_min:g} s: {deck.dt_min_action}" if deck.dt_min else "")
        + (f", {raw['output']['frames']} frames" if "frames" in raw["output"] else "")
    )
    return SceneParts(raw, cell, regions, atoms, facts)


def _check_references(deck: Deck) -> None:
    """Every element's /PART, and that part's /MAT and /PROP, and its nodes exist; there
    are elements."""
    used = {b.part for b in deck.bodies}
    for part in deck.parts.values():
        if part.id not in used:  # a part of elements that are not read (springs) may have none
            continue
        if part.mat == 0:
            raise DeckError(f"{part.where}: /PART/{part.id}: part {part.id} has no material "
                            "(mat_ID is 0 or blank)")  # fmt: skip
        if part.prop == 0:
            raise DeckError(f"{part.where}: /PART/{part.id}: part {part.id} has no property "
                            "(prop_ID is 0 or blank)")  # fmt: skip
        if part.mat not in deck.materials:
            raise DeckError(f"{part.where}: /PART/{part.id}: mat_ID {part.mat} refers to no /MAT")
        if part.prop not in deck.properties:
            raise DeckError(
                f"{part.where}: /PART/{part.id}: prop_ID {part.prop} refers to no /PROP"
            )
    if not deck.bodies:
        raise DeckError(f"{deck.starter}: no elements (/BRICK, /TETRA4, /SHELL or /SH3N)")
    for body in deck.bodies:
        if body.part not in deck.parts:
            body.card.fail(f"part_ID {body.part} refers to no /PART")
    _check_element_nodes(deck)


def _one_body(deck: Deck, parts: list[DeckPart], cell: str, cells, facts: list[str]) -> dict:
    """The tables of a body whose parts share /MAT, /PROP and their initial velocity:
    [material], [element] and [initial]."""
    facts.append(
        f"body: parts {', '.join(str(p.part.id) for p in parts)}: {len(cells)} {cell} cells, "
        f"{len(np.unique(cells))} nodes"
    )
    material, material_fact = material_table(deck, parts[0].part.mat)
    element, element_fact = element_table(deck, parts[0].part.prop, cell, material, cells)
    facts += [material_fact, element_fact]
    tables = {"material": material}
    if element:
        tables["element"] = element
    if deck.initial:
        tables["initial"] = {"velocity": list(parts[0].start)}
        facts.append(f"initial velocity: {_vec(parts[0].start)} m/s")
    return tables


def _parts(deck: Deck, parts: list[DeckPart], cell: str, facts: list[str]) -> dict:
    """The tables of a body of parts: one [[part]] per /PART, each the region of its name;
    the material, element and initial velocity that every part has are the scene's
    [material], [element] and [initial], the others each part's own."""
    nodes = np.unique(np.concatenate([p.nodes for p in parts]))
    facts.append(
        f"body: {sum(len(p.cells) for p in parts)} {cell} cells, {len(nodes)} nodes, in "
        f"{len(parts)} parts ([[part]], each the region of its name in the mesh)"
    )
    materials: dict[int, dict] = {}
    elements: dict[tuple[int, int], dict] = {}
    for mid in dict.fromkeys(p.part.mat for p in parts):
        materials[mid], fact = material_table(deck, mid)
        facts.append(f"{fact} ({_names([p for p in parts if p.part.mat == mid])})")
    for key in dict.fromkeys((p.part.prop, p.part.mat) for p in parts):
        mine = [p for p in parts if (p.part.prop, p.part.mat) == key]
        cells = np.concatenate([p.cells for p in mine])
        elements[key], fact = element_table(deck, key[0], cell, materials[key[1]], cells)
        facts.append(f"{fact} ({_names(mine)})")
    material = [materials[p.part.mat] for p in parts]
    element = [elements[(p.part.prop, p.part.mat)] for p in parts]
    velocity = [p.start for p in parts]
    tables: dict = {}
    shared_material = all(m == material[0] for m in material)
    shared_element = all(e == element[0] for e in element)
    shared_velocity = uniform_velocity(parts)
    if shared_material:
        tables["material"] = material[0]
    if shared_element and element[0]:
        tables["element"] = element[0]
    if shared_velocity and deck.initial:
        tables["initial"] = {"velocity": list(velocity[0])}
    tables["part"] = []
    for k, p in enumerate(parts):
        table: dict = {"name": p.name}
        if not shared_material:
            table["material"] = material[k]
        if not shared_element and element[k]:
            table["element"] = element[k]
        if not shared_velocity and p.velocity is not None:
            table["initial"] = {"velocity": list(p.velocity)}
        tables["part"].append(table)
        facts.append(
            f"part {p.name}: /PART/{p.part.id} ({p.part.where}): {len(p.cells)} cells, "
            f"{len(p.nodes)} nodes, /MAT {p.part.mat}, /PROP {p.part.prop}, initial velocity "
            f"{_vec(p.start)} m/s" + (f" ({p.given})" if p.given else "")
        )
    return tables


def _names(parts: list[DeckPart]) -> str:
    return ("part " if len(parts) == 1 else "parts ") + ", ".join(p.name for p in parts)


def _groups_as_parts(deck: Deck, parts: list[DeckPart]) -> dict[int, list[str]]:
    """The /GRNOD/PART (SUBSET, MAT, PROP) groups that walls take as their grnd_ID1 and
    rigid bodies as theirs, as the names of their parts (``secondary.parts``, a rigid
    body's ``parts``: every node of those parts' elements, as the group's)."""
    names = {p.part.id: p.name for p in parts}
    out = {}
    for gid in [w.add_group for w in deck.walls] + [r.group for r in deck.rigid_bodies]:
        g = deck.groups.get(gid)
        if g is not None and g.kind in ("PART", "SUBSET", "MAT", "PROP"):
            user = f"{g.where}: {g.name}: {g.kind.lower()}"
            chosen = part_ids(deck, g.kind, g.items, user).tolist()
            out[gid] = [names[pid] for pid in chosen if pid in names]
    return out


def _slug(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", name).strip("_") or "deck"


def _vec(v) -> str:
    return "[" + ", ".join(f"{c:g}" for c in v) + "]"


def _check_element_nodes(deck: Deck) -> None:
    """Every node of an element is a /NODE, and no element is flat or inside out
    (:mod:`rwall_fem.cell_shapes`: Radioss's order of nodes is gmsh's)."""
    for body in deck.bodies:
        rows = deck.node_positions(body.nodes.ravel()).reshape(body.nodes.shape)
        bad = np.argwhere(rows < 0)
        if len(bad):
            k, j = bad[0]
            body.card.fail(
                f"element {body.ids[k]}: node {body.nodes[k, j]} refers to no /NODE",
                body.card.lines[k],
            )
        if body.cell not in ("hexahedron", "tetrahedron"):
            continue  # shells: their own readers refuse degenerate ones
        flat, corner = bad_cells(deck.coordinates[rows])
        if len(flat):
            k = flat[0]
            more = f" ({len(flat)} such elements in this card)" if len(flat) > 1 else ""
            body.card.fail(
                f"element {body.ids[k]} is flat or inside out: its volume at node "
                f"{body.nodes[k, corner[0]]} is not positive (a face on the opposite one, or "
                f"nodes out of order){more}; an element needs a positive volume at every "
                "corner",
                body.card.lines[k],
            )


def _group(deck: Deck, gid: int, where: str, what: str):
    """The /GRNOD ``gid`` that the card at ``where`` names in its field ``what``, its nodes
    worked out (:mod:`~rwall_fem.radioss.groups`)."""
    node_ids(deck, gid, f"{where}: {what}")
    return deck.groups[gid]


def _used_groups(deck: Deck, by_parts: dict[int, list[str]]) -> list[int]:
    """The groups that must be written to the mesh (a wall, /BCS or /IMPVEL uses them,
    other than as the parts ``by_parts``), their nodes worked out."""
    uses = [(w.add_group, w.where, f"/RWALL/{w.kind}/{w.id}: grnd_ID1") for w in deck.walls
            if w.add_group and w.add_group not in by_parts]  # fmt: skip
    uses += [(w.exclude_group, w.where, f"/RWALL/{w.kind}/{w.id}: grnd_ID2")
             for w in deck.walls if w.exclude_group]  # fmt: skip
    uses += [(g, where, "/BCS: grnd_ID") for _, g, where in deck.clamps]
    uses += [(p.group, p.where, f"{p.card}: grnd_ID") for p in deck.velocities]
    uses += [(r.group, r.where, f"/RBODY/{r.id}: grnd_ID") for r in deck.rigid_bodies
             if r.group not in by_parts]  # fmt: skip
    for gid, where, what in uses:
        _group(deck, gid, where, what)
    return list(dict.fromkeys(gid for gid, _, _ in uses))


def _covers(group_nodes, body_nodes) -> bool:
    return bool(np.isin(body_nodes, group_nodes).all())


def _function_on_run(deck: Deck, p: Prescribed) -> tuple[np.ndarray, np.ndarray]:
    """The function of ``p`` in SI (t, value) over the run; it must cover [0, end]."""
    fct = deck.functions.get(p.fct)
    if fct is None:
        raise DeckError(f"{p.where}: {p.card}: fct_IDT {p.fct} refers to no /FUNCT")
    t, y = fct.x * p.t_scale, fct.y * p.y_scale
    span = deck.end_time
    if t[0] > 0 or t[-1] < span * (1 - 1e-12):
        raise DeckError(
            f"{fct.where}: /FUNCT/{fct.id}: covers t in [{t[0]:g}, {t[-1]:g}] s, and "
            f"{p.card} needs [0, {span:g}] s: rwall_fem holds a table constant outside its "
            "points, Radioss extrapolates; extend the function"
        )
    return t, y


def _gravity(deck: Deck, body_nodes):
    if not deck.gravity:
        return None
    g = np.zeros(3)
    for p in deck.gravity:
        group = _group(deck, p.group, p.where, "/GRAV: grnd_ID")
        if not _covers(group.nodes, body_nodes):
            raise DeckError(f"{p.where}: {p.card}: group {p.group} holds only some nodes of the "
                            "body: rwall_fem's gravity acts on every node")  # fmt: skip
        t, y = _function_on_run(deck, p)
        inside = t <= deck.end_time
        if np.ptp(y[inside | (np.arange(len(t)) == np.argmax(t > deck.end_time))]) != 0:
            raise DeckError(f"{p.where}: {p.card}: the function {p.fct} varies over the run: "
                            "rwall_fem's gravity is constant")  # fmt: skip
        g["XYZ".index(p.direction)] += y[0]
    return g


def _table(deck: Deck, items: list[Prescribed]) -> tuple[list[list[float]], str]:
    """Rows [t, vx, vy, vz] at the union of the functions' points, and the components."""
    curves = {p.direction: _function_on_run(deck, p) for p in items}
    times = np.unique(np.concatenate([t for t, _ in curves.values()]))
    rows = np.zeros((len(times), 4))
    rows[:, 0] = times
    for axis, (t, y) in curves.items():
        rows[:, 1 + "XYZ".index(axis)] = np.interp(times, t, y)
    components = "".join(sorted(a.lower() for a in curves))
    return rows.tolist(), components


def _boundaries(deck: Deck, atoms: FaceGroups, mains: set[int]):
    """The [[boundary]] tables of /BCS and of /IMPVEL on body nodes, the prescribed
    velocities of walls' main nodes (main node -> list of /IMPVEL) and the components a
    /BCS holds on walls' main nodes (main node -> "xyz" letters)."""
    out = []
    held_mains: dict[int, set[str]] = {}
    for components, gid, where in deck.clamps:
        g = _group(deck, gid, where, "/BCS: grnd_ID")
        rotations = deck.held_rotations.get(where)
        on_mains = set(g.nodes.tolist()) & mains
        for main in on_mains:  # Radioss zeroes their accelerations: motion.held
            held_mains.setdefault(main, set()).update(components)
        if on_mains and rotations:
            deck.warnings.append(f"{where}: /BCS: rotation codes on the main node of a /RWALL "
                                 "are not used (a wall translates, never rotates)")  # fmt: skip
        held = {"rotations": rotations, "where": where} if rotations else {}
        out += [{"group": a, "components": components} | held for a in atoms.of.get(gid, [])]
    on_walls: dict[int, list[Prescribed]] = {}
    by_group: dict[int, list[Prescribed]] = {}
    for p in deck.velocities:
        g = _group(deck, p.group, p.where, "/IMPVEL: grnd_ID")
        held = set(g.nodes.tolist()) & mains
        if held and len(g.nodes) > len(held):
            raise DeckError(f"{p.where}: {p.card}: group {p.group} mixes the main node of a "
                            "/RWALL with nodes of the body")  # fmt: skip
        target = on_walls.setdefault(held.pop(), []) if held else by_group.setdefault(p.group, [])
        if any(q.direction == p.direction for q in target):
            raise DeckError(f"{p.where}: {p.card}: a second imposed velocity along "
                            f"{p.direction} of the same nodes")  # fmt: skip
        target.append(p)
    for gid, items in by_group.items():
        rows, components = _table(deck, items)
        out += [{"group": a, "velocity": rows, "components": components} for a in atoms.of[gid]]
    held = {main: "".join(sorted(c)) for main, c in held_mains.items()}
    return out, on_walls, held


def _held_rotations(deck: Deck, boundaries: list[dict], cell: str) -> None:
    """Keep the rotation codes of /BCS on shells (``rotations``); on solids say once per
    card that they are not used (their nodes have none)."""
    said = set()
    for b in boundaries:
        where = b.pop("where", None)
        if where is None or cell in ("quadrilateral", "triangle"):
            continue
        del b["rotations"]
        if where not in said:
            said.add(where)
            deck.warnings.append(f"{where}: /BCS: rotation codes are not used (solid nodes "
                                 "have no rotations)")  # fmt: skip


def _wall(deck: Deck, w: Wall, atoms: FaceGroups, by_parts: dict[int, list[str]],
          imposed: list[Prescribed] | None, held: str) -> dict:  # fmt: skip
    name = f"/RWALL/{w.kind}/{w.id}"
    where = f"{w.where}: {name}"
    table: dict = {"kind": _SHAPE[w.kind]}
    point = w.point
    if w.main_node:
        row = deck.node_positions(np.array([w.main_node]))[0]
        if row < 0:
            raise DeckError(f"{where}: node_ID {w.main_node} refers to no /NODE")
        if any((b.nodes == w.main_node).any() for b in deck.bodies):
            raise DeckError(f"{where}: node_ID {w.main_node} is a node of the body; the main "
                            "node of a wall is a node of its own")  # fmt: skip
        point = deck.coordinates[row]
    table["point"] = list(point)
    if w.kind == "PLANE":
        table["normal_point"] = list(w.point1)
    elif w.kind == "CYL":
        table["axis_point"] = list(w.point1)
    elif w.kind == "PARAL":
        table |= {"corner1": list(w.point1), "corner2": list(w.point2)}
    if w.kind in ("CYL", "SPHER"):
        if w.diameter <= 0:
            raise DeckError(f"{where}: Diameter = {w.diameter:g} m: a {table['kind']} needs a "
                            "diameter > 0")  # fmt: skip
        table["diameter"] = w.diameter
    table["slide"] = _SLIDE[w.slide]
    if w.slide == 2:
        table["friction"] = w.friction
        if w.filter_flag:
            table["friction_filter"] = {_FILTER[w.filter_flag]: w.filter_factor}
    secondary: dict = {}
    if w.search_distance > 0:
        secondary["search_distance"] = w.search_distance
    for key, gid, what in (("add", w.add_group, "grnd_ID1"), ("exclude", w.exclude_group,
                                                                 "grnd_ID2")):  # fmt: skip
        if gid:
            g = _group(deck, gid, w.where, f"{name}: {what}")
            if w.main_node and w.main_node in g.nodes:
                raise DeckError(f"{where}: {what} {gid} holds the wall's own main node")
            if gid in by_parts and key == "add":
                secondary["parts"] = by_parts[gid]
            else:
                secondary[key] = atoms.of[gid]
    if not (secondary.get("add") or secondary.get("parts") or "search_distance" in secondary):
        raise DeckError(f"{where}: no secondary nodes (Dsearch is 0 and no grnd_ID1): the wall "
                        "would act on nothing; give Dsearch or grnd_ID1")  # fmt: skip
    table["secondary"] = secondary
    if w.main_node:
        if imposed:
            rows, components = _table(deck, imposed)
            both = "".join(c.upper() for c in held if c in components)
            if both:
                raise DeckError(f"{where}: its node has both a /BCS and an /IMPVEL along "
                                f"{both}: give one")  # fmt: skip
            free = [i for i, c in enumerate("xyz") if c not in components]
            # a /BCS keeps a component at VX0..VZ0, as rwall_fem does with the free ones
            _free_components_unloaded(w, [i for i in free if "xyz"[i] not in held], where)
            for i in free:
                for row in rows:
                    row[1 + i] = float(w.velocity[i])
            table["motion"] = {"velocity": rows}
        else:
            if w.mass <= 0:
                raise DeckError(f"{where}: Mass = {w.mass:g} kg: a moving wall needs a mass > 0 "
                                "(or an /IMPVEL on its node)")  # fmt: skip
            table["motion"] = {"mass": w.mass, "velocity": list(w.velocity)}
            if held:
                table["motion"]["held"] = held
    return table


def _free_components_unloaded(w: Wall, free: list[int], where: str) -> None:
    """An /IMPVEL on some components of a main node: rwall_fem prescribes the whole motion,
    so the others keep VX0..VZ0, exact only if no wall force acts along them: a
    frictionless plane whose normal has no such component."""
    if not free:
        return
    if w.kind in ("PLANE", "PARAL") and w.slide == 0:
        normal = (w.point1 - w.point) if w.kind == "PLANE" else np.cross(
            w.point1 - w.point, w.point2 - w.point)  # fmt: skip
        normal = normal / np.linalg.norm(normal)
        if np.all(np.abs(normal[free]) <= 1e-12):
            return
    axes = "".join("XYZ"[i] for i in free)
    raise DeckError(
        f"{where}: /IMPVEL on its node leaves {axes} free, where the wall's force "
        "acts: impose X, Y and Z (rwall_fem prescribes a wall's whole motion)"
    )


def _wall_fact(w: Wall, table: dict) -> str:
    motion = table.get("motion")
    how = "fixed" if motion is None else ("prescribed" if "mass" not in motion else
                                          f"main node {w.main_node}, {w.mass:g} kg")  # fmt: skip
    sec = table["secondary"]
    nodes = []
    if "search_distance" in sec:
        nodes.append(f"within {sec['search_distance']:g} m")
    if sec.get("add"):
        nodes.append(f"+ group {w.add_group}")
    if sec.get("parts"):
        nodes.append(f"+ group {w.add_group} (the parts {', '.join(sec['parts'])})")
    if sec.get("exclude"):
        nodes.append(f"- group {w.exclude_group}")
    return (
        f"wall: /RWALL/{w.kind}/{w.id} ({w.where}) -> {table['kind']}, {how}, slide "
        f"{table['slide']}, secondary nodes {' '.join(nodes)}"
    )
