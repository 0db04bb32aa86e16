"""A deck runs as the scene a user would write by hand for the same model: in every unit
system in common use and for every /RWALL variant, to round-off (energy.csv and the wall
impulses of tiny runs). The reference scenes are SI TOML tables written here, with the
built-in bar of gmsh as the body; the decks are written in their units by tests/radioss/decks.py.
"""

import copy

import numpy as np
import pytest
from mpi4py import MPI

from rwall_fem import build_simulation, parse_scene
from rwall_fem.output.wall_table import WALL_COLUMNS
from rwall_fem.radioss import convert, load_deck
from rwall_fem.scene import load_scene

from .decks import UNITS, BarDeck, steel

RTOL = 1e-9


def run(scene, directory):
    sim = build_simulation(scene, MPI.COMM_WORLD, directory)
    sim.run()
    return sim


def same_run(a, b):
    """The two runs agree to round-off: dt, every column of energy.csv (to 1e-9 of the
    column's largest value, or of the largest energy for columns of round-off such as the
    balance error) and the wall impulses."""
    assert a.state.dt == pytest.approx(b.state.dt, rel=1e-12)
    ea, eb = a.history.energy, b.history.energy
    assert ea.shape == eb.shape
    scale = np.maximum(np.abs(ea).max(axis=0), np.abs(eb).max(axis=0)) + 1e-300
    assert np.all(np.abs(ea - eb) <= RTOL * np.maximum(scale, scale[1:].max()))
    for wa, wb in zip(a.history.summary["walls"], b.history.summary["walls"], strict=True):
        ia, ib = np.array(wa["impulse"]), np.array(wb["impulse"])
        assert np.allclose(ia, ib, rtol=RTOL, atol=RTOL * np.abs(ia).max() + 1e-300)
        assert wa["secondary_nodes"] == wb["secondary_nodes"]


def deck_scene(deck: BarDeck, directory, overrides=()):
    path = deck.write(directory) if MPI.COMM_WORLD.rank == 0 else None
    path = MPI.COMM_WORLD.bcast(path, root=0)
    return load_deck(path, overrides)


def reference(deck: BarDeck, **tables) -> object:
    raw = {"run": {"end_time": deck.end_time}, "mesh": deck.scene_mesh(),
           "output": {"plot": False}, **tables}  # fmt: skip
    return parse_scene(copy.deepcopy(raw), source="reference")


def plastic_deck(units: str) -> BarDeck:
    """A Johnson-Cook bar (rate term on), falling under gravity onto a fixed plane while
    a main-node wall of 0.05 kg comes down on it: every dimension a deck converts."""
    d = BarDeck(units=units, nz=6, z0=0.0, end_time=2.5e-5)
    d.extra_nodes = [(1000, (0.0, 0.0, 0.006))]
    d.part()
    d.johnson_cook(8930.0, 117e9, 0.35, a=400e6, b=100e6, n=0.5, c=0.01, rate0=1.0)
    d.solid(24)
    d.group(1, "PART", [1])
    d.initial_velocity((0.0, 0.0, -40.0), 1)
    d.function(1, [(0.0, 1.0), (1.0, 1.0)])
    d.gravity(1, 1, "Z", 1, -9.81e4)
    d.wall("PLANE", 1, point=(0.0, 0.0, 0.0), m1=(0.0, 0.0, 1.0), dsearch=1e-3)
    d.group(2, "NODE", d.face_nodes(d.nz))
    d.wall("PLANE", 2, node=1000, m1=(0.0, 0.0, 0.0), add=2, mass=0.05,
           velocity=(0.0, 0.0, -60.0), slide=1)  # fmt: skip
    return d


def plastic_reference(d: BarDeck, **material):
    return reference(
        d,
        material={"model": "johnson_cook", "density": 8930.0, "young": 117e9, "poisson": 0.35,
                  "yield_stress": 400e6, "hardening_coefficient": 100e6,
                  "hardening_exponent": 0.5, "strain_rate_coefficient": 0.01,
                  "reference_strain_rate": 1.0, **material},
        element={"integration": "reduced", "hourglass": "physical"},
        initial={"velocity": [0.0, 0.0, -40.0]},
        gravity={"acceleration": [0.0, 0.0, -9.81e4]},
        wall=[{"kind": "plane", "point": [0, 0, 0], "normal_point": [0, 0, 1],
               "secondary": {"search_distance": 1e-3}},
              {"kind": "plane", "point": [0, 0, 0.006], "normal_point": [0, 0, 0],
               "slide": "tied", "secondary": {"add": ["top"]},
               "motion": {"mass": 0.05, "velocity": [0, 0, -60.0]}}],
    )  # fmt: skip


@pytest.fixture(scope="module")
def plastic_run(tmp_path_factory):
    d = plastic_deck("SI")
    directory = tmp_path_factory.mktemp("ref") if MPI.COMM_WORLD.rank == 0 else None
    directory = MPI.COMM_WORLD.bcast(directory, root=0)
    return run(plastic_reference(d), directory)


