"""A deck's /MAT and /PROP/SOLID as the scene's ``[material]`` and ``[element]`` tables
(SI units), with a line saying what each became; where the two codes differ without a
refusal, a warning is added to the deck's."""

from __future__ import annotations

import numpy as np

from rwall_fem.radioss.model import Deck
from rwall_fem.radioss.reader import DeckError

__all__ = ["element_table", "material_table"]


def material_table(deck: Deck, mid: int) -> tuple[dict, str]:
    """The [material] table of /MAT ``mid`` and the line saying what it became, with its
    [material.failure]: the law's failure plastic strain (EPS_p_max), or /FAIL/JOHNSON."""
    material, fact = _law_table(deck, mid)
    m, fail = deck.materials[mid], deck.failures.get(mid)
    own = m.get("failure")
    if own and fail:
        raise DeckError(f"{fail['where']}: {fail['card']}: material {mid} has a failure plastic "
                        f"strain already (EPS_p_max of {m['where']}): one failure criterion per "
                        "material here")  # fmt: skip
    failure = own or fail
    if failure is None:
        return material, fact
    if material["model"] == "linear_elastic":
        deck.warnings.append(f"{fail['where']}: {fail['card']}: material {mid} is elastic (no "
                             "plastic strain): it never fails; not used")  # fmt: skip
        return material, fact
    table = {k: v for k, v in failure.items() if k not in ("where", "card") and v is not None}
    if own:
        how = f"eroded at plastic strain {own['plastic_strain']:g} (EPS_p_max)"
    else:
        how = f"Johnson-Cook failure D1-D5 ({fail['card']}, {fail['where']})"
    return material | {"failure": table}, f"{fact}, {how}"


def _law_table(deck: Deck, mid: int) -> tuple[dict, str]:
    """The [material] table of /MAT ``mid`` without failure, and its line."""
    m = deck.materials[mid]
    table = {"density": m["density"], "young": m["young"], "poisson": m["poisson"]}
    head = f"material: /MAT/{m['law']}/{mid} ({m['where']})"
    if m["law"] == "LAW1":
        return {"model": "linear_elastic", **table}, f"{head} -> linear_elastic"
    if m["law"] == "LAW36":
        fct = deck.functions.get(m["curve"])
        if fct is None:
            raise DeckError(f"{m['curve_where']}: /MAT/LAW36/{mid}: fct_ID1 {m['curve']} "
                            "refers to no /FUNCT")  # fmt: skip
        if fct.x[0] != 0.0 or len(fct.x) > 64 or np.any(fct.y <= 0):
            raise DeckError(f"{fct.where}: /FUNCT/{fct.id}: a hardening curve starts at plastic "
                            "strain 0, has at most 64 points and positive stresses")  # fmt: skip
        rows = [[float(x), float(y * m["curve_scale"])] for x, y in zip(fct.x, fct.y, strict=True)]
        if fct.y[-1] != fct.y[-2]:
            deck.warnings.append(
                f"{fct.where}: /FUNCT/{fct.id}: rwall_fem holds the yield stress after the last "
                f"point (plastic strain {fct.x[-1]:g}); Radioss extends the last slope"
            )
        material = {"model": "elastic_plastic", **table, "hardening": "table",
                    "hardening_curve": rows}  # fmt: skip
        return material, f"{head} -> elastic_plastic, tabulated hardening ({len(rows)} points)"
    a, b, n = m["a"], m["b"], m["n"]
    if "cap" in m:  # SIG_max0
        table |= {"max_flow_stress": m["cap"]}
        head = f"{head} (flow stress capped at {m['cap']:g} Pa, SIG_max0)"
    if "c" in m or "t_melt" in m:
        material = {"model": "johnson_cook", **table, "yield_stress": a,
                    "hardening_coefficient": b, "hardening_exponent": n}  # fmt: skip
        if "c" in m:
            material |= {"strain_rate_coefficient": m["c"], "reference_strain_rate": m["rate0"]}
        if "t_melt" in m:
            material["heating"] = {
                "softening_exponent": m["m"], "melting_temperature": m["t_melt"],
                "specific_heat": m["heat"] / m["density"], "room_temperature": m["t_room"],
                "taylor_quinney": 1.0,
            }  # fmt: skip
        return material, f"{head} -> johnson_cook"
    if n == 1.0:
        material = {"model": "elastic_plastic", **table, "hardening": "linear",
                    "yield_stress": a, "hardening_modulus": b}  # fmt: skip
        return material, f"{head} -> elastic_plastic, linear hardening"
    material = {"model": "elastic_plastic", **table, "hardening": "power", "yield_stress": a,
                "hardening_coefficient": b, "hardening_exponent": n}  # fmt: skip
    return material, f"{head} -> elastic_plastic, power hardening"


