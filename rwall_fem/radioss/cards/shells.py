"""Shell elements and their property: /SHELL, /SH3N and /PROP/SHELL (/PROP/TYPE1), whose
blank fields take /DEF_SHELL's values (read at the end, wherever the cards are).

Ishell maps onto the shells' formulations (``docs/radioss.md``, "Shells"): Ishell 24 to
``"qeph"`` (QEPH: the warping correction with QEPH's physical hourglass stiffness per mode,
its yield and its viscosity, OpenRadioss's CZFINTN1; hm, hf, hr not read, as in Radioss)
with QEPH's step (``step_length = "qeph"``); the others to ``"bwc"``
(Belytschko-Lin-Tsay with the Belytschko-Wong-Chiang warping correction and viscous
hourglass control hm, hf, hr) with an elastic ``hourglass_stiffness``: 1, 2 and 4
(Radioss's Belytschko-Tsay, whose hourglass forces are elastic, CHVIS3) and 12 (read the
same way) hk = 3 :data:`HELAS` hm (1 - nu^2), the same stiffness on a square cell's
membrane hourglass mode; 3 (the elasto-plastic hourglass stiffness, orthogonal to the rigid modes)
:data:`HOURGLASS_STIFFNESS`; a warning says what each is read as; a
blank Ishell is 1, as in OpenRadioss's starter. Ish3n 1 and 2 (the C0 triangle) to
``"bsc"``. Iplas 0 (blank) or 2, Radioss's radial return for LAW2, is read as the exact
plane-stress return (Iplas 1), with a warning. Idrill 1 gives the quadrilaterals drilling
springs, ``drilling_stiffness`` :data:`DRILLING_STIFFNESS` (2 or blank: none). N, Thick, Ashear and hm, hf, hr become the [element] keys ``points``,
``thickness``, ``shear_factor`` and ``hourglass_coefficients`` (Radioss's defaults where
blank: N 5, Ashear 5/6, hm hf hr 0.01); P_thickfail becomes ``failed_share`` (blank: 1,
every point) and Ithick = 1 ``thickness_change = true`` (2 or blank: constant).
"""

from __future__ import annotations

import numpy as np

from rwall_fem.radioss.cards.base import card_units, ident
from rwall_fem.radioss.model import Body, Deck
from rwall_fem.radioss.reader import Card, fixed_table, read_fields

__all__ = ["DRILLING_STIFFNESS", "HELAS", "HOURGLASS_STIFFNESS", "ISHELL", "STARTER",
           "finish", "shell_element"]

# Ishell -> the scene's formulation of quadrilaterals.
ISHELL = {1: "bwc", 2: "bwc", 3: "bwc", 4: "bwc", 12: "bwc", 24: "qeph"}
_ISHELL_TEXT = "1, 2, 3, 4 (Belytschko-Tsay), 12 (read as Belytschko-Lin-Tsay with the " \
    "warping correction) and 24 (QEPH)"  # fmt: skip
# Ishell 3's elastic hourglass stiffness and Idrill 1's drilling springs (a G t A per node):
# the constants with which the twisted beam passes (docs/theory.md, "Warping").
HOURGLASS_STIFFNESS, DRILLING_STIFFNESS = 0.5, 0.01
# OpenRadioss's hourglass forces of Ishell 1, 2 and 4 (CHVIS3) are elastic, HELAS hm E t / 4
# per unit hourglass mode (HELAS = 0.5, engine/radioss2.F), with a quadratic viscosity
# beside them (no linear one: HVLIN = 0); the kernel's elastic hourglass stiffness of a
# square cell is hk E t / (12 (1 - nu^2)) on the same mode, so hk = 3 HELAS hm (1 - nu^2).
HELAS = 0.5
# The [element] keys of the quadrilaterals only, left out for triangles.
_QUADRILATERAL_KEYS = ("hourglass_stiffness", "drilling_stiffness", "step_length",
                       "hourglass_yield")  # fmt: skip