@pytest.mark.parametrize("units", list(UNITS))
def test_each_unit_system_runs_as_the_si_scene(units, plastic_run, shared_dir):
    sim = run(deck_scene(plastic_deck(units), shared_dir), shared_dir / "out")
    same_run(sim, plastic_run)
    assert plastic_run.history.summary["walls"][1]["peak_contacts"] > 0  # the walls acted


def test_sig_max0_runs_as_max_flow_stress(plastic_run, shared_dir):
    """/MAT/LAW2's SIG_max0 (here in kg-mm-ms) is the scene's max_flow_stress: the same run
    to round-off, and not the run without the cap (the cap acted)."""
    d = plastic_deck("kg-mm-ms")
    k = d.cards.index("/MAT/LAW2/1")
    capped = BarDeck(units="kg-mm-ms")
    capped.johnson_cook(8930.0, 117e9, 0.35, a=400e6, b=100e6, n=0.5, c=0.01, rate0=1.0,
                        sig_max=410e6)  # fmt: skip
    d.cards[k : k + len(capped.cards)] = capped.cards
    scene = deck_scene(d, shared_dir)
    assert scene.material.max_flow_stress == pytest.approx(410e6, rel=1e-14)
    sim = run(scene, shared_dir / "capped")
    same_run(sim, run(plastic_reference(d, max_flow_stress=410e6), shared_dir / "reference"))
    work = [s.history.summary["plastic_work"] for s in (sim, plastic_run)]
    print(f"plastic work {work[0]:.6g} J capped, {work[1]:.6g} J not; largest eps_p "
          f"{sim.history.summary['max_plastic_strain']:.4f}")
    assert work[0] < 0.99 * work[1]  # 5 % less seen: the capped bar flows softer


def elastic(d: BarDeck) -> None:
    d.part()
    d.elastic(7850.0, 210e9, 0.3)
    d.solid(24)


WALLS = {
    # name: (deck cards, the scene's wall tables and other tables)
    "plane fixed, sliding, Dsearch": (
        lambda d: d.wall("PLANE", point=(0, 0, 0), m1=(0.3, 0.0, 1.0), dsearch=1.0),
        {
            "wall": [
                {
                    "kind": "plane",
                    "point": [0, 0, 0],
                    "normal_point": [0.3, 0.0, 1.0],
                    "secondary": {"search_distance": 1.0},
                }
            ]
        },
    ),
    "plane on a main node, tied, grnd_ID1": (
        lambda d: (
            d.extra_nodes.append((900, (0.0, 0.0, -2e-4))),
            d.group(3, "BOX", [1]),
            d.box(1, (-1, -1, -1e-4), (1, 1, 1e-4)),
            d.wall(
                "PLANE", node=900, m1=(0, 0, 1), slide=1, add=3, mass=0.02, velocity=(0, 0, 1.0)
            ),
        ),
        {
            "wall": [
                {
                    "kind": "plane",
                    "point": [0, 0, -2e-4],
                    "normal_point": [0, 0, 1],
                    "slide": "tied",
                    "secondary": {"add": ["bottom"]},
                    "motion": {"mass": 0.02, "velocity": [0, 0, 1.0]},
                }
            ]
        },
    ),
    "cylinder fixed, friction with a filter, grnd_ID2": (
        lambda d: (
            d.group(4, "NODE", d.face_nodes(d.nz)),
            d.wall(
                "CYL",
                point=(0.001, -1, -0.002),
                m1=(0.001, 1, -0.002),
                slide=2,
                friction=0.3,
                ffac=0.5,
                ifq=1,
                diameter=0.004,
                dsearch=1.0,
                exclude=4,
            ),
        ),
        {
            "wall": [
                {
                    "kind": "cylinder",
                    "point": [0.001, -1, -0.002],
                    "axis_point": [0.001, 1, -0.002],
                    "diameter": 0.004,
                    "slide": "friction",
                    "friction": 0.3,
                    "friction_filter": {"coefficient": 0.5},
                    "secondary": {"search_distance": 1.0, "exclude": ["top"]},
                }
            ]
        },
    ),
    "sphere on a main node, prescribed by /IMPVEL": (
        lambda d: (
            d.extra_nodes.append((901, (0.001, 0.001, -0.0031))),
            d.group(5, "NODE", [901]),
            d.function(7, [(0, 0), (1, 1), (3, 1)]),
            d.function(8, [(0, 0), (3, 0)]),
            d.imposed_velocity(1, 7, "Z", 5, 1e-5, 2.0),
            d.imposed_velocity(2, 7, "X", 5, 1e-5, 0.5),
            d.imposed_velocity(3, 8, "Y", 5, 1e-5, 1.0),
            d.wall("SPHER", node=901, diameter=0.006, dsearch=1.0, mass=1.0),
        ),
        {
            "wall": [
                {
                    "kind": "sphere",
                    "point": [0.001, 0.001, -0.0031],
                    "diameter": 0.006,
                    "secondary": {"search_distance": 1.0},
                    "motion": {
                        "velocity": [[0, 0, 0, 0], [1e-5, 0.5, 0, 2.0], [3e-5, 0.5, 0, 2.0]]
                    },
                }
            ]
        },
    ),
    "sphere on a main node, sideways held by /BCS": (
        lambda d: (
            d.extra_nodes.append((902, (0.001, 0.001, -0.0031))),
            d.group(7, "NODE", [902]),
            d.clamp(2, "   110 111", 7),
            d.wall("SPHER", node=902, diameter=0.006, dsearch=1.0, mass=0.01,
                   velocity=(0.3, -0.2, 1.0)),  # fmt: skip
        ),
        {
            "wall": [
                {
                    "kind": "sphere",
                    "point": [0.001, 0.001, -0.0031],
                    "diameter": 0.006,
                    "secondary": {"search_distance": 1.0},
                    "motion": {"mass": 0.01, "velocity": [0.3, -0.2, 1.0], "held": "xy"},
                }
            ]
        },
    ),
    "parallelogram fixed, friction in steps, /BCS": (
        lambda d: (
            d.group(6, "NODE", d.face_nodes(d.nz)),
            d.clamp(1, "   110 000", 6),
            d.wall(
                "PARAL",
                point=(-0.001, -0.001, 0),
                m1=(0.003, -0.001, 0),
                m2=(-0.001, 0.0015, 0),
                slide=2,
                friction=0.2,
                ffac=20,
                ifq=2,
                dsearch=1.0,
            ),
        ),
        {
            "wall": [
                {
                    "kind": "parallelogram",
                    "point": [-0.001, -0.001, 0],
                    "corner1": [0.003, -0.001, 0],
                    "corner2": [-0.001, 0.0015, 0],
                    "slide": "friction",
                    "friction": 0.2,
                    "friction_filter": {"steps": 20.0},
                    "secondary": {"search_distance": 1.0},
                }
            ],
            "boundary": [{"group": "top", "components": "xy"}],
        },
    ),
}


