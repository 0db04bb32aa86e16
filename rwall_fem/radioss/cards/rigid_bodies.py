"""/RBODY: rigid bodies of a node group and a main node (the 2017+ format), in SI, and the
scene's ``[[rigid_body]]`` tables they become (``docs/radioss.md``, "Rigid bodies").

The card's lines: the title; ``node_ID sens_ID Skew_ID Ispher Mass grnd_ID Ikrem ICoG
surf_ID``; ``Jxx Jyy Jzz``; ``Jxy Jyz Jxz``; optionally ``Ioptoff Iexpams Ifail``. The body's
nodes are the group's; its main node is where Mass and J are added: at its own position
(ICoG 1, the default), at the centre of mass of the group's nodes (ICoG 2), or as the
body's whole mass and inertia (ICoG 4). ICoG 3 keeps the main node where it is and turns
the body about it; here a body turns about its centre of mass, as ICoG 1 (one warning
line when the two differ). A sensor, a skew with inertia, Ifail (failure of the body) and
/RBODY/LAGMUL are refused; Ispher, Ikrem, surf_ID, Ioptoff and Iexpams are noticed in one
line each when set.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from rwall_fem.radioss.cards.base import card_units, catch_all, ident
from rwall_fem.radioss.model import Deck
from rwall_fem.radioss.reader import Card, DeckError

__all__ = ["STARTER", "RigidBodyCard", "scene_tables"]


@dataclass
class RigidBodyCard:
    """An /RBODY in SI: its ID, main node, added mass (kg) and inertia (kg m^2, [Jxx, Jyy,
    Jzz, Jxy, Jyz, Jxz]), node group and ICoG."""

    id: int
    title: str
    main_node: int
    mass: float
    inertia: list[float]
    group: int
    icog: int
    where: str


def _rigid_body(deck: Deck, card: Card) -> None:
    rid = ident(card, 1, "rbody_ID")
    units = card_units(deck, card, 2)
    line = card.line(1, "node_ID sens_ID Skew_ID Ispher Mass grnd_ID Ikrem ICoG surf_ID")
    node, sensor, skew, ispher, mass, group, ikrem, icog, surface = card.read(
        1, "i:node_ID i:sens_ID i:Skew_ID i:Ispher f:Mass i:grnd_ID i:Ikrem i:ICoG i:surf_ID"
    )
    jxx, jyy, jzz = card.read(2, "f:Jxx f:Jyy f:Jzz", "Jxx Jyy Jzz")
    jxy, jyz, jxz = card.read(3, "f:Jxy f:Jyz f:Jxz", "Jxy Jyz Jxz")
    ioptoff, iexpams, ifail = card.read_optional(4, "i:Ioptoff i:Iexpams i:Ifail")
    inertia = [jxx, jyy, jzz, jxy, jyz, jxz]
    if node <= 0:
        card.fail("node_ID (the main node) is missing", line)
    if group <= 0:
        card.fail("grnd_ID (the node group of the body) is missing", line)
    if sensor:
        card.fail(f"sens_ID = {sensor}: a rigid body switched by a sensor is not supported; "
                  "leave it blank (rigid from the start)", line)  # fmt: skip
    if skew and any(inertia):
        card.fail(f"Skew_ID = {skew}: an inertia in a skew frame is not supported; give Jxx.."
                  "Jxz in the global frame", line)  # fmt: skip
    if ifail:
        card.fail(f"Ifail = {ifail}: the failure of a rigid body is not supported", card.lines[4])
    if mass < 0:
        card.fail(f"Mass = {mass:g}: an added mass is >= 0", line)
    if icog not in (0, 1, 2, 3, 4):
        card.fail(f"ICoG = {icog}: 1 (default), 2, 3 or 4", line)
    if icog == 4 and mass <= 0:
        card.fail("ICoG = 4 makes Mass the body's whole mass, and it is 0: give Mass > 0", line)
    J = np.array([[jxx, jxy, jxz], [jxy, jyy, jyz], [jxz, jyz, jzz]])
    if icog == 4 and not np.linalg.eigvalsh(J)[0] > 0:
        card.fail("ICoG = 4 makes J the body's whole inertia, and it is not positive definite: "
                  "give Jxx..Jxz", card.lines[2])  # fmt: skip
    for name, value, what in (
        ("Ispher", ispher, "the inertia is the full tensor of the nodes and J"),
        ("Ikrem", ikrem, "the elements inside a rigid body are not computed here"),
        ("surf_ID", surface, "an envelope surface is for contact interfaces, not read"),
        ("Ioptoff", ioptoff, "no domain decomposition to manage"),
        ("Iexpams", iexpams, "no advanced mass scaling here"),
    ):
        if value and not (name == "Ispher" and value == 2):  # Ispher 2 is Radioss's default
            deck.notice(card, f"{name} = {value}: not honoured ({what})")
    deck.rigid_bodies.append(RigidBodyCard(
        rid, card.title(), node, mass * units.mass,
        [j * units.factor("inertia") for j in inertia], group, icog or 1, card.header.where,
    ))  # fmt: skip


@catch_all
def _other(deck: Deck, card: Card) -> None:
    card.fail("rigid bodies by Lagrange multipliers are not read; supported: /RBODY")


STARTER = {"RBODY": _rigid_body, "RBODY/LAGMUL": _other}


def scene_tables(deck: Deck, atoms, by_parts: dict[int, list[str]], body_nodes: np.ndarray,
                 facts: list[str]) -> list[dict]:  # fmt: skip
    """The ``[[rigid_body]]`` tables of the deck's /RBODY cards: the atoms of their groups
    (or the parts of a /GRNOD/PART, as ``by_parts``), the main node's position; a line of
    ``facts`` each. DeckError for a main node that is no /NODE, a node of the elements
    outside its group, or under a /BCS or /IMPVEL (a rigid body is free here)."""
    tables = []
    held = set()
    for _, gid, _ in deck.clamps:
        held |= set(deck.groups[gid].nodes.tolist())
    for p in deck.velocities:
        held |= set(deck.groups[p.group].nodes.tolist())
    owner: dict[int, RigidBodyCard] = {}
    for r in deck.rigid_bodies:
        name = f"/RBODY/{r.id}"
        group = deck.groups[r.group]
        mine = np.intersect1d(group.nodes, body_nodes)
        taken = [owner[n] for n in mine.tolist() if n in owner]
        if taken:
            other = taken[0]
            shared = sum(o is other for o in taken)
            raise DeckError(f"{r.where}: {name}: {shared} of its nodes are also in "
                            f"/RBODY/{other.id} ({other.where}): a node belongs to one rigid "
                            "body")  # fmt: skip
        owner |= dict.fromkeys(mine.tolist(), r)
        row = deck.node_positions(np.array([r.main_node]))[0]
        if row < 0:
            raise DeckError(f"{r.where}: {name}: node_ID {r.main_node} refers to no /NODE")
        if r.main_node in body_nodes and r.main_node not in group.nodes:
            raise DeckError(f"{r.where}: {name}: node_ID {r.main_node} is a node of the "
                            f"elements outside grnd_ID {r.group}: put it in the group")  # fmt: skip
        clamped = held & ({r.main_node} | set(group.nodes.tolist()))
        if clamped:
            raise DeckError(f"{r.where}: {name}: a /BCS or /IMPVEL holds its node "
                            f"{min(clamped)}: a rigid body with imposed motion is not "
                            "supported")  # fmt: skip
        point = deck.coordinates[row]
        table: dict = {}
        if r.group in by_parts:
            table["parts"] = by_parts[r.group]
        else:
            table["sets"] = atoms.of[r.group]
        if not (table.get("sets") or table.get("parts")):
            raise DeckError(f"{r.where}: {name}: grnd_ID {r.group} holds no node of the "
                            "elements")  # fmt: skip
        table["main_node"] = [float(c) for c in point]
        if r.mass:
            table["mass"] = r.mass
        if any(r.inertia):
            table["inertia"] = [float(j) for j in r.inertia]
        if r.icog == 2:
            table["center"] = "nodes"
        if r.icog == 4:
            table["node_masses"] = False
        if r.icog == 3:
            deck.warnings.append(
                f"{r.where}: {name}: ICoG = 3 turns the body about its main node; rwall_fem "
                "turns it about its centre of mass, the mass and inertia placed as ICoG 1"
            )
        tables.append(table)
        facts.append(
            f"rigid body: {name} ({r.where}) -> [[rigid_body]], {len(mine)} nodes of group "
            f"{r.group}, main node {r.main_node}, added {r.mass:g} kg, ICoG {r.icog}"
        )
    return tables
