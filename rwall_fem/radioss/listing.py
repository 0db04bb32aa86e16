"""What Radioss's starter listing (``NAME_0000.out``) tells a user first, for
``rwall-fem check NAME_0000.rad``: each part's elements, mass and material, and the
smallest element time steps and where they are, worked out from the deck alone.

A cell's step is its stable estimate ``L / c`` at rest, the one the run starts from
(``docs/theory.md``): ``L`` its volume over its largest face area (a tetrahedron: three
times that), ``c`` the dilatational wave speed of its material,
``sqrt(E (1 - nu) / (rho (1 + nu) (1 - 2 nu)))``; a shell's ``L`` is Radioss's L_c and
``c`` Radioss's shell sound speed ``sqrt(E / rho)``, its mass rho t A. The volume of a
hexahedron is the 2 x 2 x 2 Gauss integral of its Jacobian, exact for the trilinear map.
"""

from __future__ import annotations

import numpy as np

from rwall_fem.radioss.model import Deck

__all__ = ["SMALLEST", "cell_geometry", "shell_geometry", "starter_listing"]

SMALLEST = 5  # the smallest steps listed, as Radioss lists its ten smallest

_G = 1 / np.sqrt(3)
_CORNERS = np.array([[-1, -1, -1], [1, -1, -1], [1, 1, -1], [-1, 1, -1],
                     [-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]], dtype=float)  # fmt: skip
_HEX_FACES = np.array([[0, 3, 2, 1], [0, 1, 5, 4], [0, 4, 7, 3], [1, 2, 6, 5], [2, 3, 7, 6],
                       [4, 5, 6, 7]])  # fmt: skip
_TET_FACES = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])


def cell_geometry(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Volumes (m^3) and characteristic lengths (m) of cells at ``x`` (n, 8 or 4, 3)."""
    if x.shape[1] == 4:
        volume = np.einsum("ij,ij->i", np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]),
                           x[:, 3] - x[:, 0]) / 6  # fmt: skip
        f = x[:, _TET_FACES]
        area = np.linalg.norm(np.cross(f[:, :, 1] - f[:, :, 0], f[:, :, 2] - f[:, :, 0]), axis=2)
        return volume, 3 * volume / (area.max(axis=1) / 2)
    volume = np.zeros(len(x))
    for point in _CORNERS * _G:
        # d N_I / d xi of the trilinear shape functions at the Gauss point.
        grad = _CORNERS * np.prod(1 + _CORNERS * point, axis=1)[:, None] / 8
        grad = grad / (1 + _CORNERS * point)
        j = np.einsum("nia,ib->bna", x, grad)  # the Jacobian's columns d x / d xi_b
        volume += np.einsum("na,na->n", j[0], np.cross(j[1], j[2]))
    f = x[:, _HEX_FACES]
    area = np.linalg.norm(np.cross(f[:, :, 2] - f[:, :, 0], f[:, :, 3] - f[:, :, 1]), axis=2) / 2
    return volume, volume / area.max(axis=1)


def shell_geometry(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Areas (m^2) and characteristic lengths (m) of shells at ``x`` (n, 4 or 3, 3; nodes
    in Radioss's order, around the cell): half the norm of the cross product of the
    diagonals (of the sides of a triangle), and Radioss's L_c, a quadrilateral's
    max(A / longest diagonal, shortest side or diagonal), a triangle's 2 A / longest side."""
    count = x.shape[1]
    sides = np.linalg.norm(x - np.roll(x, -1, axis=1), axis=2)
    if count == 3:
        area = np.linalg.norm(np.cross(x[:, 1] - x[:, 0], x[:, 2] - x[:, 0]), axis=1) / 2
        return area, 2 * area / sides.max(axis=1)
    d1, d2 = x[:, 2] - x[:, 0], x[:, 3] - x[:, 1]
    area = np.linalg.norm(np.cross(d1, d2), axis=1) / 2
    diagonals = np.column_stack([np.linalg.norm(d1, axis=1), np.linalg.norm(d2, axis=1)])
    shortest = np.minimum(sides.min(axis=1), diagonals.min(axis=1))
    return area, np.maximum(area / diagonals.max(axis=1), shortest)


def _wave_speed(m: dict) -> float:
    E, nu, rho = m["young"], m["poisson"], m["density"]
    return float(np.sqrt(E * (1 - nu) / (rho * (1 + nu) * (1 - 2 * nu))))


def starter_listing(deck: Deck, dt_scale: float) -> list[str]:
    """Lines of a starter listing: a table of the parts (elements, mass, material, the
    smallest step and its element) and the smallest element steps over the deck, with
    the run's first step, ``dt_scale`` x the smallest."""
    lines = ["parts (as Radioss's starter lists them):",
             f"  {'part':>10}  {'elements':>18}  {'mass (kg)':>12}  {'material':<34}  "
             f"{'smallest L/c (s)':>16}  at element"]  # fmt: skip
    steps, elements_of = [], []  # per element card: steps, and (card, part, IDs, centres)
    for pid in sorted({b.part for b in deck.bodies}):
        bodies = [b for b in deck.bodies if b.part == pid]
        part = deck.parts[pid]
        material = deck.materials[part.mat]
        speed = _wave_speed(material)
        counts, mass, smallest = {}, 0.0, (np.inf, 0)
        for body in bodies:
            rows = deck.node_positions(body.nodes.ravel())
            x = deck.coordinates[rows].reshape(*body.nodes.shape, 3)
            if body.cell in ("quadrilateral", "triangle"):  # Radioss's shell speed
                area, length = shell_geometry(x)
                volume = area * deck.properties[part.prop]["element"]["thickness"]
                speed = float(np.sqrt(material["young"] / material["density"]))
            else:
                volume, length = cell_geometry(x)
            name = body.card.key(0)
            counts[name] = counts.get(name, 0) + len(body.ids)
            mass += material["density"] * float(volume.sum())
            dt = length / speed
            k = int(np.argmin(dt))
            smallest = min(smallest, (float(dt[k]), int(body.ids[k])))
            steps.append(dt)
            elements_of.append((name, pid, body.ids, x))
        elements = ", ".join(f"{n} /{k}" for k, n in counts.items())
        law = f"/MAT/{material['law']}/{part.mat} {material['title'][:18]}".strip()
        lines.append(f"  {pid:>10}  {elements:>18}  {mass:>12.6g}  {law:<34}  "
                     f"{smallest[0]:>16.4g}  {smallest[1]}")  # fmt: skip
    dt = np.concatenate(steps)
    order = np.argsort(dt, kind="stable")[:SMALLEST]
    lines.append(f"the {len(order)} smallest element steps L/c (the run starts at about "
                 f"{dt_scale:g} x the smallest, {dt_scale * dt[order[0]]:.4g} s):")  # fmt: skip
    starts = np.cumsum([0] + [len(ids) for _, _, ids, _ in elements_of])
    for k in order:
        j = int(np.searchsorted(starts, k, side="right")) - 1
        name, pid, ids, x = elements_of[j]
        at = ", ".join(f"{c:.4g}" for c in x[k - starts[j]].mean(axis=0))
        lines.append(f"  {dt[k]:.4g} s: element {ids[k - starts[j]]} (/{name}, part {pid}) "
                     f"at ({at}) m")  # fmt: skip
    return lines