def element_table(deck: Deck, pid: int, cell: str, material: dict, cells) -> tuple[dict, str]:
    """The [element] table of /PROP/SOLID ``pid`` for ``cells`` (node IDs) of type ``cell``
    in ``material`` (a [material] table), and the line saying what it became."""
    p = deck.properties[pid]
    shells = cell in ("quadrilateral", "triangle")
    if shells != (p.get("kind") == "shell"):
        elements = "/SHELL, /SH3N" if shells else "/BRICK, /TETRA4"
        card = "/PROP/SOLID or /PROP/TYPE14" if not shells else "/PROP/SHELL or /PROP/TYPE1"
        raise DeckError(f"{p['where']}: property {pid} is not a property of {elements} "
                        f"elements: give them a {card}")  # fmt: skip
    if shells:
        from rwall_fem.radioss.cards.shells import shell_element

        return shell_element(deck, pid, cell, material["poisson"])
    head = f"property: /PROP/SOLID/{pid} Isolid {p['isolid']} ({p['where']})"
    if cell == "tetrahedron":
        if p["itetra4"]:  # the column is Irot of bricks before version 12
            raise DeckError(f"{p['line']}: /PROP/SOLID/{pid}: Itetra4 = {p['itetra4']}: "
                            "tetrahedra are one-point P1 elements (Itetra4 0)")  # fmt: skip
        return {}, f"{head} -> P1 tetrahedra (Itetra4 0)"
    element = dict(p["element"])
    plastic = material["model"] in ("elastic_plastic", "johnson_cook")
    if p["isolid"] == 24 and plastic and p["icpre"] == 0:
        deck.warnings.append(
            f"{p['line']}: /PROP/SOLID/{pid}: Icpre 0 on an elasto-plastic body: rwall_fem's "
            "physical hourglass control has no volumetric part on plastic bodies (as Icpre 1)"
        )
    if p["isolid"] == 2 and not _parallelepipeds(deck, cells):
        deck.warnings.append(
            f"{p['line']}: /PROP/SOLID/{pid}: Isolid 2 (Hallquist's hourglass modes) is read "
            "as Isolid 1 (orthogonal Flanagan-Belytschko modes): they differ on cells that "
            "are not parallelepipeds"
        )
    text = ", ".join(f"{k} {v}" for k, v in element.items())
    return element, f"{head} -> {text}"


def _parallelepipeds(deck: Deck, cells) -> bool:
    """Whether every hexahedron is a parallelepiped (no hourglass part in its shape)."""
    x = deck.coordinates[deck.node_positions(cells.ravel())].reshape(len(cells), 8, 3)
    h = np.array([[1, -1, 1, -1, 1, -1, 1, -1], [1, 1, -1, -1, -1, -1, 1, 1],
                  [1, -1, -1, 1, -1, 1, 1, -1], [-1, 1, -1, 1, 1, -1, 1, -1]])  # fmt: skip
    size = np.ptp(x, axis=1).max()
    return bool(np.abs(np.einsum("ai,cid->cad", h, x)).max() <= 1e-9 * size)
