"""The starter file's cards, read into a :class:`~rwall_fem.radioss.model.Deck` in SI.

Column layouts are those of OpenRadioss's 2026 block format; older versions (input
version >= 100) use the same columns, where a field added later is blank (its default).
A card that is not supported is refused in one line naming it and what is supported;
cards that only ask for Radioss's own outputs are skipped with one warning each.
"""

from __future__ import annotations

import numpy as np

from rwall_fem.radioss.model import Body, Deck, Function, NodeGroup, Part, Prescribed, Wall
from rwall_fem.radioss.reader import Card, DeckError, fixed_table, read_fields
from rwall_fem.radioss.units import UnitSystem, parse_unit

__all__ = ["OUTPUT_CARDS", "SUPPORTED", "read_starter"]

# Cards that only ask for the peer's own outputs: skipped, one warning each.
OUTPUT_CARDS = ("TH", "ANIM", "PRINT", "VERS", "RFILE", "STATE", "OUTP", "H3D", "TITLE")

SUPPORTED = (
    "/BEGIN, /NODE, /BRICK, /TETRA4, /PART, /MAT/LAW1 (ELAST), /MAT/LAW2 (PLAS_JOHNS), "
    "/MAT/LAW36 (PLAS_TAB), /PROP/SOLID (TYPE14), /GRNOD/NODE, /GRNOD/PART, /GRNOD/BOX, "
    "/BOX/RECTA, /FUNCT, /INIVEL/TRA, /BCS, /GRAV, /IMPVEL, /RWALL/PLANE, /RWALL/CYL, "
    "/RWALL/SPHER, /RWALL/PARAL"
)
_MATERIAL_LAWS = {"LAW1": "LAW1", "ELAST": "LAW1", "LAW2": "LAW2", "PLAS_JOHNS": "LAW2",
                  "LAW36": "LAW36", "PLAS_TAB": "LAW36"}  # fmt: skip
_WALL_KINDS = ("PLANE", "CYL", "SPHER", "PARAL")
_BIG = 1e19  # Radioss writes "no limit" as 1e20 or 1e30; a blank or 0 field means it too


def read_starter(deck: Deck, cards: list[Card]) -> None:
    """Fill ``deck`` from the starter's ``cards`` (the first one must be /BEGIN)."""
    if not cards or cards[0].key(0) != "BEGIN":
        where = cards[0].header.where if cards else str(deck.starter)
        raise DeckError(
            f"{where}: the starter file must begin with /BEGIN (run name, input version, "
            "input and work units)"
        )
    _begin(deck, cards[0])
    units = deck.input_units
    node_cards = []
    for card in cards[1:]:
        kind = card.key(0)
        if kind == "BEGIN":
            card.fail("a second /BEGIN")
        elif kind == "NODE":
            node_cards.append(card)
        elif kind in ("BRICK", "TETRA4"):
            _elements(deck, card)
        elif kind == "PART":
            _part(deck, card)
        elif kind == "MAT":
            _material(deck, card, units)
        elif kind == "PROP":
            _property(deck, card)
        elif kind == "GRNOD":
            _node_group(deck, card)
        elif kind == "BOX":
            _box(deck, card, units)
        elif kind == "FUNCT":
            _function(deck, card)
        elif kind == "INIVEL":
            _initial_velocity(deck, card, units)
        elif kind == "BCS":
            _clamp(deck, card)
        elif kind == "GRAV":
            deck.gravity.append(_prescribed(deck, card, units, "acceleration", grav=True))
        elif kind == "IMPVEL":
            deck.velocities.append(_prescribed(deck, card, units, "velocity"))
        elif kind == "RWALL":
            _wall(deck, card, units)
        elif kind in OUTPUT_CARDS:
            deck.warnings.append(
                f"{card.header.where}: {card.name}: skipped (asks for Radioss's own output)"
            )
        else:
            card.fail(f"unsupported card; the starter cards read are {SUPPORTED}")
    _nodes(deck, node_cards, units)


