"""Control and output cards are read or skipped, never refused: a deck carrying every one
of them runs exactly as the same deck without them, each skipped card named by one
notice; those that change the model are honoured (/DEF_SOLID's defaults, /RANDOM's
noise, the /DT controls below Tmin). A one-file deck, engine first as Radioss's
single-file input or after the starter, runs as its two-file form."""

import logging
from dataclasses import replace

import numpy as np
import pytest
from mpi4py import MPI

from rwall_fem.radioss import load_deck

from .decks import BarDeck, f20, i10
from .test_deck_scenes import deck_scene, run, same_run

STARTER_CONTROLS = {
    # card: its lines (a deck's usual values)
    "/TITLE": ["a bar on a wall"],
    "/ANALY": ["         0                   0         0"],
    "/IOFLAG": ["         5                   0         0         0         0         0"],
    "/SPMD": ["         0         4                   0                   0"],
    "/MEMORY": ["      1000"],
    "/SHFRA/V4": [],
    "/ARCH": ["         0"],
    "/DEF_SHELL": ["        24         0         0         0         0"],
    "/RANDOM": [f20(0.0) + f20(0.0)],
    "/SECT/1": ["a section", "         0         0         0         0"],
    "/SKEW/FIX/3": ["a skew", f20(0.0) * 3, f20(1.0) + f20(0.0) * 2, f20(0.0) + f20(1.0)],
    "/SENSOR/TIME/1": ["a sensor", f20(1.0)],
    "/ACCEL/1": ["an accelerometer", "         1         0" + f20(0.0)],
    "/TH/NODE/1": ["nodes", "DEF", "         1"],
    "/ANIM/VERS": ["        44"],
    "/CHECK/RFILE/OFF": [],
}  # fmt: skip
ENGINE_CONTROLS = {
    "/TITLE": ["a bar on a wall"],
    "/PARITH/ON": [], "/PROC": ["4"], "/VERS/2024": [], "/MON/ON": [],
    "/STOP": ["0 0 0 1 1"], "/DTIX": ["1e-9"],
    "/ANIM/VECT/VEL": [], "/ANIM/ELEM/EPSP": [], "/ANIM/GZIP": [], "/ANIM/BRICK/TENS/STRESS": [],
    "/TH/VERS": [], "/OUTP/DT": ["0.001"], "/H3D/DT": ["0 0.001"], "/STATE/DT": ["0 0.001"],
    "/RFILE/5000": [], "/PRINT/-100": [],
    "/DT/SHELL/DEL": ["0.9 1e-9"], "/DT/INTER/DEL": ["0.9 1e-9"], "/DEL/SHELL/1": ["2"],
}  # fmt: skip


def plain() -> BarDeck:
    d = BarDeck(units="kg-mm-ms", nz=2, end_time=2e-5)
    d.part()
    d.elastic(7850.0, 210e9, 0.3)
    d.solid(24)
    d.group(1, "PART", [1])
    d.initial_velocity((0.0, 0.2, -8.0), 1)
    d.wall("PLANE", point=(0, 0, 0), m1=(0, 0, 1), dsearch=1.0)
    return d


class Lines(logging.Handler):
    def __init__(self):
        super().__init__(logging.INFO)
        self.lines = []

    def emit(self, record):
        self.lines.append((record.levelno, record.getMessage()))


def loaded(d: BarDeck, directory, overrides=()):
    """The scene of the deck and the lines it logs (notices, warnings)."""
    log, handler = logging.getLogger("rwall_fem"), Lines()
    log.addHandler(handler)
    level = log.level
    log.setLevel(logging.INFO)
    try:
        scene = deck_scene(d, directory, overrides)
    finally:
        log.removeHandler(handler)
        log.setLevel(level)
    return scene, handler.lines


def test_every_control_card_changes_nothing_and_says_so_once(shared_dir):
    with_cards = plain()
    for card, lines in STARTER_CONTROLS.items():
        with_cards.cards += [card, *lines]
    for card, lines in ENGINE_CONTROLS.items():
        with_cards.engine += [card, *lines]
    scene, lines = loaded(with_cards, shared_dir, ["output.plot=false"])
    notices = [text for _, text in lines if text.startswith("deck: notice: ")]
    named = [line.split(": ")[3] for line in notices]
    assert named == [*STARTER_CONTROLS, *ENGINE_CONTROLS], notices
    assert not [text for level, text in lines if level >= logging.WARNING]
    a = run(scene, shared_dir / "with")
    b = run(deck_scene(plain(), shared_dir, ["output.plot=false"]), shared_dir / "without")
    same_run(a, b)
    assert np.array_equal(a.history.energy, b.history.energy)


