"""/CLOAD, /PLOAD, /ADMAS and /DAMP decks against closed forms, and their refusals.

A nu = 0 bar of 10 one-millimetre hexahedra in kg-mm-ms, clamped at z = 0 (/BCS), is
pulled at its top face by a force ramped over ten periods of its first mode, then held,
with mass damping (/DAMP) at half the critical of that mode: it ends at the static
extension F L / (E A). A /PLOAD of F / A on the top face's segment pulls it the same way
when the segment's normal points out of the bar (Radioss pushes along the normal), and
pushes it when the segment is turned over. /ADMAS adds to the mass books.
"""

import math

import numpy as np
import pytest
from mpi4py import MPI

from rwall_fem import build_simulation
from rwall_fem.radioss import load_deck

from .decks import BarDeck, f20, i10
from .test_bad_decks import refused_in_one_line, written

E, RHO, H, NZ = 210e9, 7850.0, 1e-3, 10
LENGTH, AREA = NZ * H, H * H
PERIOD = 4 * LENGTH / math.sqrt(E / RHO)  # s
F = 1000.0  # N
FORCE_UNIT = 1e3  # N: kg mm / ms^2


def pulled(load: str, turned: bool = False) -> BarDeck:
    """The clamped bar, damped, under a ramped /CLOAD or /PLOAD on its top."""
    d = BarDeck(units="kg-mm-ms", nx=1, ny=1, nz=NZ, h=H, end_time=15 * PERIOD)
    d.part()
    d.elastic(RHO, E, 0.0)
    d.solid(24)
    top, bottom = d.face_nodes(NZ), d.face_nodes(0)
    d.group(1, "NODE", top)
    d.group(2, "NODE", bottom)
    d.clamp(1, "111 000", 2)
    ms = 1e-3
    d.function(1, [(0.0, 0.0), (10 * PERIOD / ms, 1.0), (100 * PERIOD / ms, 1.0)])
    if load == "force":
        d.cards += ["/CLOAD/1", "pull", i10(1) + "Z".rjust(10) + i10(0) * 2 + i10(1) + i10(0)
                    + f20(0.0) + f20(F / 4 / FORCE_UNIT)]  # fmt: skip
    else:
        ring = [top[0], top[1], top[3], top[2]]  # counterclockwise seen from +z: outward
        if turned:
            ring = ring[::-1]
        d.cards += ["/SURF/SEG/5", "the top", i10(1) + "".join(i10(n) for n in ring)]
        d.cards += ["/PLOAD/1", "pull", i10(5) + i10(1) + i10(0) * 4
                    + f20(0.0) + f20(d.q(F / AREA, "stress"))]  # fmt: skip
    alpha = 2 * math.pi / PERIOD  # 1/s: xi = 1/2 on the first mode
    d.cards += ["/DAMP/1", "damping", f20(alpha * ms) + f20(0.0) + i10(3) + i10(0)]
    d.group(3, "PART", [1])
    return d


def run_deck(d: BarDeck, directory):
    scene = load_deck(written(d, directory))
    sim = build_simulation(scene, MPI.COMM_WORLD, directory)
    sim.run()
    return sim


def top_displacement(sim) -> np.ndarray:
    top = np.abs(sim.state.X[:, 2] - LENGTH) < 1e-9 * LENGTH
    return sim.state.u[top, 2]


def test_cload_and_damp_reach_the_static_extension(shared_dir):
    sim = run_deck(pulled("force"), shared_dir)
    static = F * LENGTH / (E * AREA)
    assert top_displacement(sim) == pytest.approx(static, rel=1e-6)  # 2e-10 seen
    summary = sim.history.summary
    energy = summary["energy"]
    assert energy["internal"] == pytest.approx(F * static / 2, rel=1e-6)
    assert energy["external_work"] + energy["damping_work"] == pytest.approx(
        energy["internal"], rel=1e-9
    )
    assert energy["damping_work"] < 0 and energy["max_balance_error"] < 1e-12
    assert summary["effects"][1:3] == ["load[0]", "damping"]


@pytest.mark.parametrize("turned", [False, True], ids=["outward", "turned over"])
def test_pload_on_the_top_segment_equals_the_force(turned, shared_dir):
    sim = run_deck(pulled("pressure", turned), shared_dir)
    static = F * LENGTH / (E * AREA)
    assert top_displacement(sim) == pytest.approx(-static if turned else static, rel=1e-6)


def test_admas_adds_to_the_mass_books(shared_dir):
    d = pulled("force")
    d.end_time = 1e-7
    d.cards += ["/ADMAS/0/1", "on each node", f20(0.002) + i10(1)]  # kg, on 4 nodes
    d.cards += ["/ADMAS/1/2", "spread", f20(0.01) + i10(1)]  # kg over the 4 nodes
    sim = build_simulation(load_deck(written(d, shared_dir)), MPI.COMM_WORLD, shared_dir)
    bar = RHO * AREA * LENGTH
    assert sim.info["mass"] == pytest.approx(bar + 4 * 0.002 + 0.01, rel=1e-12)
    top = np.abs(sim.state.X[:, 2] - LENGTH) < 1e-9 * LENGTH
    assert sim.state.mass[top] == pytest.approx(bar / NZ / 8 + 0.002 + 0.0025, rel=1e-12)


def edit(header: str, line: str):
    """An edit replacing the first data line after the card ``header`` by ``line``."""

    def apply(lines):
        k = next(i for i, text in enumerate(lines) if text.startswith(header))
        lines[k + 2] = line

    return apply


