"""Contact interfaces: /INTER/TYPE7 (Radioss's general node-to-surface contact), read into
:class:`Interface` (in SI) for :mod:`rwall_fem.radioss.contacts` to turn into ``[[contact]]``
tables. Other kinds of interface are refused naming the kind; TYPE3 and TYPE5 (Radioss's
older surface-to-surface and node-to-surface contacts) too, saying that TYPE7 does what
they do.

Fields read: grnd_IDs, surf_IDm, Istf, Igap, Idel, Gapmin, Stfac, Fric, Inacti, VISs,
Ifric, Ifiltr, Xfreq, Irem_gap; Fscalegap and Gap_max with Igap 2 and 3, %mesh_size with Igap 3,
Stmin and Stmax with Istf 2 to 5 (where Radioss reads them: ``hm_read_inter_type07.F``;
elsewhere Radioss leaves them out, and a warning line says so). Each other field that is
not at its default gives one warning line saying it is not honoured (``docs/radioss.md``,
"Contact interfaces").
"""

from __future__ import annotations

from dataclasses import dataclass

from rwall_fem.radioss.cards.base import card_units, catch_all, ident
from rwall_fem.radioss.model import Deck
from rwall_fem.radioss.reader import Card

__all__ = ["Interface", "STARTER"]


@dataclass
class Interface:
    """An /INTER/TYPE7 in SI: its secondary node group and main surface, the stiffness
    flag and scale, the gap flag and minimum gap (m, 0: Radioss's default), Coulomb's
    coefficient with its filter (``ifq``, ``xfreq``: as /RWALL's), the normal damping;
    the variable gap's scale, bound (m, 0: none) and size share (Fscalegap, Gap_max,
    %mesh_size), the bounds of the penalty stiffness (N/m, Stmin, Stmax; 0: none); whether
    each segment leaves out of its search the nodes within sqrt 2 x the gap of it along the
    mesh (Irem_gap 2)."""

    id: int
    title: str
    node_group: int
    surface: int
    istf: int
    igap: int
    gap_min: float
    stiffness_scale: float
    friction: float
    filter_flag: int
    filter_factor: float
    damping: float
    where: str
    gap_scale: float = 1.0
    gap_max: float = 0.0
    size_share: float = 0.4
    stiffness_min: float = 0.0
    stiffness_max: float = 0.0
    exclude_within_gap: bool = False


def _ignored(deck: Deck, card: Card, line, values: dict) -> None:
    """One warning line for each field of ``values`` (name -> value) not at its default."""
    for name, value in values.items():
        if value:
            deck.warn(card, f"{name} = {value:g}: not honoured (rwall_fem's contact has no "
                      "such option; the field is left out)", line)  # fmt: skip