def ident(card: Card, index: int, what: str = "ID") -> int:
    """The integer keyword part ``index`` (an ID); a unit_ID after it must be absent."""
    if index >= len(card.parts) or not card.parts[index]:
        card.fail(f"missing {what} in the card's name")
    try:
        value = int(card.parts[index])
    except ValueError:
        card.fail(f"{what} {card.parts[index]!r} is not an integer")
    if index + 1 < len(card.parts) and card.parts[index + 1] not in ("", "0"):
        card.fail(
            f"unit_ID {card.parts[index + 1]}: local unit systems (/UNIT) are not supported; "
            "give the values in the input units of /BEGIN"
        )
    return value


def _begin(deck: Deck, card: Card) -> None:
    deck.run_name = card.line(0, "Runname").text.strip()
    version, _ = card.read(1, "i:Invers i:Irun", "Invers Irun")
    if version < 100:
        card.fail(
            f"input version {version}: only the block format of version 10 and later "
            "(Invers >= 100) is read",
            card.lines[1],
        )
    deck.version = version
    systems = []
    for index, what in ((3, "Work_mass_unit Work_length_unit Work_time_unit"),
                        (2, "Input_mass_unit Input_length_unit Input_time_unit")):  # fmt: skip
        line = card.line(index, what)
        texts = read_fields(card, line, "s:mass:20 s:length:20 s:time:20")
        default = systems[0] if systems else UnitSystem()
        sizes, names = [], []
        for text, quantity, fallback, name in zip(
            texts, ("mass", "length", "time"),
            (default.mass, default.length, default.time), default.names, strict=True,
        ):  # fmt: skip
            size = parse_unit(text, quantity)
            if size is None and text:
                card.fail(
                    f"{quantity} unit {text!r}: give a code (an SI prefix and g, m or s, such "
                    "as kg, Mg, mm, ms, mus; or lb, in, ft) or the unit's size in SI",
                    line,
                )
            sizes.append(fallback if size is None else size)
            names.append(text or name)
        systems.append(UnitSystem(*sizes, names=tuple(names)))
    deck.work_units, deck.input_units = systems


def _nodes(deck: Deck, cards: list[Card], units: UnitSystem) -> None:
    ids, xyz = [], []
    for card in cards:
        i, x, y, z = fixed_table(card, 0, "i:node_ID f:X f:Y f:Z")
        bad = np.flatnonzero(i <= 0)
        if len(bad):
            card.fail(f"node ID {i[bad[0]]}: node IDs are positive", card.lines[bad[0]])
        ids.append(i)
        xyz.append(np.column_stack([x, y, z]))
    deck.node_ids = np.concatenate(ids) if ids else np.zeros(0, dtype=np.int64)
    deck.coordinates = (np.concatenate(xyz) if xyz else np.zeros((0, 3))) * units.length
    unique, counts = np.unique(deck.node_ids, return_counts=True)
    if np.any(counts > 1):
        raise DeckError(
            f"{cards[0].header.where}: /NODE: node {unique[counts > 1][0]} is defined twice"
        )


def _elements(deck: Deck, card: Card) -> None:
    part = ident(card, 1, "part_ID")
    count = 8 if card.key(0) == "BRICK" else 4
    layout = "i:elem_ID " + " ".join(f"i:node{k + 1}" for k in range(count))
    columns = fixed_table(card, 0, layout)
    ids, nodes = columns[0], np.column_stack(columns[1:]) if columns[1:] else None
    if nodes is None or not len(ids):
        card.fail("no elements")
    missing = np.flatnonzero((nodes <= 0).any(axis=1))
    if len(missing):
        k = missing[0]
        given = int((nodes[k] > 0).sum())
        card.fail(
            f"truncated line: element {ids[k]} needs {count} node IDs, got {given}",
            card.lines[k],
        )
    sorted_nodes = np.sort(nodes, axis=1)
    repeated = np.flatnonzero((np.diff(sorted_nodes, axis=1) == 0).any(axis=1))
    if len(repeated):
        card.fail(
            f"element {ids[repeated[0]]} repeats a node (a degenerate element): only "
            f"{count}-node elements with distinct nodes are read",
            card.lines[repeated[0]],
        )
    cell = "hexahedron" if count == 8 else "tetrahedron"
    deck.bodies.append(Body(part, cell, ids, nodes, card))


