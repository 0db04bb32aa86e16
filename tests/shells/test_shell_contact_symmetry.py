"""A model of shells cut by symmetry planes meets itself and other parts as the whole does.

A doubly curved steel cap (12 x 12 mm, z = z0 + (x^2 + y^2) / 2R, R = 20 mm, shells of
1 mm, 1 mm thick) falls at 10 m/s onto a flat 20 x 20 mm aluminium plate (1 mm shells,
1 mm thick) whose rim is clamped; one [[contact]] between them (both passes), or the two
as one self-contact surface. The cap touches at its apex, on the axis, and the contact
spreads outward as the plate dishes and the cap flattens: nodes on the planes x = 0 and
y = 0 bear on segments whose closest points are off the planes. The half (x >= 0: u_x = 0
and the rotations about y and z held on x = 0) and the quarter (x, y >= 0, likewise on
y = 0) must give a half and a quarter of the whole model's contact impulse, kinetic,
internal and contact energies and friction dissipation. Reference: the whole model itself
(symmetry).

Without care they do not: a node on a plane holds half the whole node's mass (a quarter
on two), but met its segment with the whole stiffness E t of the segment (the whole
node's spring on half its mass), along a normal leaning out of the plane, which the
symmetry condition cut. Now such a node acts with its share of the whole node
(``docs/theory.md``, "Symmetry planes"), as a solid's node does.

Before, the half and the quarter were 1e-3 off the whole (3e-3 of the plate's momentum,
5e-3 of the internal energy with triangles), and at the whole model's step of 1e-7 s the
half stopped at step 71 on the step guard: its plane nodes' springs on half masses. Now
they equal the whole to 1e-11 (1.2e-13 measured), on 1 and 2 ranks.

The meshes are written here node by node, the cut models' nodes being exactly the whole
model's (x^2 + y^2 is exact under x -> -x) and each mirrored cell keeping its nodes'
order, so that nothing but the order of the sums separates the models (the
Belytschko-Stolarski-Carpenter triangle depends on which node comes first by about 1e-7
of the energies). All take one fixed step, 5e-8 s (below every stable step; the
automatic step of a cut model differs from the whole's: see test_contact_symmetry.py).
"""

import numpy as np
import pytest
from conftest import run
from mpi4py import MPI

comm = MPI.COMM_WORLD

STEEL = {"model": "linear_elastic", "density": 7850.0, "young": 200e9, "poisson": 0.3}
ALUMINIUM = {"model": "linear_elastic", "density": 2700.0, "young": 70e9, "poisson": 0.33}
H = 1e-3  # m: the cells' side
PLATE, CAP, RADIUS = 10, 6, 0.02  # the plate's and the cap's half width (cells), R (m)
LIFT = 0.9e-3  # m: the cap's apex above the plate (the gap is 0.8 mm: 0.4 mm per shell)
SPEED, END, DT = 10.0, 6e-5, 5e-8  # m/s, s, s


def sheet(n: int, cut_x: bool, cut_y: bool, triangles: bool):
    """The nodes (integer grid coordinates i, j) and cells of a square sheet of n cells
    each way from the centre lines, on the sides x >= 0 (``cut_x``) or y >= 0 (``cut_y``)
    only or on both sides of them: the cells of the quarter i, j >= 0 (quadrilaterals
    counter-clockwise from +z, or each split along its diagonal from the corner nearer the
    centre) and their mirror images, each node of a mirror image in its cell's order."""
    i, j = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    i, j = i.ravel(), j.ravel()
    corners = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)]
    order = ((0, 1, 2), (0, 2, 3)) if triangles else ((0, 1, 2, 3),)
    quarter = np.concatenate([np.stack([np.column_stack(corners[k]) for k in cell], axis=1)
                              for cell in order])  # (cells, corners, 2)  # fmt: skip
    signs = [(sx, sy) for sx in ((1,) if cut_x else (1, -1)) for sy in ((1,) if cut_y else (1, -1))]
    cells = np.concatenate([quarter * np.array(sign) for sign in signs])
    grid, conn = np.unique(cells.reshape(-1, 2), axis=0, return_inverse=True)
    return grid, conn.reshape(len(cells), -1)