def _type7(deck: Deck, card: Card) -> None:
    iid = ident(card, 2, "inter_ID")
    units = card_units(deck, card, 3)
    if any(i.id == iid for i in deck.interfaces):
        card.fail(f"interface {iid} is defined twice")
    layout = "i:grnd_IDs i:surf_IDm i:Istf i:Ithe i:Igap -:blank i:Ibag i:Idel i:Icurv i:Iadm"
    nodes, surf, istf, ithe, igap, ibag, idel, icurv, iadm = card.read(1, layout)
    if surf <= 0:
        card.fail(f"surf_IDm = {surf}: the main surface is a /SURF ID > 0", card.lines[1])
    if nodes < 0:
        card.fail(f"grnd_IDs = {nodes}: the secondary nodes are a /GRNOD ID (0: none)",
                  card.lines[1])  # fmt: skip
    if istf < 0 or istf not in (0, 1, 2, 3, 4, 5, 1000):
        card.fail(f"Istf = {istf}: 0 or 1000 (the main side's stiffness), 1 (Stfac is the "
                  "stiffness), 2 to 5 (main and secondary combined)", card.lines[1])  # fmt: skip
    if istf == 1:
        card.fail("Istf = 1: a stiffness given as a value (Stfac, N/m) is not supported; "
                  "give Istf 0 and Stfac as a scale of the main side's stiffness",
                  card.lines[1])  # fmt: skip
    if istf in (2, 3, 4, 5):
        deck.warn(card, f"Istf = {istf}: not honoured: the stiffness is the main side's "
                  "(Istf 1000), within Stmin and Stmax", card.lines[1])  # fmt: skip
    if igap not in (0, 1, 2, 3, 1000):
        card.fail(f"Igap = {igap}: 0 or 1000 (a constant gap), 1, 2 or 3 (variable)",
                  card.lines[1])  # fmt: skip
    if idel not in (0, 1000):
        deck.warn(card, f"Idel = {idel}: not honoured: contact bodies do not erode here, "
                  "so no segment is ever deleted", card.lines[1])  # fmt: skip
    _ignored(deck, card, card.lines[1], {"Ithe": ithe, "Ibag": ibag, "Icurv": icurv,
                                         "Iadm": iadm})  # fmt: skip
    fscale, gapmax, fpenmax, itied, ists = card.read(
        2, "f:Fscalegap f:Gap_max f:Fpenmax -:blank:20 i:Itied i:Ists")
    gap = _variable_gap(deck, card, igap, fscale, gapmax, units.length)
    _ignored(deck, card, card.lines[2], {"Fpenmax": fpenmax, "Itied": itied,
                                         "Ists": ists})  # fmt: skip
    stmin, stmax, mesh, dtmin, irem_gap, irem_i2 = card.read(
        3, "f:Stmin f:Stmax f:Percent_mesh_size f:dtmin i:Irem_gap i:Irem_i2")
    gap["size_share"] = _size_share(deck, card, igap, mesh)
    stiffness = units.factor("force") / units.length
    bounds = _stiffness_bounds(deck, card, istf, stmin, stmax, stiffness)
    _ignored(deck, card, card.lines[3], {"dtmin": dtmin, "Irem_i2": irem_i2})
    at = 5 if icurv in (1, 2) else 4  # the curvature's node line
    stfac, fric, gapmin, tstart, tstop = card.read(at, "f:Stfac f:Fric f:GAPmin f:Tstart f:Tstop")
    if stfac < 0:
        card.fail(f"Stfac = {stfac:g}: the stiffness scale is >= 0 (0: 1)", card.lines[at])
    if fric < 0:
        card.fail(f"Fric = {fric:g}: Coulomb's coefficient is >= 0", card.lines[at])
    if gapmin < 0:
        card.fail(f"GAPmin = {gapmin:g}: the minimum gap is >= 0 (0: Radioss's default)",
                  card.lines[at])  # fmt: skip
    _ignored(deck, card, card.lines[at], {"Tstart": tstart, "Tstop": tstop})
    ibc, inacti, viss, visf, bumult = card.read_optional(
        at + 1, "s:IBC -:blank:20 i:Inacti f:VIS_S f:VIS_F f:Bumult")
    if inacti not in (0, 6, 1000):
        deck.warn(card, f"Inacti = {inacti}: not honoured: taken as 6 (a node inside the gap "
                  "at the start gets a gap of 0.95 of its distance, growing back)")  # fmt: skip
    if not 0.0 <= viss <= 1.0:
        card.fail(f"VIS_S = {viss:g}: the normal damping is a fraction of critical in [0, 1]",
                  card.lines[at + 1])  # fmt: skip
    _ignored(deck, card, None, {"IBC": int(ibc or 0), "VIS_F": visf, "Bumult": bumult})
    ifric, ifiltr, xfreq, iform, sensor, fct, ascale, fric_id = card.read_optional(
        at + 2, "i:Ifric i:Ifiltr f:Xfreq i:Iform i:sens_ID i:fct_IDF f:AscaleF i:fric_ID")
    if ifric:
        card.fail(f"Ifric = {ifric}: only Coulomb friction (Ifric 0) is supported")
    if ifiltr not in (0, 1, 2, 3):
        card.fail(f"Ifiltr = {ifiltr}: 0 (no filter), 1 (alpha), 2 (period in steps), 3 "
                  "(cut-off frequency)")  # fmt: skip
    _ignored(deck, card, None, {"Iform": iform if iform != 1 else 0, "sens_ID": sensor,
                                "fct_IDF": fct, "AscaleF": ascale, "fric_ID": fric_id})  # fmt: skip
    if xfreq == 0.0:
        ifiltr = 0  # Radioss: no factor, no filter
    deck.interfaces.append(Interface(
        iid, card.title(), nodes, surf, istf, 1 if igap in (1, 2, 3) else 0,
        gapmin * units.length, stfac or 1.0, fric, ifiltr,
        xfreq * (units.factor("rate") if ifiltr == 3 else 1.0), viss or 0.05,
        card.header.where, **gap, **bounds, exclude_within_gap=irem_gap == 2,
    ))  # fmt: skip


