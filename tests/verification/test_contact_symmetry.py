"""A quarter model cut by symmetry planes meets another body as the whole model does.

Two bars (4 x 4 x 40 mm), of aluminium (nu = 0.33) below and steel (nu = 0.3) above, meet
head-on at +-10 m/s through a [[contact]]: their ends bulge unequally and slide on each
other (with friction 0.3, the contact dissipates 3.5 % more than without). The quarter
(x >= 0, y >= 0, cut by the planes x = 0 and y = 0 through the bars' axis, u_x = 0 held on
the first and u_y = 0 on the second) must give a quarter of the whole model's impulse,
kinetic and strain energy and contact dissipation. Reference: the whole model itself
(symmetry).

Without care it does not: the cut faces of the two bars lie in one plane, and a node of
one bar on it is taken as a whole gap inside the other's cut face (distance 0): the
penalty pushes it along the plane's normal, which the symmetry condition cancels, so the
node passes through the other bar, and the spring at its cap stiffness shrinks the step
until the run stops (two steel bars, undamped, at the automatic step: "the changes of the
time step have put 5.43 % of the body's energy into it" at step 252, with at most 6 of
the 18 nodes of the two passes in contact). Now the faces on symmetry planes are not
segments, and a node on the planes acts as its share of the whole node
(``docs/theory.md``, "Symmetry planes").

Both runs take one fixed step (5e-8 s, below both stable steps): the automatic step of
a quarter differs from the whole's, since the highest eigenvalue of its mesh is found
without its symmetry conditions. With the contact's default damping the quarter equals
the whole to 1e-9 (2e-11 measured, with and without friction). Undamped (two steel bars),
the nodes that come into and out of contact at each ringing of the stiff springs grow the
round-off of the two sums (the whole model adds mirror forces in another order) to about
1e-6.
"""

import pytest
from conftest import run
from mpi4py import MPI

from test_contact import write_geo

L, A_SIDE, H, SPEED = 0.04, 0.004, 0.001, 10.0
STEEL = {"model": "linear_elastic", "density": 7850.0, "young": 200e9, "poisson": 0.3}
ALUMINIUM = {"model": "linear_elastic", "density": 2700.0, "young": 70e9, "poisson": 0.33}


def bars_geo(quarter: bool, separation=2e-4) -> str:
    """Two bars along z of 1 mm hexahedra, ``separation`` (m) apart: the whole (centred on
    the z axis) or its quarter x, y >= 0, whose faces on x = 0 and y = 0 are the groups
    "cut_x" and "cut_y"."""
    a = A_SIDE / 2 if quarter else A_SIDE
    o = 0.0 if quarter else -A_SIDE / 2
    lines = []
    for k, (name, z) in enumerate((("lower", 0.0), ("upper", L + separation))):
        corners = ((o, o), (o + a, o), (o + a, o + a), (o, o + a))
        lines += [
            "p = newp;",
            *(f"Point(p + {i}) = {{{x}, {y}, {z}, {H}}};" for i, (x, y) in enumerate(corners)),
            "q = newl;",
            *(f"Line(q + {i}) = {{p + {i}, p + {(i + 1) % 4}}};" for i in range(4)),
            "r = newll;",
            "Curve Loop(r) = {q, q + 1, q + 2, q + 3};",
            "f = news;",
            "Plane Surface(f) = {r};",
            f"Transfinite Curve {{q, q + 1, q + 2, q + 3}} = {round(a / H) + 1};",
            "Transfinite Surface {f};",
            "Recombine Surface {f};",
            f"out{k}[] = Extrude {{0, 0, {L}}} {{ Surface{{f}}; Layers{{{round(L / H)}}}; "
            "Recombine; };",
            f'Physical Volume("{name}") = {{out{k}[1]}};',
        ]
    # The sides extruded from lines q (y = o) and q + 3 (x = o).
    lines += ['Physical Surface("cut_y") = {out0[2], out1[2]};',
              'Physical Surface("cut_x") = {out0[5], out1[5]};']  # fmt: skip
    return "\n".join(lines) + "\n"


def bars(directory, quarter: bool, friction=0.0) -> dict:
    raw = {
        "run": {"end_time": 3.2e-5, "dt": 5e-8},
        "mesh": {"file": str(write_geo(directory, "bars.geo", bars_geo(quarter)))},
        "material": STEEL,
        "part": [
            {"name": "lower", "initial": {"velocity": [0, 0, SPEED]}, "material": ALUMINIUM},
            {"name": "upper", "initial": {"velocity": [0, 0, -SPEED]}},
        ],
        "contact": [{"main": ["upper"], "secondary": ["lower"], "friction": friction}],
        "output": {"plot": False},
    }
    if quarter:
        raw["boundary"] = [{"group": "cut_x", "components": "x"},
                           {"group": "cut_y", "components": "y"}]  # fmt: skip
    return raw


@pytest.mark.parametrize("friction", [0.0, 0.3])
def test_a_quarter_of_two_bars_meets_as_the_whole(tmp_path_factory, friction):
    """The quarter's impulse, kinetic and strain energy and the contact's dissipation
    (damping; and friction, as the bars' ends bulge and slide on each other) x 4 equal the
    whole model's to 1e-9 of the whole's; its surface has a quarter of the whole's segments
    (the cut faces left out); the contact acted (the aluminium bar turns back) and the
    books close."""

    def folder(name):
        comm = MPI.COMM_WORLD
        return comm.bcast(tmp_path_factory.mktemp(name) if comm.rank == 0 else None, root=0)

    books = {}
    for quarter in (False, True):
        directory = folder("quarter" if quarter else "whole")
        sim = run(bars(directory, quarter, friction), directory)
        s = sim.history.summary
        share = 4.0 if quarter else 1.0
        books[quarter] = {
            "impulse": share * s["contacts"][0]["impulse"][2],
            "kinetic": share * s["energy"]["kinetic"],
            "internal": share * s["energy"]["internal"],
            "segments": share * s["contacts"][0]["segments"],
            "friction": share * s["energy"]["contact_friction"],
        }
        assert s["energy"]["max_balance_error"] <= 1e-12
    whole, part = books[False], books[True]
    mass = ALUMINIUM["density"] * A_SIDE**2 * L
    assert -whole["impulse"] >= 2 * mass * SPEED  # the aluminium bar turns back
    assert part["segments"] == whole["segments"]
    for name in ("impulse", "kinetic", "internal", "friction"):
        scale = abs(whole["impulse"]) if name == "impulse" else whole["kinetic"] + whole["internal"]
        assert abs(part[name] - whole[name]) <= 1e-9 * scale, name


def test_the_cut_faces_stay_out_of_a_surface_that_follows_erosion(shared_dir):
    """A part whose cells may erode keeps its faces on symmetry planes out of its surface
    as well (its surface is rebuilt as cells erode): the quarter bars with erosion below
    dt_min have the segments of the quarter without it, a quarter of the whole's (336 of
    1344: 2 passes of 2 x 168 faces)."""
    from rwall_fem import build_simulation, parse_scene

    raw = bars(shared_dir, quarter=True)
    raw["run"] = {"end_time": 1e-6, "dt_min": 1e-12, "dt_min_action": "erode"}
    sim = build_simulation(parse_scene(raw, source="test"), MPI.COMM_WORLD, shared_dir)
    assert type(sim.contacts[0]).__name__ == "ErodingContact"
    assert sim.contacts[0].summary()["segments"] == 336
    sim.contacts[0]._follow(rebuild=True)  # as after a resume
    assert sim.contacts[0].summary()["segments"] == 336