def _part(deck: Deck, card: Card) -> None:
    pid = ident(card, 1, "part_ID")
    prop, mat = card.read(1, "i:prop_ID i:mat_ID", "prop_ID mat_ID subset_ID")
    if pid in deck.parts:
        card.fail(f"part {pid} is defined twice")
    if mat == 0:
        card.fail(f"part {pid} has no material (mat_ID is 0 or blank)", card.lines[1])
    if prop == 0:
        card.fail(f"part {pid} has no property (prop_ID is 0 or blank)", card.lines[1])
    deck.parts[pid] = Part(pid, card.title(), prop, mat, card.lines[1].where)


def _inactive(value: float) -> bool:
    """A Radioss limit left at its default: blank (0) or 1e20-like."""
    return value == 0.0 or abs(value) >= _BIG


def _material(deck: Deck, card: Card, units: UnitSystem) -> None:
    law = _MATERIAL_LAWS.get(card.key(1))
    if law is None:
        card.fail(
            "unsupported material law; supported: /MAT/LAW1 (ELAST), /MAT/LAW2 (PLAS_JOHNS), "
            "/MAT/LAW36 (PLAS_TAB)"
        )
    mid = ident(card, 2, "mat_ID")
    if mid in deck.materials:
        card.fail(f"material {mid} is defined twice")
    rho, rho0 = card.read(1, "f:RHO_I f:RHO_0", "RHO_I")
    facts: dict = {"law": law, "title": card.title(), "where": card.header.where,
                   "density": rho * units.factor("density")}  # fmt: skip
    if rho0 and rho0 != rho:
        deck.warnings.append(
            f"{card.lines[1].where}: {card.name}: RHO_0 (reference density of an equation of "
            "state) is not used: these laws have none"
        )
    stress = units.factor("stress")
    if law == "LAW1":
        E, nu = card.read(2, "f:E f:nu", "E nu")
        facts |= {"young": E * stress, "poisson": nu}
    elif law == "LAW2":
        facts |= _johnson_cook(deck, card, units)
    else:
        facts |= _tabulated(card, units)
    deck.materials[mid] = facts