def write_msh(path, cut_x: bool, cut_y: bool, triangles=False) -> None:
    """The plate and the cap as a gmsh 2.2 file: the physical surfaces "plate" and "cap",
    the curves "rim" (the plate's outer edges), "cut_x" and "cut_y" (the edges on x = 0
    and y = 0: of a cut model, its cuts; of the whole, its centre lines)."""
    nodes, cells, lines = [], [], []
    for part, (n, tag) in enumerate(((PLATE, 1), (CAP, 2))):
        grid, conn = sheet(n, cut_x, cut_y, triangles)
        x, y = grid[:, 0] * H, grid[:, 1] * H
        z = np.zeros_like(x) if part == 0 else LIFT + (x * x + y * y) / (2 * RADIUS)
        base = len(nodes)
        nodes += list(zip(x, y, z, strict=True))
        cells += [(tag, base + row) for row in conn]
        ids = base + np.arange(len(grid)).reshape(-1)
        at = {tuple(g): k for k, g in zip(ids, grid, strict=True)}
        i0 = 0 if cut_x else -n
        j0 = 0 if cut_y else -n

        def edge(points, group):
            for p, q in zip(points[:-1], points[1:], strict=True):
                lines.append((group, at[p], at[q]))

        if part == 0:  # the rim: the outer edges
            edge([(n, j) for j in range(j0, n + 1)], 3)
            edge([(i, n) for i in range(i0, n + 1)], 3)
            if not cut_x:
                edge([(-n, j) for j in range(j0, n + 1)], 3)
            if not cut_y:
                edge([(i, -n) for i in range(i0, n + 1)], 3)
        edge([(0, j) for j in range(j0, n + 1)], 4)  # a cut, or the whole's centre line
        edge([(i, 0) for i in range(i0, n + 1)], 5)
    names = [(2, 1, "plate"), (2, 2, "cap"), (1, 3, "rim"), (1, 4, "cut_x"), (1, 5, "cut_y")]
    out = ["$MeshFormat", "2.2 0 8", "$EndMeshFormat", "$PhysicalNames", str(len(names))]
    out += [f'{d} {t} "{name}"' for d, t, name in names]
    out += ["$EndPhysicalNames", "$Nodes", str(len(nodes))]
    out += [f"{k + 1} {x:.17g} {y:.17g} {z:.17g}" for k, (x, y, z) in enumerate(nodes)]
    out += ["$EndNodes", "$Elements", str(len(lines) + len(cells))]
    k = 0
    for group, p, q in lines:
        k += 1
        out.append(f"{k} 1 2 {group} {group} {p + 1} {q + 1}")
    for tag, row in cells:
        k += 1
        kind = 2 if len(row) == 3 else 3
        out.append(f"{k} {kind} 2 {tag} {tag} " + " ".join(str(v + 1) for v in row))
    out.append("$EndElements")
    path.write_text("\n".join(out) + "\n")


def scene(directory, cuts: str, contact: dict, triangles=False) -> dict:
    """The cap on the plate, cut by the planes ``cuts`` (some of "xy")."""
    path = directory / "cap.msh"
    if comm.rank == 0:
        write_msh(path, "x" in cuts, "y" in cuts, triangles)
    comm.Barrier()
    raw = {
        "run": {"end_time": END, "dt": DT},
        "mesh": {"file": str(path)},
        "material": STEEL,
        "element": {"thickness": 1e-3},
        "part": [
            {"name": "plate", "material": ALUMINIUM},
            {"name": "cap", "initial": {"velocity": [0.0, 0.0, -SPEED]}},
        ],
        "boundary": [{"group": "rim", "components": "xyz", "rotations": "xyz"}],
        "contact": [contact],
        "output": {"plot": False},
    }
    for c in cuts:
        others = "".join(a for a in "xyz" if a != c)
        raw["boundary"].append({"group": f"cut_{c}", "components": c, "rotations": others})
    return raw


CONTACTS = {
    "two_parts": {"main": ["plate"], "secondary": ["cap"]},
    "two_parts_friction": {"main": ["plate"], "secondary": ["cap"], "friction": 0.3},
    "self_friction": {"self": True, "friction": 0.3},
}


def books(directory, cuts: str, contact: dict, triangles=False) -> dict:
    """The whole model's share of the run's contact impulse and parts' momenta (N s, along
    z) and energies (J)."""
    sim = run(scene(directory, cuts, contact, triangles), directory)
    s = sim.history.summary
    share = 2.0 ** len(cuts)
    energy = {k: share * v for k, v in s["energy"].items()
              if k != "max_balance_error" and isinstance(v, float)}  # fmt: skip
    momenta = {f"{p['name']}_momentum": share * p["momentum"][2] for p in s["parts"]}
    return {"impulse": share * s["contacts"][0]["impulse"][2], **momenta, **energy,
            "balance": s["energy"]["max_balance_error"]}  # fmt: skip


