"""/MAT: LAW1 (ELAST), LAW2 (PLAS_JOHNS: Johnson-Cook, with its failure plastic strain)
and LAW36 (PLAS_TAB: one tabulated hardening curve), read into material facts in SI
(:mod:`rwall_fem.radioss.materials` makes them [material] tables). A field of a law that
has no counterpart is refused unless it is left at its default."""

from __future__ import annotations

import math

from rwall_fem.radioss.cards.base import card_units, catch_all, ident, inactive, keyword
from rwall_fem.radioss.model import Deck
from rwall_fem.radioss.reader import Card
from rwall_fem.radioss.units import UnitSystem

__all__ = ["LAWS", "STARTER"]

# Keyword -> law, for the laws read.
LAWS = {"LAW1": "LAW1", "ELAST": "LAW1", "LAW2": "LAW2", "PLAS_JOHNS": "LAW2",
        "LAW36": "LAW36", "PLAS_TAB": "LAW36"}  # fmt: skip
_SUPPORTED = ("/MAT/LAW1 (ELAST), /MAT/LAW2 (PLAS_JOHNS), /MAT/LAW36 (PLAS_TAB), /MAT/LAW0 "
              "(VOID)")


def _material(deck: Deck, card: Card) -> None:
    law = LAWS[keyword(card.parts[1])]
    mid = ident(card, 2, "mat_ID")
    units = card_units(deck, card, 3)
    if mid in deck.materials:
        card.fail(f"material {mid} is defined twice")
    rho, rho0 = card.read(1, "f:RHO_I f:RHO_0", "RHO_I")
    facts: dict = {"law": law, "title": card.title(), "where": card.header.where,
                   "density": rho * units.factor("density"), "raw_density": rho}  # fmt: skip
    if rho0 and rho0 != rho:
        deck.warn(card, "RHO_0 (reference density of an equation of state) is not used: these "
                  "laws have none", card.lines[1])  # fmt: skip
    stress = units.factor("stress")
    if law == "LAW1":
        E, nu = card.read(2, "f:E f:nu", "E nu")
        facts |= {"young": E * stress, "poisson": nu, "raw_young": E}
    elif law == "LAW2":
        facts |= _johnson_cook(deck, card, units)
    else:
        facts |= _tabulated(card, units)
    deck.materials[mid] = facts


def _void(deck: Deck, card: Card) -> None:
    """/MAT/VOID (/MAT/LAW0): no stiffness, no mass; its elements are left out of the mesh
    (:mod:`rwall_fem.radioss.void`)."""
    mid = ident(card, 2, "mat_ID")
    if mid in deck.materials:
        card.fail(f"material {mid} is defined twice")
    deck.materials[mid] = {"law": "LAW0", "title": card.title(), "where": card.header.where,
                           "density": 0.0}  # fmt: skip


@catch_all
def _other_material(deck: Deck, card: Card) -> None:
    card.fail(f"unsupported material law; supported: {_SUPPORTED}")


def _failure_strain(card: Card, name: str, value: float, line) -> dict:
    """The [material.failure] facts of a failure plastic strain field (none if inactive)."""
    if inactive(value):
        return {}
    if value < 0:
        card.fail(f"{name} = {value:g}: a failure plastic strain is > 0 (blank: none)", line)
    return {"failure": {"criterion": "plastic_strain", "plastic_strain": value}}


def _johnson_cook(deck: Deck, card: Card, units: UnitSystem) -> dict:
    """/MAT/LAW2: (a + b eps_p^n)(1 + c ln(rate/rate_0))(1 - T*^m) (Iflag 1: b and n from
    a tensile test), the element deleted when eps_p reaches EPS_p_max; what has no
    counterpart is refused unless inactive."""
    stress = units.factor("stress")
    E, nu, iflag, vp, pmin = card.read(2, "f:E f:nu i:Iflag i:VP f:Pmin", "E nu Iflag VP Pmin")
    if iflag not in (0, 1):
        card.fail(f"Iflag = {iflag}: 0 (a, b, n) or 1 (yield stress, UTS, strain at UTS)",
                  card.lines[2])  # fmt: skip
    if not inactive(pmin):
        card.fail(f"Pmin = {pmin:g}: rwall_fem has no pressure cut-off; leave Pmin blank",
                  card.lines[2])  # fmt: skip
    a, b, n, eps_max, sig_max = card.read(3, "f:a f:b f:n f:EPS_p_max f:SIG_max0",
                                          "a b n EPS_p_max SIG_max0")  # fmt: skip
    c, rate0, icc, smooth, _, chard = card.read_optional(
        4, "f:c f:EPS_DOT_0 i:ICC i:Fsmooth f:F_cut f:Chard"
    )
    if chard != 0.0:
        card.fail(f"Chard = {chard:g}: rwall_fem's hardening is isotropic (Chard 0)",
                  card.lines[4])  # fmt: skip
    m, t_melt, rho_cp, t_room, t_max = card.read_optional(5, "f:m f:T_melt f:rhoC_p f:T_r f:T_max")
    if iflag == 1:
        b, n = _from_tensile_test(deck, card, E, a, b, n)
    elif n == 0.0 and b != 0.0:
        n = 1.0  # Radioss's default exponent
    facts = {"young": E * stress, "poisson": nu, "a": a * stress, "b": b * stress,
             "n": n if n else 1.0, "raw_young": E}  # fmt: skip
    facts |= _failure_strain(card, "EPS_p_max", eps_max, card.lines[3])
    facts |= _flow_stress_cap(card, sig_max, a, icc, c != 0.0 or not inactive(t_melt), stress)
    if c != 0.0:
        if rate0 <= 0.0:
            card.fail("c > 0 needs EPS_DOT_0 > 0 (the reference strain rate)", card.lines[4])
        facts |= {"c": c, "rate0": rate0 * units.factor("rate")}
        deck.warn(card, "the rate term uses rwall_fem's strain rate, the equivalent deviatoric "
                  f"rate of each step, unfiltered (flagVP {vp}, Fsmooth {smooth} of the deck "
                  "choose Radioss's)", card.lines[4])  # fmt: skip
    if not inactive(t_melt):
        if rho_cp <= 0.0:
            card.fail("T_melt is given: the thermal term needs rhoC_p > 0", card.lines[5])
        if not inactive(t_max):
            card.fail(f"T_max = {t_max:g}: rwall_fem has no temperature cap; leave it blank",
                      card.lines[5])  # fmt: skip
        facts |= {"m": m if m else 1.0, "t_melt": t_melt,
                  "heat": rho_cp * units.factor("heat_capacity_per_volume"),
                  "t_room": t_room if t_room else 298.0}  # fmt: skip
        deck.warn(card, "the thermal term heats by the plastic work (taylor_quinney = 1), where "
                  "Radioss heats by the internal energy", card.lines[5])  # fmt: skip
    return facts