def _johnson_cook(deck: Deck, card: Card, units: UnitSystem) -> dict:
    """/MAT/LAW2: (a + b eps_p^n)(1 + c ln(rate/rate_0))(1 - T*^m); what has no
    counterpart is refused unless it is inactive."""
    stress = units.factor("stress")
    E, nu, iflag, vp, pmin = card.read(2, "f:E f:nu i:Iflag i:VP f:Pmin", "E nu Iflag VP Pmin")
    if iflag != 0:
        card.fail("Iflag 1 (yield stress, UTS and strain at UTS): give a, b and n (Iflag 0)",
                  card.lines[2])  # fmt: skip
    if not _inactive(pmin):
        card.fail(f"Pmin = {pmin:g}: rwall_fem has no pressure cut-off; leave Pmin blank",
                  card.lines[2])  # fmt: skip
    a, b, n, eps_max, sig_max = card.read(3, "f:a f:b f:n f:EPS_p_max f:SIG_max0",
                                          "a b n EPS_p_max SIG_max0")  # fmt: skip
    if not _inactive(eps_max):
        card.fail(f"EPS_p_max = {eps_max:g}: rwall_fem has no failure (no element erosion); "
                  "leave EPS_p_max blank", card.lines[3])  # fmt: skip
    if not _inactive(sig_max):
        card.fail(f"SIG_max0 = {sig_max:g}: rwall_fem has no cap on the flow stress; leave "
                  "SIG_max0 blank", card.lines[3])  # fmt: skip
    c, rate0, _, smooth, _, chard = card.read(
        4, "f:c f:EPS_DOT_0 i:ICC i:Fsmooth f:F_cut f:Chard", "c EPS_DOT_0 ICC Fsmooth F_cut Chard"
    )
    if chard != 0.0:
        card.fail(f"Chard = {chard:g}: rwall_fem's hardening is isotropic (Chard 0)",
                  card.lines[4])  # fmt: skip
    m, t_melt, rho_cp, t_room, t_max = card.read(4 + 1, "f:m f:T_melt f:rhoC_p f:T_r f:T_max",
                                                 "m T_melt rhoC_p T_r T_max")  # fmt: skip
    if n == 0.0 and b != 0.0:
        n = 1.0  # Radioss's default exponent
    facts = {"young": E * stress, "poisson": nu, "a": a * stress, "b": b * stress,
             "n": n if n else 1.0}  # fmt: skip
    if c != 0.0:
        if rate0 <= 0.0:
            card.fail("c > 0 needs EPS_DOT_0 > 0 (the reference strain rate)", card.lines[4])
        facts |= {"c": c, "rate0": rate0 * units.factor("rate")}
        deck.warnings.append(
            f"{card.lines[4].where}: {card.name}: the rate term uses rwall_fem's strain rate, "
            f"the equivalent deviatoric rate of each step, unfiltered (flagVP {vp}, Fsmooth "
            f"{smooth} of the deck choose Radioss's)"
        )
    if not _inactive(t_melt):
        if rho_cp <= 0.0:
            card.fail("T_melt is given: the thermal term needs rhoC_p > 0", card.lines[5])
        if not _inactive(t_max):
            card.fail(f"T_max = {t_max:g}: rwall_fem has no temperature cap; leave it blank",
                      card.lines[5])  # fmt: skip
        facts |= {"m": m if m else 1.0, "t_melt": t_melt,
                  "heat": rho_cp * units.factor("heat_capacity_per_volume"),
                  "t_room": t_room if t_room else 298.0}  # fmt: skip
        deck.warnings.append(
            f"{card.lines[5].where}: {card.name}: the thermal term heats by the plastic work "
            "(taylor_quinney = 1), where Radioss heats by the internal energy"
        )
    return facts


def _tabulated(card: Card, units: UnitSystem) -> dict:
    """/MAT/LAW36 with one function and no rate, pressure or modulus dependence: a
    tabulated hardening curve."""
    stress = units.factor("stress")
    E, nu, eps_max, eps_t, eps_m = card.read(2, "f:E f:nu f:EPS_p_max f:EPS_t f:EPS_m",
                                             "E nu EPS_p_max EPS_t EPS_m")  # fmt: skip
    for name, value in (("EPS_p_max", eps_max), ("EPS_t", eps_t), ("EPS_m", eps_m)):
        if not _inactive(value):
            card.fail(f"{name} = {value:g}: rwall_fem has no failure; leave it blank",
                      card.lines[2])  # fmt: skip
    nfunct, _, chard = card.read(3, "i:N_funct i:Fsmooth f:Chard", "N_funct Fsmooth Chard")
    if nfunct != 1:
        card.fail(f"N_funct = {nfunct}: one hardening function (no strain-rate dependence) is "
                  "read", card.lines[3])  # fmt: skip
    if chard != 0.0:
        card.fail(f"Chard = {chard:g}: rwall_fem's hardening is isotropic (Chard 0)",
                  card.lines[3])  # fmt: skip
    fct_p, _, fct_e = card.read(4, "i:fct_IDp f:Fscale i:fct_IDE", "fct_IDp Fscale fct_IDE")
    if fct_p or fct_e:
        card.fail("fct_IDp and fct_IDE (pressure and Young's modulus functions) are not read; "
                  "leave them blank", card.lines[4])  # fmt: skip
    (fct,) = card.read(5, "i:fct_ID1", "fct_ID1")
    (scale,) = card.read(6, "f:Fscale1", "Fscale1")
    if fct <= 0:
        card.fail("fct_ID1 (the hardening function) is missing", card.lines[5])
    return {"young": E * stress, "poisson": nu, "curve": fct,
            "curve_scale": (scale or 1.0) * stress, "curve_where": card.lines[5].where}  # fmt: skip


