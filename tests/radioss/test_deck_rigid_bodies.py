"""/RBODY: a deck's rigid body runs as the [[rigid_body]] a user would write by hand (in
kg-mm-ms and in SI, to round-off), its flags are read as Radioss reads them, and what is
not supported is refused in one line naming the card's file:line."""

import numpy as np
import pytest
from mpi4py import MPI

from rwall_fem.radioss import load_deck
from rwall_fem.radioss.reader import DeckError

from .decks import BarDeck, f20, i10, steel
from .test_deck_scenes import reference, run, same_run

MAIN = 1000  # the main node's ID


def rigid_body(deck: BarDeck, rid: int, group: int, *, node: int = MAIN, mass: float = 0.0,
               inertia=(0.0,) * 6, icog: int = 0, ispher: int = 0, sensor: int = 0,
               extra: str = "") -> None:  # fmt: skip
    """An /RBODY in the 2017+ format, SI arguments written in the deck's units."""
    J = [deck.q(j, "mass") / deck.q(1.0, "length") ** 2 for j in inertia]
    deck.cards += [
        f"/RBODY/{rid}", f"rigid body {rid}",
        i10(node) + i10(sensor) + i10(0) + i10(ispher) + f20(deck.q(mass, "mass")) + i10(group)
        + i10(0) + i10(icog) + i10(0),
        "".join(f20(j) for j in J[:3]), "".join(f20(j) for j in J[3:]),
    ] + ([extra] if extra else [])  # fmt: skip


def written(d: BarDeck, directory):
    """The starter file of ``d`` written by rank 0 into ``directory`` (made)."""
    path = None
    if MPI.COMM_WORLD.rank == 0:
        directory.mkdir(parents=True, exist_ok=True)
        path = d.write(directory)
    return MPI.COMM_WORLD.bcast(path, root=0)


def bar_with_rigid_top(units: str) -> BarDeck:
    """A steel bar onto a fixed plane whose top face is a rigid body with a main node 2 mm
    above the top's centre, carrying 5 g and an inertia."""
    d = BarDeck(units=units, nz=6, z0=1e-4, end_time=2e-5)
    top = d.z0 + d.nz * d.h
    d.extra_nodes = [(MAIN, (d.h, d.h, top + 2e-3))]
    d.part()
    d.elastic(**{"rho": 7850.0, "E": 210e9, "nu": 0.3})
    d.solid()
    d.group(1, "NODE", [n for k in range(d.nz + 1) for n in d.face_nodes(k)])
    d.group(2, "NODE", d.face_nodes(d.nz))
    d.initial_velocity((0.0, 0.0, -10.0), 1)
    d.wall("PLANE", point=(0, 0, 0), m1=(0, 0, 1), dsearch=1e-3)
    rigid_body(d, 7, 2, mass=5e-3, inertia=(2e-9, 3e-9, 1e-9, 0.0, 0.0, 0.0))
    return d


@pytest.mark.parametrize("units", ["kg-mm-ms", "SI"])
def test_rigid_top_runs_as_its_scene(units, shared_dir):
    d = bar_with_rigid_top(units)
    scene = load_deck(written(d, shared_dir / units))
    top = d.z0 + d.nz * d.h
    hand = reference(
        d,
        material=dict(steel(), model="linear_elastic"),
        initial={"velocity": [0.0, 0.0, -10.0]},
        wall=[{"kind": "plane", "point": [0.0, 0.0, 0.0], "normal_point": [0.0, 0.0, 1.0],
               "secondary": {"search_distance": 1e-3}}],
        rigid_body=[{"sets": ["top"], "main_node": [d.h, d.h, top + 2e-3], "mass": 5e-3,
                     "inertia": [2e-9, 3e-9, 1e-9, 0.0, 0.0, 0.0]}],
    )  # fmt: skip
    a = run(scene, shared_dir / f"{units}_deck")
    b = run(hand, shared_dir / f"{units}_hand")
    same_run(a, b)
    assert "rigid_body" in a.history.balance.columns
    body = a.rigid_bodies[0]
    assert body.mass == pytest.approx(5e-3 + 7850.0 * d.h**2 * d.h / 2 * 4, rel=1e-12)
    assert a.history.summary["energy"]["max_balance_error"] < 1e-9


