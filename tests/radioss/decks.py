"""Radioss decks written for the tests: a bar of hexahedra and the cards around it, in any
unit system, with the scene a user would write by hand for the same model (in SI).

The deck's numbers are the SI values divided by the unit system's factors (computed here
by hand from the unit sizes, independently of rwall_fem.radioss.units); fields are fixed
columns of 10 (integers) and 20 (reals) characters, as Radioss writes them.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

# name: (mass kg, length m, time s) of each unit system in common use
UNITS = {
    "kg-mm-ms": ((1.0, 1e-3, 1e-3), ("kg", "mm", "ms")),
    "Mg-mm-s": ((1e3, 1e-3, 1.0), ("Mg", "mm", "s")),
    "g-mm-ms": ((1e-3, 1e-3, 1e-3), ("g", "mm", "ms")),
    "SI": ((1.0, 1.0, 1.0), ("kg", "m", "s")),
}
# dimension (mass, length, time) of each quantity
DIM = {
    "length": (0, 1, 0), "time": (0, 0, 1), "mass": (1, 0, 0), "velocity": (0, 1, -1),
    "acceleration": (0, 1, -2), "density": (1, -3, 0), "stress": (1, -1, -2), "rate": (0, 0, -1),
}  # fmt: skip


def f20(x: float) -> str:
    text = f"{x:.14g}"
    return text.rjust(20)


def i10(n: int) -> str:
    return f"{n:10d}"


@dataclass
class BarDeck:
    """A bar [0, nx h] x [0, ny h] x [z0, z0 + nz h] of hexahedra (SI values), in units."""

    units: str = "SI"
    h: float = 1e-3
    nx: int = 2
    ny: int = 2
    nz: int = 8
    z0: float = 0.0
    cards: list[str] = field(default_factory=list)  # extra starter cards (in deck units)
    engine: list[str] = field(default_factory=list)
    end_time: float = 2e-5
    extra_nodes: list[tuple[int, tuple[float, float, float]]] = field(default_factory=list)
    front: int = 0  # layers from z0 whose bricks are the part front_part's (0: none)
    front_part: int = 2

    @property
    def sizes(self):
        return UNITS[self.units][0]

    def q(self, value: float, quantity: str) -> float:
        """An SI value of ``quantity`` in the deck's units."""
        mass, length, time = self.sizes
        a, b, c = DIM[quantity]
        return value / (mass**a * length**b * time**c)

    def node_id(self, i: int, j: int, k: int) -> int:
        return 1 + i + (self.nx + 1) * (j + (self.ny + 1) * k)

    def face_nodes(self, k: int) -> list[int]:
        """The node IDs of the layer k (k = 0: the bottom face)."""
        return [self.node_id(i, j, k) for j in range(self.ny + 1) for i in range(self.nx + 1)]

    def write(self, directory: Path, name: str = "model", one_file: str = "") -> Path:
        """Write the starter NAME_0000.rad and the engine NAME_0001.rad; ``one_file``
        "engine first" (Radioss's single-file input) or "starter first" writes both in
        NAME_0000.rad with /END/ENGINE after the engine's cards."""
        masses, names = UNITS[self.units]
        lines = ["#RADIOSS STARTER", "/BEGIN", name, "      2026"]
        lines += ["".join(n.rjust(20) for n in names)] * 2
        lines.append("/NODE")
        for k in range(self.nz + 1):
            for j in range(self.ny + 1):
                for i in range(self.nx + 1):
                    x = (i * self.h, j * self.h, self.z0 + k * self.h)
                    lines.append(i10(self.node_id(i, j, k)) +
                                 "".join(f20(self.q(c, "length")) for c in x))  # fmt: skip
        for nid, x in self.extra_nodes:
            lines.append(i10(nid) + "".join(f20(self.q(c, "length")) for c in x))
        e = 0
        for k in range(self.nz):
            if k in (0, self.front):
                lines.append(f"/BRICK/{self.front_part if k < self.front else 1}")
            for j in range(self.ny):
                for i in range(self.nx):
                    e += 1
                    n = self.node_id
                    ids = [n(i, j, k), n(i + 1, j, k), n(i + 1, j + 1, k), n(i, j + 1, k),
                           n(i, j, k + 1), n(i + 1, j, k + 1), n(i + 1, j + 1, k + 1),
                           n(i, j + 1, k + 1)]  # fmt: skip
                    lines.append(i10(e) + "".join(i10(q) for q in ids))
        lines += self.cards + ["/END"]
        starter = Path(directory) / f"{name}_0000.rad"
        engine = ["#RADIOSS ENGINE", f"/RUN/{name}/1", f"{self.q(self.end_time, 'time'):.14g}"]
        engine += self.engine
        if one_file == "engine first":
            lines = engine + ["/END/ENGINE"] + lines
        elif one_file == "starter first":
            lines = lines + engine + ["/END/ENGINE"]
        else:
            (Path(directory) / f"{name}_0001.rad").write_text("\n".join(engine + ["/END"]) + "\n")
        starter.write_text("\n".join(lines) + "\n")
        return starter

    def scene_mesh(self) -> dict:
        """The [mesh] table of the same bar, built by gmsh (meshes/bar.geo)."""
        return {"shape": "bar", "origin": [0.0, 0.0, self.z0],
                "size": [self.nx * self.h, self.ny * self.h, self.nz * self.h],
                "element_size": self.h}  # fmt: skip

    # --- cards, in SI arguments --------------------------------------------------------

    def part(self, mat: int = 1, prop: int = 1, pid: int = 1, title: str = "the bar") -> None:
        self.cards += [f"/PART/{pid}", title, "#  prop_ID    mat_ID", i10(prop) + i10(mat)]

    def piece(self, pid: int, x0: float, nz: int, first: int) -> list[int]:
        """A second bar of nx x ny x nz cells of the part ``pid`` beside this one, from
        (x0, 0, z0): node and element IDs from ``first``; returns its node IDs."""
        nodes = {}
        lines = ["/NODE"]
        for k in range(nz + 1):
            for j in range(self.ny + 1):
                for i in range(self.nx + 1):
                    nodes[i, j, k] = first + len(nodes)
                    x = (x0 + i * self.h, j * self.h, self.z0 + k * self.h)
                    lines.append(i10(nodes[i, j, k]) +
                                 "".join(f20(self.q(c, "length")) for c in x))  # fmt: skip
        lines.append(f"/BRICK/{pid}")
        e = first
        for k in range(nz):
            for j in range(self.ny):
                for i in range(self.nx):
                    n = lambda a, b, c: nodes[a, b, c]  # noqa: E731
                    ids = [n(i, j, k), n(i + 1, j, k), n(i + 1, j + 1, k), n(i, j + 1, k),
                           n(i, j, k + 1), n(i + 1, j, k + 1), n(i + 1, j + 1, k + 1),
                           n(i, j + 1, k + 1)]  # fmt: skip
                    lines.append(i10(e) + "".join(i10(q) for q in ids))
                    e += 1
        self.cards += lines
        return list(nodes.values())

    def elastic(self, rho: float, E: float, nu: float, mid: int = 1) -> None:
        self.cards += [f"/MAT/LAW1/{mid}", "elastic", f20(self.q(rho, "density")),
                       f20(self.q(E, "stress")) + f20(nu)]  # fmt: skip

    def johnson_cook(self, rho, E, nu, a, b, n, c=0.0, rate0=0.0, mid=1, keyword="LAW2",
                     eps_max=0.0, sig_max=0.0):  # fmt: skip
        s = lambda v: f20(self.q(v, "stress"))  # noqa: E731
        self.cards += [f"/MAT/{keyword}/{mid}", "Johnson-Cook", f20(self.q(rho, "density")),
                       f20(self.q(E, "stress")) + f20(nu) + i10(0) + i10(0) + f20(0.0),
                       s(a) + s(b) + f20(n) + f20(eps_max) + s(sig_max),
                       f20(c) + f20(self.q(rate0, "rate")) + i10(0) + i10(0) + f20(0) + f20(0),
                       f20(0.0) * 5]  # fmt: skip

    def solid(self, isolid: int = 24, pid: int = 1, icpre: int = 0, h: float = 0.0) -> None:
        self.cards += [f"/PROP/SOLID/{pid}", "solid",
                       i10(isolid) + i10(0) + i10(0) + i10(icpre) + i10(0) * 4 + f20(0.0),
                       f20(0.0) * 2 + f20(h) + f20(0.0) * 2]  # fmt: skip

    def group(self, gid: int, kind: str, ids: list[int]) -> None:
        rows = [ids[k : k + 10] for k in range(0, len(ids), 10)]
        self.cards += [f"/GRNOD/{kind}/{gid}", f"group {gid}"]
        self.cards += ["".join(i10(n) for n in row) for row in rows]

    def box(self, bid: int, low, high) -> None:
        self.cards += [f"/BOX/RECTA/{bid}", "box", i10(0) * 3,
                       "".join(f20(self.q(c, "length")) for c in low),
                       "".join(f20(self.q(c, "length")) for c in high)]  # fmt: skip

    def initial_velocity(self, v, group: int, iid: int = 1) -> None:
        self.cards += [f"/INIVEL/TRA/{iid}", "impact",
                       "".join(f20(self.q(c, "velocity")) for c in v) + i10(group) + i10(0),
                       f20(0.0) + i10(0)]  # fmt: skip

    def function(self, fid: int, points) -> None:
        """Points (x, y) written as they are: the card using it scales them."""
        self.cards += [f"/FUNCT/{fid}", f"function {fid}"]
        self.cards += [f20(x) + f20(y) for x, y in points]

    def imposed_velocity(self, iid: int, fid: int, direction: str, group: int,
                         t_scale: float, v_scale: float) -> None:  # fmt: skip
        """v(t) = v_scale f(t / t_scale), SI scales."""
        self.cards += [f"/IMPVEL/{iid}", "imposed", i10(fid) + direction.rjust(10) + i10(0) * 2
                       + i10(group) + i10(0) * 2,
                       f20(self.q(t_scale, "time")) + f20(self.q(v_scale, "velocity"))]  # fmt: skip

    def gravity(self, gid: int, fid: int, direction: str, group: int, g: float) -> None:
        self.cards += [f"/GRAV/{gid}", "gravity",
                       i10(fid) + direction.rjust(10) + i10(0) * 2 + i10(group) + i10(0),
                       f20(0.0) + f20(self.q(g, "acceleration"))]  # fmt: skip

    def clamp(self, bid: int, code: str, group: int) -> None:
        self.cards += [f"/BCS/{bid}", "clamp", code.rjust(10) + i10(0) + i10(group)]

    def wall(self, kind: str, wid: int = 1, *, point=(0.0, 0.0, 0.0), m1=None, m2=None,
             slide: int = 0, add: int = 0, exclude: int = 0, dsearch: float = 0.0,
             friction: float = 0.0, diameter: float = 0.0, ffac: float = 0.0, ifq: int = 0,
             node: int = 0, mass: float = 0.0, velocity=(0.0, 0.0, 0.0)) -> None:  # fmt: skip
        L = lambda v: f20(self.q(v, "length"))  # noqa: E731
        lines = [f"/RWALL/{kind}/{wid}", f"wall {wid}",
                 i10(node) + i10(slide) + i10(add) + i10(exclude) + i10(0),
                 L(dsearch) + f20(friction) + L(diameter)
                 + f20(self.q(ffac, "rate") if ifq == 3 else ffac) + i10(ifq)]  # fmt: skip
        if node:
            lines.append(f20(self.q(mass, "mass"))
                         + "".join(f20(self.q(c, "velocity")) for c in velocity))  # fmt: skip
        else:
            lines.append("".join(L(c) for c in point))
        for p in (m1, m2):
            if p is not None:
                lines.append("".join(L(c) for c in p))
        self.cards += lines

    def dt_scale(self, scale: float) -> None:
        self.engine += ["/DT", f"{scale} 0.0"]


def steel() -> dict:
    return {"density": 7850.0, "young": 210e9, "poisson": 0.3}


def wave_time(h: float, nz: int) -> float:
    return 2 * nz * h / math.sqrt(210e9 / 7850.0)