# Element technologies by Isolid: the scene's [element] keys.
ISOLID = {
    24: {"integration": "reduced", "hourglass": "physical"},
    14: {"integration": "full"},
    1: {"integration": "reduced", "hourglass": "viscous"},
    2: {"integration": "reduced", "hourglass": "viscous"},
}


def _property(deck: Deck, card: Card) -> None:
    if card.key(1) not in ("SOLID", "TYPE14"):
        card.fail("unsupported property; supported: /PROP/SOLID (/PROP/TYPE14)")
    pid = ident(card, 2, "prop_ID")
    if pid in deck.properties:
        card.fail(f"property {pid} is defined twice")
    line = card.line(1, "Isolid Ismstr Iale Icpre Itetra10 Inpts Itetra4 Iframe dn")
    isolid, ismstr, iale, icpre, _, inpts, itetra4, _, dn = read_fields(
        card, line, "i:Isolid i:Ismstr i:Iale i:Icpre i:Itetra10 i:Inpts i:Itetra4 i:Iframe f:dn"
    )
    isolid = isolid or 1  # Radioss's default without /DEF_SOLID
    if isolid not in ISOLID:
        card.fail(f"Isolid = {isolid}: supported: 24 (HEPH: one point, physical hourglass "
                  "control), 14 (fully integrated), 1 and 2 (one point, viscous hourglass "
                  "control)", line)  # fmt: skip
    if ismstr not in (0, 2, 4):
        card.fail(f"Ismstr = {ismstr}: small-strain formulations are not supported; leave "
                  "Ismstr blank (full geometric non-linearity)", line)  # fmt: skip
    if iale:
        card.fail(f"Iale = {iale}: ALE and Euler elements are not supported", line)
    if isolid == 14 and inpts not in (0, 222):
        card.fail(f"Inpts = {inpts}: Isolid 14 is read with 2 x 2 x 2 points (Inpts 222)", line)
    if itetra4 not in (0,):
        card.fail(f"Itetra4 = {itetra4}: tetrahedra are one-point P1 elements (Itetra4 0)", line)
    qa, qb, h = (0.0, 0.0, 0.0)
    if len(card.lines) > 2:
        qa, qb, h = card.read(2, "f:qa f:qb f:h", "qa qb h")
    facts = {"isolid": isolid, "icpre": icpre, "element": dict(ISOLID[isolid]),
             "where": card.header.where, "line": line.where}  # fmt: skip
    if isolid in (1, 2):
        facts["element"]["hourglass_coefficient"] = h if h else 0.1
    elif h:
        deck.warnings.append(f"{line.where}: {card.name}: h = {h:g} is not used with Isolid "
                             f"{isolid}")  # fmt: skip
    if qa or qb:
        deck.warnings.append(f"{line.where}: {card.name}: qa, qb (bulk viscosity) are not "
                             "used: rwall_fem has no bulk viscosity")  # fmt: skip
    if dn:
        deck.warnings.append(f"{line.where}: {card.name}: dn (numerical damping) is not used")
    deck.properties[pid] = facts


def _id_list(card: Card) -> np.ndarray:
    """The IDs listed after the title, ten 10-character fields a line; a negative ID
    removes that item."""
    columns = fixed_table(card, 1, " ".join(f"i:id{k}" for k in range(10)))
    ids = np.concatenate([np.column_stack(columns).ravel()]) if columns else np.zeros(0, int)
    ids = ids[ids != 0]
    keep = np.setdiff1d(ids[ids > 0], -ids[ids < 0])
    return keep


def _node_group(deck: Deck, card: Card) -> None:
    kind = card.key(1)
    if kind not in ("NODE", "PART", "BOX"):
        card.fail("unsupported node group; supported: /GRNOD/NODE, /GRNOD/PART, /GRNOD/BOX")
    gid = ident(card, 2, "grnd_ID")
    if gid in deck.groups:
        card.fail(f"node group {gid} is defined twice")
    deck.groups[gid] = NodeGroup(gid, card.title(), kind, _id_list(card), card.header.where)