NOT_READ = {
    "loads_admas_type_2": (
        ["/ADMAS/2/1", "per area", f20(1.0) + i10(5)], "/ADMAS/2/1", r"type 2: rwall_fem reads "
        r"types 0 \(Mass on each node of a node group\) and 1",
    ),
    "loads_damp_inter": (
        ["/DAMP/INTER/1", "contact", i10(20), f20(1.0) + i10(3)], "/DAMP/INTER/1",
        r"unsupported damping; supported: /DAMP \(Rayleigh",
    ),
    "loads_damp_tstart": (
        ["/DAMP/2", "late", f20(1.0) + f20(0.0) + i10(3) + i10(0) + f20(1.0)], "/DAMP/2",
        r"Tstart and Tstop are not supported",
    ),
    "loads_damp_by_direction": (
        ["/DAMP/2", "by axis", f20(1.0) + f20(0.0) + i10(3), f20(2.0) + f20(0.0)], "/DAMP/2",
        r"Alpha_y, Beta_y = 2, 0 differ from Alpha, Beta",
    ),
    "loads_cload_moment": (
        ["/CLOAD/2", "twist", i10(1) + "XX".rjust(10) + i10(0) * 2 + i10(1)], "/CLOAD/2",
        r"Dir = 'XX': X, Y or Z \(a force",
    ),
    "loads_cload_of_displacement": (
        ["/CLOAD/2", "spring", i10(1) + "X".rjust(10) + i10(0) * 2 + i10(1) + i10(2)],
        "/CLOAD/2", r"Itypfun = 2: only functions of time",
    ),
    "loads_pload_inside": (
        ["/SURF/SEG/6", "inside", i10(1) + "".join(i10(n) for n in (21, 22, 24, 23)),
         "/PLOAD/2", "inside", i10(6) + i10(1)], "/PLOAD/2",
        r"surf_ID 6: the segment \[21, 22, 24, 23\] is not an outer face of the body",
    ),
    "loads_pload_both_ways": (
        ["/SURF/SEG/6", "two ways", i10(1) + "".join(i10(n) for n in (1, 2, 4, 3)),
         i10(2) + "".join(i10(n) for n in (41, 42, 44, 43)),
         "/PLOAD/2", "two ways", i10(6) + i10(1)], "/PLOAD/2",
        r"1 segments point out of the body and 1 into it",
    ),
}  # fmt: skip


@pytest.mark.parametrize("case", list(NOT_READ))
def test_what_is_not_read_is_one_line(case, shared_dir):
    cards, header, pattern = NOT_READ[case]
    d = pulled("force")
    d.cards += cards
    refused_in_one_line(written(d, shared_dir), header, pattern)


def void_bar(front: int) -> BarDeck:
    """A steel bar falling at 5 m/s onto a plane at z = 0, its lowest ``front`` layers of
    a void material (/MAT/VOID, /PROP/VOID); without them when ``front`` is 0, starting as
    high as the bar's solid layers do."""
    d = BarDeck(units="kg-mm-ms", nz=8 - (0 if front else 2), z0=0.0 if front else 2e-3,
                front=front, end_time=3e-6)  # fmt: skip
    d.part()
    d.elastic(RHO, E, 0.3)
    d.solid(24)
    if front:
        d.part(mat=2, prop=2, pid=2, title="void")
        d.cards += ["/MAT/VOID/2", "nothing", "/PROP/VOID/2", "nothing"]
    d.group(1, "PART", [1])
    d.initial_velocity((0.0, 0.0, -5.0), 1)
    d.wall("PLANE", m1=(0, 0, 1), dsearch=1.0, add=1)
    return d


def test_void_elements_are_left_out(shared_dir):
    """A void part (no stiffness, no mass) changes nothing: the bar runs as the bar
    without it, its free nodes left out."""
    scene = load_deck(written(void_bar(2), shared_dir))
    sim = build_simulation(scene, MPI.COMM_WORLD, shared_dir)
    sim.run()
    if MPI.COMM_WORLD.rank == 0:
        (shared_dir / "bare").mkdir(exist_ok=True)
    MPI.COMM_WORLD.Barrier()
    bare = build_simulation(load_deck(written(void_bar(0), shared_dir / "bare")),
                            MPI.COMM_WORLD, shared_dir / "bare")  # fmt: skip
    bare.run()
    assert sim.info["mass"] == pytest.approx(RHO * 2e-3 * 2e-3 * 6e-3, rel=1e-12)
    assert sim.info["nodes"] == bare.info["nodes"] == 9 * 7
    assert sim.state.dt == bare.state.dt
    a, b = sim.history.energy, bare.history.energy
    assert np.allclose(a, b, rtol=0, atol=1e-9 * np.abs(b).max())
    assert sim.history.summary["energy"]["external_work"] == 0.0


def tetrahedra_as_bricks(lines):
    k = next(i for i, text in enumerate(lines) if text.startswith("/BRICK"))
    for layer in (3, 5):
        a, b, c, d, e, f, g, h = (int(lines[k + 1 + layer][10 * j : 10 * j + 10])
                                  for j in range(1, 9))  # fmt: skip
        lines[k + 1 + layer] = i10(layer + 1) + "".join(i10(q) for q in (a, b, c, c, g, g, g, g))


def test_degenerate_bricks_are_one_line_naming_them(shared_dir):
    refused_in_one_line(written(pulled("force"), shared_dir, tetrahedra_as_bricks), "/BRICK",
                        r"2 elements repeat a node \(degenerate: 4, 6\): only 8-node")