def controls(*cards, engine=()) -> dict:
    d = plain()
    d.cards += list(cards)
    d.engine += list(engine)
    return d


def solid_property(isolid: int) -> list[str]:
    return ["/PROP/SOLID/1", "solid", i10(isolid) + i10(0) * 8 + f20(0.0), f20(0.0) * 5]


@pytest.mark.parametrize(
    ("cards", "engine", "expect"),
    [
        # /DEF_SOLID gives a blank Isolid its value (Radioss's default is 1, viscous)
        (["/DEF_SOLID", i10(14)], [], {"element": {"integration": "full"}}),
        ([], [], {"element": {"integration": "reduced", "hourglass": "viscous"}}),
        # /RANDOM: coordinate noise of Anoise (input length unit), its seed
        (["/RANDOM", f20(1e-4) + f20(7.0)], [], {"noise": (1e-7, 7)}),
        # the /DT controls: the step's scale and what happens below Tmin (work units, ms)
        ([], ["/DT/BRICK/STOP", "0.8 1e-6"], {"run": (0.8, 1e-9, "stop")}),
        ([], ["/DT/BRICK/DEL", "0.8 1e-6"], {"run": (0.8, 1e-9, "erode")}),
        ([], ["/DT/BRICK/CST/0", "0.67 4e-4"], {"run": (0.67, 4e-7, "mass_scaling")}),
        ([], ["/DT/NODA/CST/0", "0.67 1e-6"], {"run": (0.67, 1e-9, "mass_scaling")}),
        ([], ["/DT/NODA/0", "0.67 1e-6", "/DT/BRICK/CST/0", "0.5 4e-4"],
         {"run": (0.5, 4e-7, "mass_scaling")}),
        ([], ["/DT", "0.7 1e-6"], {"run": (0.7, 1e-9, "stop")}),
    ],
)  # fmt: skip
def test_control_cards_that_change_the_model_are_honoured(cards, engine, expect, shared_dir):
    d = controls(*cards, engine=engine)
    if "element" in expect:  # the property with a blank Isolid
        k = d.cards.index("/PROP/SOLID/1")
        d.cards[k : k + 4] = solid_property(0)
    scene, _ = loaded(d, shared_dir)
    if "element" in expect:
        element = scene.element
        for key, value in expect["element"].items():
            assert getattr(element, key) == value
    if "noise" in expect:
        assert scene.mesh.noise[0] == pytest.approx(expect["noise"][0], rel=1e-12)
        assert scene.mesh.noise[1] == expect["noise"][1]
    if "run" in expect:
        scale, floor, action = expect["run"]
        assert scene.run.dt_scale == scale
        assert scene.run.dt_min == pytest.approx(floor, rel=1e-12)
        assert scene.run.dt_min_action == action


def test_mass_scaling_of_dt_brick_cst_acts(shared_dir):
    """/DT/BRICK/CST with Tmin above the step at rest adds mass at the first step, as
    run.dt_min_action = "mass_scaling" does."""
    d = controls(engine=["/DT/BRICK/CST/0", "0.9 1.41e-4"])
    sim = run(deck_scene(d, shared_dir, ["output.plot=false"]), shared_dir / "cst")
    assert sim.history.summary["status"] == "done"
    assert 0 < sim.history.summary["time_step"]["added_mass_percent"] < 5
    assert sim.history.summary["time_step"]["smallest"] == pytest.approx(1.41e-7, rel=1e-9)


def same_but_names(scene):
    return replace(scene, source="", mesh=replace(scene.mesh, file=None),
                   output=replace(scene.output, directory=None))  # fmt: skip