def _box(deck: Deck, card: Card, units: UnitSystem) -> None:
    if card.key(1) != "RECTA":
        card.fail("unsupported box; supported: /BOX/RECTA")
    bid = ident(card, 2, "box_ID")
    n1, n2, skew = card.read(1, "i:N1 i:N2 i:skew_ID", "N1 N2 skew_ID")
    if n1 or n2 or skew:
        card.fail("a box by nodes (N1, N2) or in a skew is not supported; give Xp1..Zp2",
                  card.lines[1])  # fmt: skip
    p1 = np.array(card.read(2, "f:X f:Y f:Z", "Xp1 Yp1 Zp1")) * units.length
    p2 = np.array(card.read(3, "f:X f:Y f:Z", "Xp2 Yp2 Zp2")) * units.length
    deck.boxes[bid] = (np.minimum(p1, p2), np.maximum(p1, p2), card.header.where)


def _function(deck: Deck, card: Card) -> None:
    fid = ident(card, 1, "fct_ID")
    x, y = fixed_table(card, 1, "f:X f:Y")
    if len(x) < 2 or np.any(np.diff(x) <= 0):
        card.fail("a function needs at least two points with increasing X")
    deck.functions[fid] = Function(fid, x, y, card.header.where)


def _initial_velocity(deck: Deck, card: Card, units: UnitSystem) -> None:
    if card.key(1) != "TRA":
        card.fail("unsupported initial velocity; supported: /INIVEL/TRA")
    ident(card, 2, "inivel_ID")
    vx, vy, vz, group, skew = card.read(1, "f:Vx f:Vy f:Vz i:grnd_ID i:skew_ID",
                                        "Vx Vy Vz Gnod_id Skew_id")  # fmt: skip
    if skew:
        card.fail("a skew (Skew_id) is not supported", card.lines[1])
    if len(card.lines) > 2:
        tstart, sensor = card.read(2, "f:Tstart i:sens_ID", "Tstart sens_ID")
        if tstart or sensor:
            card.fail("Tstart and sens_ID are not supported: the velocity is initial",
                      card.lines[2])  # fmt: skip
    velocity = np.array([vx, vy, vz]) * units.factor("velocity")
    deck.initial.append((velocity, group, card.lines[1].where))


def _clamp(deck: Deck, card: Card) -> None:
    if len(card.parts) > 1 and not card.parts[1].lstrip("-").isdigit():
        card.fail("unsupported boundary condition; supported: /BCS")
    ident(card, 1, "bcs_ID")
    line = card.line(1, "Tra rot skew_ID grnd_ID")
    code, skew, group = read_fields(card, line, "s:Trarot:10 i:skew_ID i:grnd_ID")
    if line.free:
        digits = code.replace(" ", "")
        tra = digits[:3] if len(digits) in (3, 6) else ""
    else:
        tra = line.text[3:6].replace(" ", "0") if len(code) else ""
        digits = line.text[:10].replace(" ", "")
    if not tra or any(c not in "01" for c in digits):
        card.fail(f"Tra rot = {code!r}: six codes 0 or 1 (TX TY TZ, then rotations), right "
                  "aligned in the first 10 columns", line)  # fmt: skip
    if skew:
        card.fail("a skew (skew_ID) is not supported", line)
    components = "".join(axis for axis, c in zip("xyz", tra, strict=True) if c == "1")
    if not components:
        deck.warnings.append(f"{line.where}: {card.name}: no translation is fixed (Tra 000): "
                             "nothing to do on solid nodes")  # fmt: skip
        return
    if digits[3:].strip("0"):
        deck.warnings.append(f"{line.where}: {card.name}: rotation codes are not used (solid "
                             "nodes have no rotations)")  # fmt: skip
    deck.clamps.append((components, group, line.where))