def _variable_gap(deck: Deck, card: Card, igap: int, scale: float, bound: float,
                  length: float) -> dict:  # fmt: skip
    """Fscalegap and Gap_max (the deck's length, ``length`` m): read with Igap 2 and 3 (0:
    1 and no bound), left out with a warning line with Igap 0 and 1 (as Radioss does); a
    negative one refused."""
    if scale < 0:
        card.fail(f"Fscalegap = {scale:g}: the gap scale is > 0 (0: 1)", card.lines[2])
    if bound < 0:
        card.fail(f"Gap_max = {bound:g}: the largest gap is > 0 (0: no bound)", card.lines[2])
    if igap in (2, 3):
        return {"gap_scale": scale or 1.0, "gap_max": bound * length}
    for name, value in (("Fscalegap", scale), ("Gap_max", bound)):
        if value:
            deck.warn(card, f"{name} = {value:g}: left out: Radioss reads it with Igap 2 and "
                      f"3 only (Igap = {igap})", card.lines[2])  # fmt: skip
    return {}


def _size_share(deck: Deck, card: Card, igap: int, share: float) -> float:
    """%mesh_size: a pair's variable gap at most this fraction of the sum of the node's and
    the segment's shortest sides, in (0, 1] (0: Radioss's 0.4); read with Igap 3, left out with a warning
    line with Igap 0 to 2 (as Radioss does; with Igap 1 and 2 0.4 kept, the cap of every
    variable gap)."""
    if not 0.0 <= share <= 1.0:
        card.fail(f"%mesh_size = {share:g}: the share of the shortest side is in (0, 1] (0: "
                  "0.4)", card.lines[3])  # fmt: skip
    if share and igap != 3:
        kept = "; 0.4 kept" if igap in (1, 2) else ""  # a constant gap has no share
        deck.warn(card, f"%mesh_size = {share:g}: left out: Radioss reads it with Igap 3 only "
                  f"(Igap = {igap}){kept}", card.lines[3])  # fmt: skip
        return 0.4
    return share or 0.4


def _stiffness_bounds(deck: Deck, card: Card, istf: int, low: float, high: float,
                      unit: float) -> dict:  # fmt: skip
    """Stmin and Stmax (the deck's stiffness, ``unit`` N/m): read with Istf 2 to 5 (Stmax
    0: no bound), left out with a warning line with Istf 0 and 1000 (as Radioss does);
    negative or crossed, refused."""
    if low < 0 or high < 0:
        card.fail(f"Stmin = {low:g}, Stmax = {high:g}: the bounds of the stiffness are >= 0 "
                  "(Stmax 0: no bound)", card.lines[3])  # fmt: skip
    if high and low > high:
        card.fail(f"Stmin = {low:g} is above Stmax = {high:g}: the bounds of the stiffness",
                  card.lines[3])  # fmt: skip
    if istf in (2, 3, 4, 5):
        return {"stiffness_min": low * unit, "stiffness_max": high * unit}
    for name, value in (("Stmin", low), ("Stmax", high)):
        if value:
            deck.warn(card, f"{name} = {value:g}: left out: Radioss reads it with Istf 2 to 5 "
                      f"only (Istf = {istf})", card.lines[3])  # fmt: skip
    return {}


def _older(deck: Deck, card: Card) -> None:
    card.fail(f"interfaces of {card.key(1)} are not read: /INTER/TYPE7 is (node-to-surface "
              "contact, both sides of shells, self-contact): write the contact as a TYPE7")


@catch_all
def _other(deck: Deck, card: Card) -> None:
    card.fail(f"interfaces of {card.key(1) or 'no kind'} are not read; supported: "
              "/INTER/TYPE7")


STARTER = {"INTER/TYPE7": _type7, "INTER/TYPE3": _older, "INTER/TYPE5": _older,
           "INTER": _other}  # fmt: skip