def test_a_one_file_deck_runs_as_its_two_file_form(shared_dir):
    """Both one-file forms give the scene of the two-file deck (the same mesh file, every
    key the same), and it runs."""
    d = plain()
    d.engine += ["/TFILE", "0.001", "/DT", "0.8 0.0"]
    scenes = []
    for form in ("engine first", "starter first"):
        name = form.split()[0]
        path = d.write(shared_dir, name, one_file=form) if MPI.COMM_WORLD.rank == 0 else None
        path = MPI.COMM_WORLD.bcast(path, root=0)
        assert not path.with_name(f"{name}_0001.rad").exists()
        scenes.append(load_deck(path))
    two_files = deck_scene(d, shared_dir)
    for scene in scenes:  # the mesh file and results folder are named after the deck
        assert scene.mesh.file.parent == two_files.mesh.file.parent  # the same content
        assert same_but_names(scene) == same_but_names(two_files)
    sim = run(replace(scenes[0], output=replace(scenes[0].output, plot=False)), shared_dir / "one")
    assert sim.history.summary["status"] == "done" and sim.step_size.mode == "adaptive"


def test_cards_in_local_units_of_a_unit_card(shared_dir):
    """A /MAT in the /UNIT it names (Mg, mm, s) and a wall in another (kg, m, s), in a deck
    of kg, mm, ms: the scene of the deck written in its input units alone."""
    d = plain()
    local = plain()
    k = local.cards.index("/MAT/LAW1/1")
    local.cards[k : k + 4] = ["/MAT/LAW1/1/7", "elastic", f20(7.85e-9), f20(2.1e5) + f20(0.3)]
    k = local.cards.index("/RWALL/PLANE/1")
    wall = local.cards[k : k + 6]
    local.cards[k : k + 6] = [
        "/RWALL/PLANE/1/8",
        wall[1],
        wall[2],
        f20(1.0) + wall[3][20:],
        f20(0.0) * 3,
        f20(0.0) * 2 + f20(1.0),
    ]
    local.cards += ["/UNIT/7", "Mg mm s", f"{'Mg':>20}{'mm':>20}{'s':>20}",
                    "/UNIT/8", "SI", f"{'1':>20}{'1.D0':>20}{'s':>20}"]  # fmt: skip
    a, _ = loaded(local, shared_dir)
    b, _ = loaded(d, shared_dir)
    assert a.material.density == pytest.approx(b.material.density, rel=1e-14)
    assert a.material.young == pytest.approx(b.material.young, rel=1e-14)
    assert a.walls[0].secondary.search_distance == pytest.approx(1.0, rel=1e-14)
    assert a.walls[0] == replace(b.walls[0], normal_point=a.walls[0].normal_point)
    assert a.walls[0].normal_point == pytest.approx(b.walls[0].normal_point, rel=1e-14)


def test_tfile_spaces_the_history_rows_in_time(shared_dir):
    """/TFILE's dt_his (work units, ms) is output.history_time (s); without /TFILE a row
    every step; a --set of output.history_interval replaces the deck's interval (and one
    of output.history_time a deck's row every step) instead of clashing with it. The run
    writes its rows at the first step at or after each multiple of 1 us, the first and
    the last steps."""
    d = controls(engine=["/TFILE", "0.001"])
    scene, _ = loaded(d, shared_dir)
    assert scene.output.history_time == pytest.approx(1e-6, rel=1e-12)
    without, _ = loaded(plain(), shared_dir)
    assert (without.output.history_time, without.output.history_interval) == (None, 1)
    steps, _ = loaded(d, shared_dir, ["output.history_interval=3"])
    assert (steps.output.history_time, steps.output.history_interval) == (None, 3)
    timed, _ = loaded(plain(), shared_dir, ["output.history_time=2e-6"])
    assert timed.output.history_time == 2e-6
    sim = run(replace(scene, output=replace(scene.output, plot=False)), shared_dir / "tfile")
    times = sim.history.energy[:, 0]
    dt = sim.history.summary["time_step"]["smallest"]
    reached = np.floor(times / 1e-6 + 1e-9)  # the multiples of 1 us reached at each row
    assert dt < 1e-6 and times[0] == 0
    assert times[-1] == pytest.approx(scene.run.end_time, abs=dt)  # the last step
    assert np.array_equal(reached[:-1], np.arange(len(times) - 1))  # each multiple once
    assert reached[-1] - reached[-2] in (0, 1)
    assert np.all(times[1:-1] - reached[1:-1] * 1e-6 < dt)  # at the first step after it