def _prescribed(deck: Deck, card: Card, units: UnitSystem, quantity: str,
                grav: bool = False) -> Prescribed:  # fmt: skip
    """/IMPVEL or /GRAV: fct_IDT Dir skew sens grnd (frame icoor), Ascale_x Fscale_y."""
    ident(card, 1, "ID")
    line = card.line(1, "fct_IDT Dir skew_ID sens_ID grnd_ID frame_ID icoor")
    fct, direction, skew, sensor, group, frame, icoor = read_fields(
        card, line, "i:fct_IDT s:Dir i:skew_ID i:sens_ID i:grnd_ID i:frame_ID i:icoor"
    )
    direction = direction.upper()
    if direction not in ("X", "Y", "Z"):
        card.fail(f"Dir = {direction!r}: X, Y or Z (translations)", line)
    if skew or sensor or frame or icoor:
        card.fail("skew_ID, sens_ID, frame_ID and icoor are not supported; leave them blank",
                  line)  # fmt: skip
    if fct <= 0:
        card.fail("fct_IDT (the function of time) is missing", line)
    a_scale, y_scale = 1.0, 1.0
    if len(card.lines) > 2:
        layout = "f:Ascale_x f:Fscale_y" if grav else "f:Ascale_x f:Fscale_y f:Tstart f:Tstop"
        values = card.read(2, layout, layout.replace("f:", ""))
        a_scale, y_scale = values[0] or 1.0, values[1] or 1.0
        if not grav and (values[2] or (values[3] and values[3] < _BIG)):
            card.fail("Tstart and Tstop are not supported: the velocity is imposed from t = 0 to "
                      "the end", card.lines[2])  # fmt: skip
    return Prescribed(card.name, fct, direction, group, a_scale * units.time,
                      y_scale * units.factor(quantity), line.where)  # fmt: skip


def _wall(deck: Deck, card: Card, units: UnitSystem) -> None:
    kind = card.key(1)
    if kind not in _WALL_KINDS:
        card.fail("unsupported rigid wall; supported: /RWALL/PLANE, /RWALL/CYL, /RWALL/SPHER, "
                  "/RWALL/PARAL")  # fmt: skip
    wid = ident(card, 2, "rwall_ID")
    node, slide, add, exclude, iform = card.read(
        1, "i:node_ID i:Slide i:grnd_ID1 i:grnd_ID2 i:Iform", "node_ID Slide grnd_ID1 grnd_ID2"
    )
    if slide not in (0, 1, 2):
        card.fail(f"Slide = {slide}: 0 (sliding), 1 (tied) or 2 (friction)", card.lines[1])
    if iform:
        card.fail(f"Iform = {iform}: only the kinematic formulation (Iform 0) is supported",
                  card.lines[1])  # fmt: skip
    d, fric, diameter, ffac, ifq = card.read(2, "f:Dsearch f:fric f:Diameter f:ffac i:ifq",
                                             "Dsearch fric Diameter ffac ifq")  # fmt: skip
    if d < 0:
        card.fail(f"Dsearch = {d:g}: a search distance is >= 0", card.lines[2])
    if ifq not in (0, 1, 2, 3):
        card.fail(f"ifq = {ifq}: 0 (no filter), 1 (alpha), 2 (period in steps), 3 (cut-off "
                  "frequency)", card.lines[2])  # fmt: skip
    if ffac == 0.0:
        ifq = 0  # Radioss: no factor, no filter
    mass, velocity, point = 0.0, np.zeros(3), np.zeros(3)
    if node:
        m, vx, vy, vz = card.read(3, "f:Mass f:VX0 f:VY0 f:VZ0", "Mass VX0 VY0 VZ0")
        mass, velocity = m * units.mass, np.array([vx, vy, vz]) * units.factor("velocity")
    else:
        point = np.array(card.read(3, "f:XM f:YM f:ZM", "XM YM ZM")) * units.length
    points = []
    for index, name in ((4, "M1"), (5, "M2")):
        if (kind in ("PLANE", "CYL", "PARAL") and name == "M1") or (kind == "PARAL"):
            xyz = card.read(index, "f:X f:Y f:Z", f"X{name} Y{name} Z{name}")
            points.append(np.array(xyz) * units.length)
        else:
            points.append(None)
    filter_factor = ffac * (units.factor("rate") if ifq == 3 else 1.0)
    deck.walls.append(Wall(
        wid, kind, card.title(), node, slide, add, exclude, d * units.length,
        fric, diameter * units.length, ifq, filter_factor, point, mass, velocity,
        points[0], points[1], card.header.where,
    ))  # fmt: skip