def _elements(deck: Deck, card: Card) -> None:
    part = ident(card, 1, "part_ID")
    count = 4 if card.key(0) == "SHELL" else 3
    layout = "i:elem_ID " + " ".join(f"i:node{k + 1}" for k in range(count))
    columns = fixed_table(card, 0, layout)
    ids = columns[0]
    nodes = np.column_stack(columns[1:])
    if not len(ids):
        card.fail("no elements")
    missing = np.flatnonzero((nodes <= 0).any(axis=1))
    if len(missing):
        k = missing[0]
        card.fail(f"truncated line: element {ids[k]} needs {count} node IDs, got "
                  f"{int((nodes[k] > 0).sum())}", card.lines[k])  # fmt: skip
    repeated = np.flatnonzero((np.diff(np.sort(nodes, axis=1), axis=1) == 0).any(axis=1))
    if len(repeated):
        card.fail(f"element {ids[repeated[0]]} repeats a node (a degenerate element): give "
                  "a triangle as /SH3N", card.lines[repeated[0]])  # fmt: skip
    cell = "quadrilateral" if count == 4 else "triangle"
    deck.bodies.append(Body(part, cell, ids, nodes, card))


def _property(deck: Deck, card: Card) -> None:
    pid = ident(card, 2, "prop_ID")
    if pid in deck.properties:
        card.fail(f"property {pid} is defined twice")
    units = card_units(deck, card, 3)
    first = card.line(1, "Ishell Ismstr Ish3n Idrill Ipinch P_thickfail")
    ishell, ismstr, ish3n, idrill, _, thickfail = read_fields(
        card, first, "i:Ishell i:Ismstr i:Ish3n i:Idrill i:Ipinch -:blank f:P_thickfail"
    )
    hm, hf, hr, _, dn = card.read(2, "f:hm f:hf f:hr f:dm f:dn", "hm hf hr dm dn")
    third = card.line(3, "N Istrain Thick Ashear Ithick Iplas")
    n, _, thick, ashear, ithick, iplas = read_fields(
        card, third, "i:N i:Istrain f:Thick f:Ashear -:blank i:Ithick i:Iplas"
    )
    deck.properties[pid] = {
        "unread": "shell", "card": card, "where": card.header.where, "first": first.where,
        "third": third.where,
        "given": {"ishell": ishell, "ismstr": ismstr, "ish3n": ish3n, "idrill": idrill,
                  "ithick": ithick, "iplas": iplas},
        "n": n, "thick": thick * units.length, "ashear": ashear, "hourglass": (hm, hf, hr),
        "thickfail": thickfail, "dn": dn,
    }  # fmt: skip


def finish(deck: Deck) -> None:
    """Every /PROP/SHELL with /DEF_SHELL's values in its blank fields, checked."""
    for pid, raw in deck.properties.items():
        if raw.get("unread") == "shell":
            deck.properties[pid] = _shell_property(deck, raw)


