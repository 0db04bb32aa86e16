"""What a starter card that no family reads is, for the one line that refuses it: the
physics it asks for and what rwall_fem reads instead."""

from __future__ import annotations

__all__ = ["refusal"]

_WHY = {
    "element": "elements of this kind are not read: rwall_fem's elements are /BRICK (hexahedra) "
    "and /TETRA4 (tetrahedra)",
    "kinematic": "kinematic conditions of this kind are not read: /BCS and /IMPVEL are",
    "load": "loads and initial states of this kind are not read: /INIVEL/TRA, /BCS, /IMPVEL, "
    "/GRAV, /CLOAD, /PLOAD and /ADMAS are",
    "fluid": "ALE, SPH, fluids and heat are not read: rwall_fem's solids are Lagrangian",
    "option": "this option is not read",
}
# A card's keyword (or first two) -> what it asks for.
KINDS = {
    **dict.fromkeys(("SHELL", "SH3N", "BEAM", "SPRING", "TRUSS", "QUAD", "TRIA", "BRIC20",
                     "TETRA10", "PENTA6", "SHEL16", "SPHCEL", "XELEM"), "element"),
    **dict.fromkeys(("RBE2", "RBE3", "RLINK", "CYL_JOINT", "GJOINT", "MERGE", "MPC",
                     "BCS/CYCLIC", "BCS/LAGMUL"), "kinematic"),
    **dict.fromkeys(("LOAD", "IMPDISP", "IMPACC", "PBLAST", "PFLUID",
                     "INIVEL/ROT", "INIVEL/AXIS", "INISTA", "INIBRI", "INIGRAV", "REFSTA",
                     "PRELOAD"), "load"),
    **dict.fromkeys(("ALE", "EULER", "EBCS", "SPH", "SPHBCS", "MONVOL", "AIRBAG", "EOS", "LEAK",
                     "THERM", "HEAT", "CONVEC", "RADIATION", "DFS"), "fluid"),
    **dict.fromkeys(("AMS", "PERTURB", "ENCRYPT", "PARAMETER", "TRANSFORM", "DRAPE", "ADMESH",
                     "FXBODY", "EIG", "OPTIMIZATION"), "option"),
}  # fmt: skip


def refusal(card) -> str | None:
    """Why ``card`` is refused when its keyword names physics not read here; None for a
    keyword unknown to this table."""
    for key in (f"{card.key(0)}/{card.key(1)}", card.key(0)):
        if key in KINDS:
            return _WHY[KINDS[key]]
    return None
