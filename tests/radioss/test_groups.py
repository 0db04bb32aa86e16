"""Groups and surfaces of a deck select what Radioss's do: node, element and part groups,
their unions and removals (negative IDs), boxes, subsets, and surfaces of segments, of
solid parts' outer faces (/SURF/PART/EXT, pointing out) or all faces, counted and
oriented against a bar worked out by hand; a group that refers to nothing or to itself
is refused in one line; a wall and a /BCS on groups built from other groups run as the
scene of the same node sets."""

import numpy as np
import pytest
from mpi4py import MPI

from rwall_fem.radioss import DeckError, read_deck
from rwall_fem.radioss.groups import element_ids, flip, node_ids, part_ids, surface

from .decks import BarDeck, i10, steel
from .test_deck_scenes import deck_scene, reference, run, same_run

# The bar of the tests: 2 x 2 x 4 hexahedra of 1 mm (nodes 1..45, elements 1..16, layer k
# of elements 4k+1..4k+4), the bottom layer part 2 ("front"), the others part 1.
NX, NY, NZ = 2, 2, 4


def listed(kind: str, gid: int, ids, family: str = "GRNOD") -> list[str]:
    """A group card listing ``ids`` (ten to a line)."""
    rows = [ids[k : k + 10] for k in range(0, len(ids), 10)]
    return [f"/{family}/{kind}/{gid}", f"{family} {kind} {gid}"] + [
        "".join(i10(n) for n in row) for row in rows
    ]


def bar() -> BarDeck:
    d = BarDeck(units="kg-mm-ms", nx=NX, ny=NY, nz=NZ, front=1)
    d.cards += ["/PART/1", "the bar", i10(1) + i10(1) + i10(10)]
    d.cards += ["/PART/2", "front", i10(1) + i10(1) + i10(11)]
    d.cards += ["/SUBSET/10", "the whole", i10(11), "/SUBSET/11", "the front"]
    d.elastic(7850.0, 210e9, 0.3)
    d.solid(24)
    return d


def read(d: BarDeck, directory):
    path = d.write(directory) if MPI.COMM_WORLD.rank == 0 else None
    return read_deck(MPI.COMM_WORLD.bcast(path, root=0))


def layer_nodes(d: BarDeck, k: int) -> set[int]:
    return set(d.face_nodes(k))


def test_node_groups_unions_and_removals(shared_dir):
    d = bar()
    d.cards += listed("NODE", 1, [*range(1, 10), -5])
    d.cards += listed("NODE", 3, [1, 2])
    d.cards += listed("GRNOD", 2, [1, -3])
    d.cards += listed("PART", 4, [2])
    d.cards += listed("SUBSET", 5, [10, -11])  # the whole, less the front: part 1
    d.cards += listed("MAT", 6, [1])
    d.cards += listed("BOX", 7, [1])
    d.cards += ["/BOX/SPHER/1", "around node 1", i10(1) + " " * 20 + f"{2.2:20g}",
                "".join(f"{0.0:20g}" for _ in range(3))]  # fmt: skip
    deck = read(d, shared_dir)
    user = "test: grnd_ID"
    assert node_ids(deck, 1, user).tolist() == [1, 2, 3, 4, 6, 7, 8, 9]
    assert node_ids(deck, 2, user).tolist() == [3, 4, 6, 7, 8, 9]
    assert set(node_ids(deck, 4, user).tolist()) == layer_nodes(d, 0) | layer_nodes(d, 1)
    part1 = set().union(*(layer_nodes(d, k) for k in range(1, NZ + 1)))
    assert set(node_ids(deck, 5, user).tolist()) == part1
    assert len(node_ids(deck, 6, user)) == (NX + 1) * (NY + 1) * (NZ + 1)
    # A sphere of diameter 2.2 mm about node 1 at the origin holds the nodes within 1.1 mm.
    assert node_ids(deck, 7, user).tolist() == [1, 2, 4, 10]
    assert part_ids(deck, "SUBSET", np.array([10]), user).tolist() == [1, 2]
    assert deck.groups[4].nodes is not None  # resolved groups keep their nodes