@pytest.mark.parametrize("variant", list(WALLS))
def test_each_wall_variant_runs_as_the_scene(variant, shared_dir):
    cards, tables = WALLS[variant]
    d = BarDeck(units="kg-mm-ms", nz=4, end_time=3e-5)
    elastic(d)
    d.group(1, "PART", [1])
    d.initial_velocity((0.4, 0.2, -8.0), 1)
    cards(d)
    ref = reference(d, material={"model": "linear_elastic", **steel()},
                    element={"integration": "reduced", "hourglass": "physical"},
                    initial={"velocity": [0.4, 0.2, -8.0]}, **tables)  # fmt: skip
    a = run(deck_scene(d, shared_dir), shared_dir / "deck")
    b = run(ref, shared_dir / "scene")
    same_run(a, b)
    assert a.history.summary["walls"][0]["peak_contacts"] > 0


def test_convert_round_trips(shared_dir):
    """convert writes a TOML scene and its mesh that run exactly as the deck does."""
    d = plastic_deck("kg-mm-ms")
    scene = deck_scene(d, shared_dir)
    toml = None
    if MPI.COMM_WORLD.rank == 0:
        toml = convert(shared_dir / "model_0000.rad", shared_dir / "converted")
    toml = MPI.COMM_WORLD.bcast(toml, root=0)
    assert toml.read_text().startswith("# Converted by rwall_fem")
    a = run(scene, shared_dir / "deck")
    b = run(load_scene(toml), shared_dir / "toml")
    same_run(a, b)
    assert np.array_equal(a.history.energy, b.history.energy)


def test_bcs_on_a_main_node_holds_its_translations(shared_dir):
    """/BCS 110 111 on a sphere wall's main node: Radioss zeroes the node's x and y
    accelerations (bcs2.F), so the wall keeps VX0 and VY0 exactly while the bar's impact
    changes VZ; the rotation codes are said to be unused, in one line."""
    d = BarDeck(units="kg-mm-ms", nz=4, end_time=3e-5)
    elastic(d)
    d.group(1, "PART", [1])
    d.initial_velocity((0.4, 0.2, -8.0), 1)
    WALLS["sphere on a main node, sideways held by /BCS"][0](d)
    report = []
    path = d.write(shared_dir) if MPI.COMM_WORLD.rank == 0 else None
    path = MPI.COMM_WORLD.bcast(path, root=0)
    scene = load_deck(path, report=report)
    assert scene.walls[0].motion.held == "xy"
    said = [w for w in report[0].warnings if "rotation codes on the main node" in w]
    assert len(said) == 1
    sim = run(scene, shared_dir / "held")
    rows = sim.history.wall(0)
    velocity = rows[:, [WALL_COLUMNS.index(f"velocity_{c}") for c in "xyz"]]
    assert np.array_equal(velocity[:, 0], np.full(len(rows), 0.3))
    assert np.array_equal(velocity[:, 1], np.full(len(rows), -0.2))
    assert velocity[-1, 2] < 1.0 - 0.1  # the bar slowed the wall down along z
