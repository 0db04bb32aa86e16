"""Decks of several parts run as the scene of [[part]] a user would write by hand: a steel
rod with an aluminium nose (two /MAT, two /PROP, bonded; one /INIVEL on both; a wall on
the nose's /GRNOD/PART) against the built-in bar with a front region, and two bars of one
material at their own velocities (/INIVEL per part) against a gmsh geometry of two
boxes, to round-off; the converted TOML and mesh run exactly as the deck."""

from pathlib import Path

import numpy as np
import pytest
from mpi4py import MPI

from rwall_fem import parse_scene
from rwall_fem.radioss import convert, read_deck
from rwall_fem.radioss.model import Body, Deck, Part
from rwall_fem.radioss.parts import deck_parts
from rwall_fem.radioss.to_scene import scene_of
from rwall_fem.scene import load_scene

from .decks import BarDeck, steel
from .test_deck_scenes import deck_scene, run, same_run

ALUMINIUM = {"density": 2700.0, "young": 70e9, "poisson": 0.33}


def bimetal_deck() -> BarDeck:
    """A steel rod (part 1) with an aluminium nose (part 2: its first 2 of 8 layers, plastic,
    fully integrated), moving at one velocity onto a fixed plane that holds the nose."""
    d = BarDeck(units="kg-mm-ms", nz=8, front=2, end_time=3e-5)
    d.part(mat=1, prop=1, pid=1, title="steel rod")
    d.part(mat=2, prop=2, pid=2, title="aluminium nose")
    d.elastic(7850.0, 210e9, 0.3, mid=1)
    d.johnson_cook(2700.0, 70e9, 0.33, a=150e6, b=200e6, n=0.3, mid=2)
    d.solid(24, pid=1)
    d.solid(14, pid=2)
    d.group(1, "PART", [1, 2])
    d.initial_velocity((0.4, 0.2, -8.0), 1)
    d.group(2, "PART", [2])
    d.wall("PLANE", point=(0, 0, 0), m1=(0, 0, 1), add=2)
    return d


def bimetal_reference(d: BarDeck):
    nose = {"model": "elastic_plastic", **ALUMINIUM, "hardening": "power", "yield_stress": 150e6,
            "hardening_coefficient": 200e6, "hardening_exponent": 0.3}  # fmt: skip
    raw = {
        "run": {"end_time": d.end_time},
        "mesh": {**d.scene_mesh(), "front_length": 2 * d.h},
        "output": {"plot": False},
        "initial": {"velocity": [0.4, 0.2, -8.0]},
        "part": [
            {"name": "steel_rod", "volumes": ["body"],
             "material": {"model": "linear_elastic", **steel()},
             "element": {"integration": "reduced", "hourglass": "physical"}},
            {"name": "aluminium_nose", "volumes": ["front"], "material": nose,
             "element": {"integration": "full"}},
        ],
        "wall": [{"kind": "plane", "point": [0, 0, 0], "normal_point": [0, 0, 1],
                  "secondary": {"parts": ["aluminium_nose"]}}],
    }  # fmt: skip
    return parse_scene(raw, source="reference")


@pytest.fixture(scope="module")
def bimetal_run(tmp_path_factory):
    """The bimetal deck, run: (its folder, the Simulation)."""
    directory = tmp_path_factory.mktemp("bimetal") if MPI.COMM_WORLD.rank == 0 else None
    directory = MPI.COMM_WORLD.bcast(directory, root=0)
    return directory, run(deck_scene(bimetal_deck(), directory), directory / "deck")


def test_two_materials_become_parts(shared_dir):
    """One [[part]] per /PART named from its title, the mesh's region of that name, with
    its own material and element; the velocity they share is [initial]; the wall's
    /GRNOD/PART is secondary.parts; check's lines name the parts."""
    scene = deck_scene(bimetal_deck(), shared_dir)
    assert [(p.name, p.volumes) for p in scene.parts] == [
        ("steel_rod", ("steel_rod",)), ("aluminium_nose", ("aluminium_nose",))
    ]  # fmt: skip
    assert scene.material is None
    assert [p.material.model for p in scene.parts] == ["linear_elastic", "elastic_plastic"]
    assert [p.element.integration for p in scene.parts] == ["reduced", "full"]
    assert scene.initial.velocity == (0.4, 0.2, -8.0)
    assert all(p.initial is None for p in scene.parts)
    secondary = scene.walls[0].secondary
    assert secondary.parts == ("aluminium_nose",) and secondary.add == ()
    facts = scene_of(read_deck(shared_dir / "model_0000.rad")).facts
    assert any(f.startswith("part aluminium_nose: /PART/2 (") for f in facts), facts
    assert any(f.startswith("part steel_rod: /PART/1 (") for f in facts), facts


def test_parts_of_one_material_stay_one_body(shared_dir):
    """Two /PART of one /MAT and /PROP at one velocity: the scene of one body, as before."""
    d = BarDeck(units="kg-mm-ms", nz=4, front=1)
    d.part(pid=1)
    d.part(pid=2, title="front")
    d.elastic(7850.0, 210e9, 0.3)
    d.solid(24)
    d.group(1, "PART", [2])
    d.wall("PLANE", point=(0, 0, 0), m1=(0, 0, 1), add=1)
    scene = deck_scene(d, shared_dir)
    assert scene.parts == () and scene.material.model == "linear_elastic"
    assert scene.walls[0].secondary.add == ("grnod_1",)