def test_element_groups_and_boxes(shared_dir):
    d = bar()
    d.cards += listed("BRIC", 1, [1, 2, 3, 4, 5, -2], "GRBRIC")
    d.cards += listed("PART", 2, [1], "GRBRIC")
    d.cards += listed("GRBRIC", 3, [1, 2, -1], "GRBRIC")  # part 1 less bricks 1, 3, 4, 5
    d.cards += listed("BOX", 4, [1], "GRBRIC")
    d.cards += listed("BOX2", 5, [1], "GRBRIC")
    d.cards += listed("GRBRIC", 6, [4])  # /GRNOD/GRBRIC: the nodes of the bricks in box 1
    d.box(1, (-1e-4, -1e-4, -1e-4), (0.0021, 0.0021, 0.0011))  # the bottom layer, m
    deck = read(d, shared_dir)
    user = "test: grbric_ID"
    assert element_ids(deck, "GRBRIC", 1, user).tolist() == [1, 3, 4, 5]
    assert element_ids(deck, "GRBRIC", 2, user).tolist() == list(range(5, 17))
    assert element_ids(deck, "GRBRIC", 3, user).tolist() == list(range(6, 17))
    assert element_ids(deck, "GRBRIC", 4, user).tolist() == [1, 2, 3, 4]
    assert element_ids(deck, "GRBRIC", 5, user).tolist() == list(range(1, 9))
    assert set(node_ids(deck, 6, user).tolist()) == layer_nodes(d, 0) | layer_nodes(d, 1)


def normals(deck, segments) -> np.ndarray:
    x = deck.coordinates[deck.node_positions(segments.ravel())].reshape(*segments.shape, 3)
    return np.cross(x[:, 2] - x[:, 0], x[:, 3] - x[:, 1]), x.mean(axis=1)


def test_surfaces_outer_faces_all_faces_segments(shared_dir):
    d = bar()
    d.cards += listed("PART/EXT", 1, [1, 2], "SURF")
    d.cards += listed("PART/EXT", 2, [2], "SURF")
    d.cards += listed("PART/ALL", 3, [1], "SURF")
    top = d.face_nodes(NZ)
    d.cards += ["/SURF/SEG/4", "a quad and a triangle",
                i10(1) + "".join(i10(n) for n in (top[0], top[1], top[4], top[3])),
                i10(2) + "".join(i10(n) for n in (top[1], top[2], top[5])) + i10(0)]  # fmt: skip
    d.cards += listed("SURF", 5, [4, -2], "SURF")
    d.cards += listed("SURF", 6, [1])
    d.cards += listed("PART", 7, [1], "SURF")  # shells of part 1: none
    deck = read(d, shared_dir)
    user = "test: surf_ID"
    outer = surface(deck, 1, user)
    assert len(outer) == 2 * (NX * NY + NX * NZ + NY * NZ)
    n, centre = normals(deck, outer)
    middle = np.array([NX, NY, NZ]) * 1e-3 / 2
    assert np.all(np.einsum("ij,ij->i", n, centre - middle) > 0)  # every face points out
    front = surface(deck, 2, user)
    assert len(front) == 2 * NX * NY + 2 * (NX + NY)  # its interface with part 1 included
    n, centre = normals(deck, front)
    on_top = np.isclose(centre[:, 2], 1e-3)
    assert on_top.sum() == NX * NY and np.all(n[on_top, 2] > 0)
    assert len(surface(deck, 3, user)) == 6 * NX * NY * (NZ - 1)
    segments = surface(deck, 4, user)
    assert segments[1].tolist() == [top[1], top[2], top[5], top[5]]
    both = surface(deck, 5, user)
    assert len(both) == 2 + len(front)
    assert np.array_equal(both[2:], flip(front))
    n, centre = normals(deck, both[2:])  # turned over: into the front layer
    assert np.all(np.einsum("ij,ij->i", n, centre - [1e-3, 1e-3, 0.5e-3]) < 0)
    # /GRNOD/SURF of the bar's skin: every node but the 3 inside.
    assert len(node_ids(deck, 6, user)) == (NX + 1) * (NY + 1) * (NZ + 1) - 3
    assert len(surface(deck, 7, user)) == 0