def _refused(d: BarDeck, directory, match: str):
    path = written(d, directory)
    with pytest.raises(DeckError, match=match) as err:
        load_deck(path)
    assert "\n" not in str(err.value)


def test_rigid_body_refusals(shared_dir):
    for k, (change, match) in enumerate([
        (dict(sensor=3), r"model_0000\.rad:\d+: /RBODY/7: sens_ID = 3: a rigid body switched "
                         "by a sensor is not supported"),
        (dict(extra=i10(0) + i10(0) + i10(1)), r"/RBODY/7: Ifail = 1: the failure of a rigid "
                                               "body"),
        (dict(icog=5), r"/RBODY/7: ICoG = 5: 1 \(default\), 2, 3 or 4"),
        (dict(node=4242), r"/RBODY/7: node_ID 4242 refers to no /NODE"),
        (dict(node=1), r"/RBODY/7: node_ID 1 is a node of the elements outside grnd_ID 2"),
        (dict(icog=4, mass=0.0), r"/RBODY/7: ICoG = 4 makes Mass the body's whole mass, and "
                                 "it is 0"),
        (dict(icog=4), r"model_0000\.rad:\d+: /RBODY/7: ICoG = 4 makes J the body's whole "
                       "inertia, and it is not positive definite"),
    ]):  # fmt: skip
        d = bar_with_rigid_top("SI")
        d.cards = d.cards[: -5]  # the /RBODY written by bar_with_rigid_top
        rigid_body(d, 7, 2, **({"mass": 5e-3} | change))
        _refused(d, shared_dir / str(k), match)
    d = bar_with_rigid_top("SI")
    d.cards += ["/RBODY/LAGMUL/8", "lagrange", i10(MAIN) + i10(2)]
    _refused(d, shared_dir / "lagmul", r"/RBODY/LAGMUL/8: rigid bodies by Lagrange multipliers")
    d = bar_with_rigid_top("SI")
    rigid_body(d, 8, 2)
    _refused(d, shared_dir / "twice", r"/RBODY/8: 9 of its nodes are also in /RBODY/7 \(.*"
             r"model_0000\.rad:\d+\): a node belongs to one rigid body")  # fmt: skip
    d = bar_with_rigid_top("SI")
    d.clamp(1, "111000", 2)
    _refused(d, shared_dir / "clamped", r"/RBODY/7: a /BCS or /IMPVEL holds its node")


def test_rigid_body_flags(shared_dir):
    """ICoG 2 puts the main node's mass at the nodes' centre, ICoG 4 makes the body the
    main node's mass and inertia alone, ICoG 3 warns; Ispher 1 is noticed."""
    d = bar_with_rigid_top("SI")
    d.cards = d.cards[:-5]
    rigid_body(d, 7, 2, mass=5e-3, icog=3, ispher=1, extra=i10(0) + i10(2))  # Iexpams 2
    said = []
    scene = load_deck(written(d, shared_dir / "icog3"), report=said)
    assert scene.rigid_bodies[0].center == "with_main_node"
    assert any("/RBODY/7: ICoG = 3 turns the body about its main node" in w
               for w in said[0].warnings)  # fmt: skip
    assert any("/RBODY/7: Ispher = 1: not honoured" in n for n in said[0].notices)
    assert any("/RBODY/7: Iexpams = 2: not honoured" in n for n in said[0].notices)
    for icog, key, value in ((2, "center", "nodes"), (4, "node_masses", False)):
        d = bar_with_rigid_top("SI")
        d.cards = d.cards[:-5]
        rigid_body(d, 7, 2, mass=5e-3, inertia=(2e-9, 3e-9, 1e-9, 0, 0, 0), icog=icog)
        scene = load_deck(written(d, shared_dir / f"icog{icog}"))
        assert getattr(scene.rigid_bodies[0], key) == value
    sim = run(scene, shared_dir / "icog4_run")  # ICoG 4: 5 g and J alone, at the main node
    body = sim.rigid_bodies[0]
    assert body.mass == pytest.approx(5e-3, rel=1e-14)
    assert np.allclose(body.center0, [d.h, d.h, d.z0 + d.nz * d.h + 2e-3], rtol=0, atol=1e-15)
    assert np.allclose(np.diag(body.inertia0), [2e-9, 3e-9, 1e-9], rtol=1e-12, atol=0)