def test_bimetal_deck_runs_as_the_scene_of_parts(bimetal_run):
    _, deck = bimetal_run
    reference = run(bimetal_reference(bimetal_deck()), bimetal_run[0] / "scene")
    same_run(deck, reference)
    walls = deck.history.summary["walls"]
    assert walls[0]["secondary_nodes"] == 27 and walls[0]["peak_contacts"] > 0


def test_convert_of_parts_round_trips(bimetal_run):
    """convert writes [[part]] tables and a mesh of one physical volume per part that run
    exactly as the deck does."""
    directory, deck = bimetal_run
    toml = None
    if MPI.COMM_WORLD.rank == 0:
        toml = convert(directory / "model_0000.rad", directory / "converted")
    toml = MPI.COMM_WORLD.bcast(toml, root=0)
    text = toml.read_text()
    assert text.count("\n[[part]]") == 2 and "\n[part.material]" in text
    msh = (directory / "converted" / "model.msh").read_text()
    assert '\n3 1 "steel_rod"\n3 2 "aluminium_nose"\n' in msh
    converted = run(load_scene(toml), directory / "toml")
    same_run(deck, converted)
    assert np.array_equal(deck.history.energy, converted.history.energy)


TWO_BOXES = """// two bars of 2 x 2 x 4 cells of 1 mm, 2 mm apart along x
Point(1) = {0, 0, 0, 1e-3};
la[] = Extrude {0.002, 0, 0} { Point{1}; Layers{2}; Recombine; };
sa[] = Extrude {0, 0.002, 0} { Line{la[1]}; Layers{2}; Recombine; };
va[] = Extrude {0, 0, 0.004} { Surface{sa[1]}; Layers{4}; Recombine; };
Point(100) = {0.004, 0, 0, 1e-3};
lb[] = Extrude {0.002, 0, 0} { Point{100}; Layers{2}; Recombine; };
sb[] = Extrude {0, 0.002, 0} { Line{lb[1]}; Layers{2}; Recombine; };
vb[] = Extrude {0, 0, 0.004} { Surface{sb[1]}; Layers{4}; Recombine; };
Physical Volume("left") = {va[1]};
Physical Volume("right") = {vb[1]};
"""


def test_pieces_at_their_own_velocities_run_as_the_scene(shared_dir):
    """Two bars of one /MAT and /PROP sharing no node, an /INIVEL each (a /GRNOD/PART, and
    a node list of exactly the second bar's nodes), onto a plane with friction: parts
    that differ only in their initial velocity."""
    d = BarDeck(units="Mg-mm-s", nz=4, end_time=2e-5)
    d.part(pid=1, title="left bar")
    d.part(pid=2, title="right bar")
    d.elastic(7850.0, 210e9, 0.3)
    d.solid(24)
    right = d.piece(2, x0=0.004, nz=4, first=1001)
    d.group(1, "PART", [1])
    d.initial_velocity((0.0, 0.0, -8.0), 1, iid=1)
    d.group(2, "NODE", right)
    d.initial_velocity((0.5, 0.0, -3.0), 2, iid=2)
    d.wall("PLANE", point=(0, 0, 0), m1=(0, 0, 1), dsearch=1.0, slide=2, friction=0.2)
    scene = deck_scene(d, shared_dir)
    assert scene.material.model == "linear_elastic" and scene.initial.velocity == (0, 0, 0)
    assert [p.initial.velocity for p in scene.parts] == [(0.0, 0.0, -8.0), (0.5, 0.0, -3.0)]
    if MPI.COMM_WORLD.rank == 0:
        (shared_dir / "two_boxes.geo").write_text(TWO_BOXES)
    MPI.COMM_WORLD.Barrier()
    raw = {
        "run": {"end_time": d.end_time},
        "mesh": {"file": "two_boxes.geo"},
        "output": {"plot": False},
        "material": {"model": "linear_elastic", **steel()},
        "element": {"integration": "reduced", "hourglass": "physical"},
        "part": [{"name": "left_bar", "volumes": ["left"],
                  "initial": {"velocity": [0.0, 0.0, -8.0]}},
                 {"name": "right_bar", "volumes": ["right"],
                  "initial": {"velocity": [0.5, 0.0, -3.0]}}],
        "wall": [{"kind": "plane", "point": [0, 0, 0], "normal_point": [0, 0, 1],
                  "slide": "friction", "friction": 0.2,
                  "secondary": {"search_distance": 1.0}}],
    }  # fmt: skip
    reference = parse_scene(raw, source="reference", base=Path(shared_dir))
    a = run(scene, shared_dir / "deck")
    b = run(reference, shared_dir / "scene")
    same_run(a, b)
    assert a.history.summary["walls"][0]["peak_contacts"] == 18  # both bottoms


def test_part_names_are_unique_identifiers():
    """Titles made identifiers (a letter first, at most 64 characters), else part_<ID>;
    the ID appended to a name already taken."""
    deck = Deck(starter=Path("x_0000.rad"))
    titles = ["nose", "nose", "", "2nd piece: steel (hard)", "x" * 80, "part_3"]
    for pid, title in enumerate(titles, start=1):
        deck.parts[pid] = Part(pid, title, 1, 1, "x_0000.rad:1")
        deck.bodies.append(Body(pid, "hexahedron", np.array([pid]), np.arange(8)[None], None))
    names = [p.name for p in deck_parts(deck)]
    assert names == ["nose", "nose_2", "part_3", "part_2nd_piece_steel_hard", "x" * 64,
                     "part_3_6"]  # fmt: skip