REFUSED = {
    # name: (cards, the message)
    "a group of itself": (
        listed("GRNOD", 8, [9]) + listed("GRNOD", 9, [8]),
        r"/GRNOD/GRNOD/\d: holds itself through /GRNOD/\d -> /GRNOD/\d -> /GRNOD/\d",
    ),
    "a group of nothing": (
        listed("GRNOD", 8, [99]), r"/GRNOD/GRNOD/8: grnod 99 refers to no /GRNOD"
    ),
    "an element of nothing": (
        listed("BRIC", 8, [99], "GRBRIC"),
        r"/GRBRIC/BRIC/8: element 99 refers to no element of GRBRIC's kind",
    ),
    "a subset of nothing": (listed("SUBSET", 8, [12]), r"subset 12 refers to no /SUBSET"),
    "a segment of no node": (
        ["/SURF/SEG/3", "s", i10(1) + i10(1) + i10(2) + i10(999)] + listed("SURF", 8, [3]),
        r"/SURF/SEG/3: node 999 refers to no /NODE",
    ),
}  # fmt: skip


@pytest.mark.parametrize("case", list(REFUSED))
def test_a_group_that_refers_to_nothing_or_itself_is_one_line(case, shared_dir):
    cards, pattern = REFUSED[case]
    d = bar()
    d.cards += cards
    deck = read(d, shared_dir)
    family = "GRBRIC" if "GRBRIC" in cards[0] else "GRNOD"
    with pytest.raises(DeckError, match=pattern) as info:
        if family == "GRNOD":
            node_ids(deck, 8, "test: grnd_ID")
        else:
            element_ids(deck, family, 8, "test: grbric_ID")
    assert "\n" not in str(info.value) and "model_0000.rad:" in str(info.value)


def test_wall_and_bcs_on_groups_of_groups_run_as_the_scene(shared_dir):
    """A wall whose grnd_ID1 is the bottom face made of groups of groups (the nodes of
    the bricks in a box less the nodes above z = 0), and a /BCS on the top face given by
    a /SURF/SEG's nodes, run as the scene's bottom and top node sets."""
    d = BarDeck(units="kg-mm-ms", nz=NZ, end_time=3e-5)
    d.part()
    d.elastic(7850.0, 210e9, 0.3)
    d.solid(24)
    d.group(1, "PART", [1])
    d.initial_velocity((0.0, 0.0, -8.0), 1)
    d.cards += listed("BOX", 1, [1], "GRBRIC")
    d.box(1, (-1e-4, -1e-4, -1e-4), (0.0021, 0.0021, 0.0011))
    d.box(2, (-1e-4, -1e-4, 0.5e-3), (0.0021, 0.0021, 0.1))
    d.cards += listed("GRBRIC", 2, [1]) + listed("BOX", 3, [2]) + listed("GRNOD", 4, [2, -3])
    top = d.face_nodes(NZ)
    quads = [(top[i], top[i + 1], top[i + 4], top[i + 3]) for i in (0, 1, 3, 4)]
    d.cards += ["/SURF/SEG/1", "the top"]
    d.cards += [i10(k + 1) + "".join(i10(n) for n in q) for k, q in enumerate(quads)]
    d.cards += listed("SURF", 5, [1])
    d.clamp(1, "   110 000", 5)
    d.wall("PLANE", point=(0, 0, -1e-5), m1=(0, 0, 1), add=4, slide=1)
    ref = reference(d, material={"model": "linear_elastic", **steel()},
                    element={"integration": "reduced", "hourglass": "physical"},
                    initial={"velocity": [0.0, 0.0, -8.0]},
                    boundary=[{"group": "top", "components": "xy"}],
                    wall=[{"kind": "plane", "point": [0, 0, -1e-5], "normal_point": [0, 0, 1],
                           "slide": "tied", "secondary": {"add": ["bottom"]}}])  # fmt: skip
    a = run(deck_scene(d, shared_dir), shared_dir / "deck")
    b = run(ref, shared_dir / "scene")
    same_run(a, b)
    assert a.history.summary["walls"][0]["secondary_nodes"] == (NX + 1) * (NY + 1)
    assert a.history.summary["walls"][0]["peak_contacts"] > 0