def _flow_stress_cap(card: Card, sig_max: float, a: float, icc: int, factors: bool,
                     stress: float) -> dict:  # fmt: skip
    """The max_flow_stress fact of SIG_max0 (none if blank or 1e20-like): above the yield
    stress a; applied to a + b eps_p^n before the rate and thermal factors, Radioss's ICC 1
    (its default), so that ICC 2 (the cap after them) is refused where there are factors."""
    if inactive(sig_max):
        return {}
    if sig_max <= a:
        card.fail(f"SIG_max0 = {sig_max:g}: the flow-stress cap must be above the yield stress "
                  f"a = {a:g} (blank: no cap)", card.lines[3])  # fmt: skip
    if icc == 2 and factors:
        card.fail("ICC = 2: rwall_fem caps a + b eps_p^n before the rate and thermal factors "
                  "(ICC 1, the default); leave ICC blank or 1", card.lines[4])  # fmt: skip
    return {"cap": sig_max * stress}


def _from_tensile_test(deck: Deck, card: Card, E: float, a: float, uts: float,
                       strain: float) -> tuple[float, float]:  # fmt: skip
    """b and n of Iflag 1, from the yield stress a, the engineering stress UTS and strain
    at UTS, as Radioss works them out: the true stress and strain at UTS lie on the curve
    where it starts necking (Considere: d sigma / d eps = sigma), n = sigma ln(1 + e) /
    (sigma - a); above n = 1, the line through the yield point and UTS (Radioss's)."""
    line = card.lines[3]
    if uts <= a or strain <= 0:
        card.fail(f"Iflag 1: UTS = {uts:g} must be above the yield stress {a:g} and the strain "
                  f"at UTS ({strain:g}) above 0", line)  # fmt: skip
    true_stress, true_strain = uts * (1 + strain), math.log(1 + strain)
    n = true_stress * true_strain / (true_stress - a)
    b = true_stress / (n * true_strain ** (n - 1))
    if n > 1:
        n = 1.0
        b = (true_stress - a) / (true_strain - true_stress / E - a / E)
        deck.warn(card, "Iflag 1: the exponent from UTS is above 1: linear hardening through the "
                  "yield point and UTS, as Radioss", line)  # fmt: skip
    return b, n


def _tabulated(card: Card, units: UnitSystem) -> dict:
    """/MAT/LAW36 with one function and no rate, pressure or modulus dependence: a
    tabulated hardening curve, the element deleted at EPS_p_max."""
    stress = units.factor("stress")
    E, nu, eps_max, eps_t, eps_m = card.read(2, "f:E f:nu f:EPS_p_max f:EPS_t f:EPS_m",
                                             "E nu EPS_p_max EPS_t EPS_m")  # fmt: skip
    for name, value in (("EPS_t", eps_t), ("EPS_m", eps_m)):
        if not inactive(value):
            card.fail(f"{name} = {value:g}: rwall_fem has no failure by tensile strain (with "
                      "damage); leave it blank (EPS_p_max, the failure plastic strain, is "
                      "read)", card.lines[2])  # fmt: skip
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
    return {"young": E * stress, "poisson": nu, "curve": fct, "raw_young": E,
            "curve_scale": (scale or 1.0) * stress, "curve_where": card.lines[5].where,
            **_failure_strain(card, "EPS_p_max", eps_max, card.lines[2])}  # fmt: skip


STARTER = {f"MAT/{keyword}": _material for keyword in LAWS} | {"MAT": _other_material}
STARTER |= {"MAT/VOID": _void, "MAT/LAW0": _void}