def errors(part: dict, whole: dict) -> dict:
    """The differences of ``part``'s books from ``whole``'s, relative to the cap's initial
    momentum (impulse, momenta) or the whole's kinetic + internal energy."""
    momentum = 7850.0 * 1e-3 * (2 * CAP * H) ** 2 * SPEED
    energy = whole["kinetic"] + whole["internal"]
    return {key: abs(part[key] - whole[key]) / (energy if key in ENERGIES else momentum)
            for key in whole if key != "balance"}  # fmt: skip


ENERGIES = ("initial", "kinetic", "rotational_kinetic", "internal", "hourglass",
            "contact_energy", "contact_friction", "external_work", "wall_work")  # fmt: skip


@pytest.mark.parametrize("triangles", [False, True], ids=["quadrilaterals", "triangles"])
@pytest.mark.parametrize("name", list(CONTACTS))
def test_a_half_and_a_quarter_meet_as_the_whole(tmp_path_factory, name, triangles):
    """The half's and the quarter's books x 2 and x 4 equal the whole model's to 1e-9;
    the contact acted (the cap turns back) and the books close."""

    def folder(tag):
        return comm.bcast(tmp_path_factory.mktemp(tag) if comm.rank == 0 else None, root=0)

    contact = CONTACTS[name]
    whole = books(folder("whole"), "", contact, triangles)
    print(f"whole: cap momentum {whole['cap_momentum']:.6e} N s")
    assert whole["cap_momentum"] > 0.0  # the contact turned the cap back
    assert whole["balance"] <= 1e-10
    worst = {}
    for cuts in ("x", "xy"):
        part = books(folder(cuts), cuts, contact, triangles)
        assert part["balance"] <= 1e-10
        worst[cuts] = errors(part, whole)
        print(cuts, ", ".join(f"{k} {v:.1e}" for k, v in worst[cuts].items()))
    for cuts, found in worst.items():
        for key, error in found.items():
            assert error <= 1e-11, (cuts, key)


@pytest.mark.parametrize("erode", [False, True], ids=["kept", "eroding"])
def test_the_nodes_on_the_planes_and_only_they_act_as_shares(shared_dir, erode):
    """The quarter's nodes on x = 0 or y = 0 (the plate's 21, the cap's 13) hold their
    share of the whole node, 1/2, and the two on both planes 1/4, also when the shells may
    erode (the surfaces then follow the erosion); a sheet lying in a plane whose edge is
    held in that plane's normal with its rotations (a sliding clamp: the plate's rim held
    in z, its rotations about x and y held) is not cut there, nor is the whole model along
    its centre lines held so (shells on both sides of them): nothing acts as a share."""
    from rwall_fem import build_simulation, parse_scene

    def shares(raw):
        if erode:
            raw["run"] = {"end_time": END, "dt_min": 1e-12, "dt_min_action": "erode"}
        sim = build_simulation(parse_scene(raw, source="test"), comm, shared_dir)
        eroding = type(sim.contacts[0]).__name__ == "ErodingContact"
        assert eroding == erode
        mirrored = sim.contacts[0].mirrored
        if mirrored is None:
            return {}
        share, planes = mirrored
        counted = {(s, p): comm.allreduce(int(np.sum((share == s) & (planes == p))))
                   for s, p in ((0.5, 1), (0.5, 2), (0.25, 3))}  # fmt: skip
        return counted | {"others": comm.allreduce(int(np.sum((share < 1.0) & (planes == 0))))}

    quarter = scene(shared_dir, "xy", CONTACTS["two_parts"])
    assert shares(quarter) == {(0.5, 1): 10 + 6, (0.5, 2): 10 + 6, (0.25, 3): 2, "others": 0}
    sliding = scene(shared_dir, "", CONTACTS["two_parts"])
    sliding["boundary"] = [{"group": "rim", "components": "z", "rotations": "xy"}]
    assert shares(sliding) == {}
    whole = scene(shared_dir, "", CONTACTS["two_parts"])
    whole["boundary"] += [{"group": f"cut_{c}", "components": c,
                           "rotations": "".join(a for a in "xyz" if a != c)} for c in "xy"]
    assert shares(whole) == {}