def _shell_property(deck: Deck, raw: dict) -> dict:
    """The facts of a /PROP/SHELL: its kind ("shell"), Ishell, Ish3n and the [element]
    keys; refusals of what has no counterpart name its line."""
    card: Card = raw["card"]
    first = next(li for li in card.lines if li.where == raw["first"])
    third = next(li for li in card.lines if li.where == raw["third"])
    value = {k: v or deck.shell_defaults.get(k, 0) for k, v in raw["given"].items()}
    # a blank Ishell (and /DEF_SHELL's) is 1 in OpenRadioss's starter (defaults_mod.F90,
    # init_def_elem: 24 only with /IMPLICIT, which is not read here)
    ishell = value["ishell"] or 1
    ish3n = value["ish3n"] or 2
    if ishell not in ISHELL:
        card.fail(f"Ishell = {ishell}: supported: {_ISHELL_TEXT}", first)
    if ish3n not in (1, 2):
        card.fail(f"Ish3n = {ish3n}: supported: 1 and 2 (the C0 triangle)", first)
    if value["ismstr"] not in (0, 2, 4):
        card.fail(f"Ismstr = {value['ismstr']}: small-strain formulations are not supported; "
                  "leave it blank (full geometric non-linearity)", first)  # fmt: skip
    if value["ithick"] not in (0, 1, 2):
        card.fail(f"Ithick = {value['ithick']}: 1 (the thickness follows the membrane "
                  "strain) or 2 (constant, as when blank)", third)  # fmt: skip
    if not 0.0 <= raw["thickfail"] <= 1.0:
        card.fail(f"P_thickfail = {raw['thickfail']:g}: a share of the points through the "
                  "thickness, 0 to 1 (blank: 1)", first)  # fmt: skip
    if raw["thick"] <= 0.0:
        card.fail(f"Thick = {raw['thick']:g} m: a shell needs a thickness > 0", third)
    points = raw["n"] or 5
    if not 1 <= points <= 10:
        card.fail(f"N = {points}: 1 to 10 points through the thickness", third)
    if value["idrill"] not in (0, 1, 2):
        card.fail(f"Idrill = {value['idrill']}: 1 (drilling springs) or 2 (none, as when "
                  "blank)", first)  # fmt: skip
    hourglass = [h if h else 0.01 for h in raw["hourglass"]]
    element = {"thickness": raw["thick"], "points": points,
               "hourglass_coefficients": hourglass}  # fmt: skip
    if value["idrill"] == 1:
        element["drilling_stiffness"] = DRILLING_STIFFNESS
        deck.warn(card, f"Idrill = 1: drilling springs of {DRILLING_STIFFNESS:g} G t A per "
                  "node on quadrilaterals (Radioss's own drilling stiffness differs; "
                  "triangles have none)", first)  # fmt: skip
    if ishell == 3:
        element["hourglass_stiffness"] = HOURGLASS_STIFFNESS
        deck.warn(card, f"Ishell = 3: read as Belytschko-Lin-Tsay shells with the warping "
                  f"correction, an elastic hourglass stiffness {HOURGLASS_STIFFNESS:g} (not "
                  "elasto-plastic) and viscous hourglass control hm, hf, hr", first)  # fmt: skip
    if raw["ashear"]:
        element["shear_factor"] = raw["ashear"]
    if raw["thickfail"]:
        element["failed_share"] = raw["thickfail"]
    if value["ithick"] == 1:
        element["thickness_change"] = True
    if value["iplas"] in (0, 2):
        deck.warn(card, f"Iplas = {value['iplas']}{' (blank)' if not value['iplas'] else ''}: "
                  "Radioss returns a LAW2 material's plane stress radially (a scaled trial "
                  "stress, cgrtails.F and m2cplr.F); rwall_fem's return is the exact one of "
                  "Iplas 1", third)  # fmt: skip
    if ishell not in (3, 24):
        what = ("QEPH's physical stabilisation" if ishell == 12 else
                "Radioss's elastic hourglass forces (HELAS hm, with a quadratic viscosity)")
        deck.warn(card, f"Ishell = {ishell}: read as Belytschko-Lin-Tsay shells with the "
                  f"warping correction, {what} as the elastic hourglass stiffness "
                  f"3 HELAS hm (1 - nu^2), HELAS = 0.5, and linear viscous hm, hf, hr",
                  first)  # fmt: skip
    if ishell == 24 and raw["dn"] and raw["dn"] != 0.015:
        deck.warn(card, f"dn = {raw['dn']:g}: QEPH's numerical damping is not applied; "
                  "its step and hourglass viscosity take dn = 0.015", first)  # fmt: skip
    return {"kind": "shell", "ishell": ishell, "ish3n": ish3n, "where": card.header.where,
            "line": first.where, "element": element}  # fmt: skip


def shell_element(deck: Deck, pid: int, cell: str, poisson: float) -> tuple[dict, str]:
    """The [element] table of /PROP/SHELL ``pid`` for ``cell`` cells of a material of
    Poisson's ratio ``poisson``, and the line saying what it became."""
    p = deck.properties[pid]
    element = dict(p["element"])
    element["formulation"] = "bsc" if cell == "triangle" else ISHELL[p["ishell"]]
    if p["ishell"] not in (3, 24):  # Radioss's elastic hourglass forces (CHVIS3)
        hm = element["hourglass_coefficients"][0]
        element["hourglass_stiffness"] = 3.0 * HELAS * hm * (1.0 - poisson**2)
    if p["ishell"] == 24:  # QEPH: its own characteristic length (CZCORC1, CNDT3) and its
        # physical hourglass stiffness with its yield and viscosity (CZFINTN1), where hm,
        # hf, hr are not read (hm_read_prop01.F: Hm becomes Dn)
        element["step_length"] = "qeph"
        if cell == "quadrilateral":
            element.pop("hourglass_stiffness", None)
            element["hourglass_coefficients"] = [0.0, 0.0, 0.0]
            element["hourglass_yield"] = True
    if cell == "triangle":
        for name in _QUADRILATERAL_KEYS:
            element.pop(name, None)
    head = (f"property: /PROP/SHELL/{pid} Ishell {p['ishell']} Ish3n {p['ish3n']} "
            f"({p['where']})")  # fmt: skip
    text = ", ".join(f"{k} {v}" for k, v in element.items())
    return element, f"{head} -> {text}"


STARTER = {
    "SHELL": _elements,
    "SH3N": _elements,
    "PROP/SHELL": _property,
    "PROP/TYPE1": _property,
}
