"""The stable step of a run with contact: node by node (docs/theory.md, contact's "Stable
step"), against a hand computation independent of the code.

Two blocks of one column of two hexahedra each (a cube of side h facing the other block,
a thin cell of height t behind it), at rest, their facing faces s apart: farther than the
gap, within the reach (half the cube's thickness), so each pair counts in the step with
its stiffness k0 and no force. Each corner node of a facing face is held by its cube alone:

- its mass m = rho h^3 / 8 (the lumped mass of a rectangular box), the cube's share;
- the cube's stable step dt_e = cal h / c (L = V / A_max = h, c = sqrt(E / rho) at nu = 0,
  cal the run's calibration), so the cells' term e = m / dt_e^2;
- its contact stiffness K = 2 k0: k0 as the secondary node of its pair, and 1 x k0 as the
  corner of the segment the facing node meets at that corner, k0 = B A^2 / V = (E / 3) h
  (B = E / 3 at nu = 0);

hence dt_node = sqrt(m / (e + K / 2)). The thin cells' step is cal t / c. The run's limit
is the smaller of the two; the former global rule, 1 / dt^2 = 1 / dt_e,min^2 +
1 / dt_c^2 with dt_c = sqrt(2 m / K) (the smallest cell anywhere with the stiffest
spring anywhere), is below it.
"""

import math

import pytest
from conftest import run
from mpi4py import MPI

E, RHO = 200e9, 7850.0
C = math.sqrt(E / RHO)  # m/s, the P-wave speed at nu = 0
H, T, S = 0.002, 0.0014, 0.0006  # m: the cube's side, the thin cell's height, the opening


def columns_geo(h: float, t: float, s: float) -> str:
    """Two h x h columns along z: "lower" (a cell of height t, then a cube of side h) and
    "upper" (a cube, then a cell of height t), s apart."""
    lines = []
    for k, (name, z, first) in enumerate((("lower", 0.0, t), ("upper", t + h + s, h))):
        lines += [
            "p = newp;",
            f"Point(p) = {{0, 0, {z}}};",
            f"Point(p + 1) = {{{h}, 0, {z}}};",
            f"Point(p + 2) = {{{h}, {h}, {z}}};",
            f"Point(p + 3) = {{0, {h}, {z}}};",
            "q = newl;",
            *(f"Line(q + {i}) = {{p + {i}, p + {(i + 1) % 4}}};" for i in range(4)),
            "r = newll;",
            "Curve Loop(r) = {q, q + 1, q + 2, q + 3};",
            "f = news;",
            "Plane Surface(f) = {r};",
            "Transfinite Curve {q, q + 1, q + 2, q + 3} = 2;",
            "Transfinite Surface {f};",
            "Recombine Surface {f};",
            f"out{k}[] = Extrude {{0, 0, {t + h}}} {{ Surface{{f}}; "
            f"Layers{{{{1, 1}}, {{{first / (t + h)}, 1}}}}; Recombine; }};",
            f'Physical Volume("{name}") = {{out{k}[1]}};',
        ]
    return "\n".join(lines) + "\n"


def columns_scene(directory) -> dict:
    path = directory / "columns.geo"
    if MPI.COMM_WORLD.rank == 0:
        path.write_text(columns_geo(H, T, S))
    MPI.COMM_WORLD.Barrier()
    return {
        "run": {"end_time": 5e-7},
        "mesh": {"file": str(path)},
        "material": {"model": "linear_elastic", "density": RHO, "young": E, "poisson": 0.0},
        "part": [{"name": "lower"}, {"name": "upper"}],
        "contact": [{"main": ["upper"], "secondary": ["lower"]}],
        "output": {"plot": False},
    }


def test_the_step_of_a_contact_node_is_its_cells_and_springs_together(shared_dir):
    """The run's limit is the corner nodes' sqrt(m / (e + k0)) to 1e-12 (below the thin
    cells' cal t / c), above the former global rule's; the step dt_scale x it rounded down
    to 4 figures; every step alike (nothing moves)."""
    sim = run(columns_scene(shared_dir), shared_dir)
    step = sim.step_size
    assert sim.info["cell"] == "hexahedron"
    cal = step.calibration
    m = RHO * H**3 / 8
    e = m / (cal * H / C) ** 2
    k0 = E / 3 * H
    node = math.sqrt(m / (e + 2 * k0 / 2))
    thin = cal * T / C
    assert node < thin  # the contact nodes set the step
    assert step.limit == pytest.approx(node, rel=1e-12)
    springs = math.sqrt(2 * m / (2 * k0))
    former = 1 / math.sqrt(1 / thin**2 + 1 / springs**2)
    assert former < 0.9 * node  # the sharper bound: ~12 % more step here
    records = step.summary()
    unit = 10.0 ** (math.floor(math.log10(step.dt_scale * node)) - 3)  # 4 figures
    dt = math.floor(step.dt_scale * node / unit) * unit
    assert records["smallest"] == pytest.approx(dt, rel=1e-12)
    assert records["largest"] == records["smallest"]
    assert sim.history.summary["energy"]["kinetic"] == 0.0
